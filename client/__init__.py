"""A small Python client of the toptraj HTTP API (httpx), with typed results.

    from toptraj.client import Client

    with Client("http://127.0.0.1:8000") as toptraj:
        trajectory = toptraj.plan("ur5", waypoints=[[0, -1.2, 1, 0, 0, 0], [2, -1.3, 1.2, 0.2, 0.4, 1.2]])
        trajectory.duration, trajectory.t, trajectory.q    # s; (n,), (n, 6) numpy arrays
        [c.duration for c in toptraj.compare("ur5", waypoints=..., methods=["phase_plane", "quintic"])]

Errors come back as ``ProblemError`` with the problem+json's ``status``, ``title`` and ``detail``.
"""

from toptraj.client.api import Client, Comparison, ProblemError, Trajectory

__all__ = ["Client", "Comparison", "ProblemError", "Trajectory"]
