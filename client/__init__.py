"""The Python client of the toptraj HTTP API: every endpoint as a method, typed results with
numpy arrays (one row per sample, one column per joint, SI units), every error answer as one
exception, ``ProblemError``. It speaks HTTP only (httpx), so it runs wherever the service is
reachable, without the planning libraries.

Example:
    ```python
    from toptraj.client import Client, ProblemError

    with Client("http://127.0.0.1:8000", timeout=60) as toptraj:
        waypoints = [[0, -1.2, 1, 0, 0, 0], [2, -1.3, 1.2, 0.2, 0.4, 1.2]]
        trajectory = toptraj.plan("ur5", waypoints, constraints=["velocity", "acceleration", "torque"])
        trajectory.duration, trajectory.t, trajectory.q      # s; (n,) and (n, 6) arrays
        trajectory.peak_utilization.torque                   # (6,): peak |tau| / limit
        table = toptraj.plan("ur5", waypoints, format="csv")  # CsvTrajectory: the same columns
        for result in toptraj.compare("ur5", waypoints, methods=["phase_plane", "quintic"]):
            print(result.method, result.duration)
        job = toptraj.submit({"robot": "geering_2r", "path": {"kind": "free", "start": [0, 0], "goal": [0.76, 0]},
                              "timing": {"method": "collocation", "constraints": ["torque"]}})
        done = toptraj.wait(job, progress=lambda fraction, stage: print(f"{fraction:4.0%} {stage}"))
        try:
            toptraj.plan("ur5", [[0] * 6, [9, 0, 0, 0, 0, 0]])
        except ProblemError as problem:
            print(problem.status, problem.detail)  # 422: the waypoint is outside the limits
    ```
"""

from toptraj.client.api import ENDPOINTS, Client
from toptraj.client.bodies import compare_request, trajectory_request
from toptraj.client.errors import ProblemError
from toptraj.client.jobs import Progress
from toptraj.client.resources import BatchItem, Job, JobPage, Limits, Robot, RobotSummary, Skeleton
from toptraj.client.results import (
    Accuracy,
    Binding,
    Clearance,
    Comparison,
    Conditioning,
    CsvTrajectory,
    PhasePlane,
    SwitchPoint,
    Trajectory,
    Utilization,
)

__all__ = [
    "ENDPOINTS",
    "Accuracy",
    "BatchItem",
    "Binding",
    "Clearance",
    "Client",
    "Comparison",
    "Conditioning",
    "CsvTrajectory",
    "Job",
    "JobPage",
    "Limits",
    "PhasePlane",
    "ProblemError",
    "Progress",
    "Robot",
    "RobotSummary",
    "Skeleton",
    "SwitchPoint",
    "Trajectory",
    "Utilization",
    "compare_request",
    "trajectory_request",
]
