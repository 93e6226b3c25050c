"""toptraj: time-optimal trajectories with torques for URDF robot arms.

One import name for the four parts of the project, each a sub-package:

* ``toptraj.robots``: arms as Pinocchio models with their limits (catalog and uploads);
* ``toptraj.planners``: the library (paths, constraints, timing methods, motion generators);
* ``toptraj.service``: the HTTP service, its command line and its web page;
* ``toptraj.client``: a Python client of the HTTP API.

``toptraj.__version__`` is read from the installed package's metadata when first asked for
(``importlib.metadata`` takes tens of milliseconds to import, which ``toptraj plan`` does without).
"""


def __getattr__(name: str) -> str:
    if name != "__version__":
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("toptraj")
    except PackageNotFoundError:  # a checkout on PYTHONPATH, not installed
        return "0+unknown"


__all__ = ["__version__"]
