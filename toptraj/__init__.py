"""toptraj: time-optimal trajectories with torques for URDF robot arms.

One import name for the four parts of the project, each a sub-package:

* ``toptraj.robots``: arms as Pinocchio models with their limits (catalog and uploads);
* ``toptraj.planners``: the library (paths, constraints, timing methods, motion generators);
* ``toptraj.service``: the HTTP service, its command line and its web page;
* ``toptraj.client``: a Python client of the HTTP API.
"""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("toptraj")
except PackageNotFoundError:  # a checkout on PYTHONPATH, not installed
    __version__ = "0+unknown"

__all__ = ["__version__"]
