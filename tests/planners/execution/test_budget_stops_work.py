"""A 504 stops the work: a real server with a 1.5 s budget, one request per slow family, and the
server's process tree (worker processes included) uses under 0.5 CPU-s in the 2 s after the 504."""

from __future__ import annotations

import time

import numpy as np
import pytest

from tests.conftest import UR5_WAYPOINTS
from tests.live_server import LiveServer

#: Long enough for min_cost to reach its solver (which used to run on for seconds after the 504).
BUDGET_S = 1.5
START = [0.0, -1.2, 1.0, 0.0, 0.0, 0.0]
#: A 0.3 m x 0.2 m rectangle in the ur5's workspace, from the start pose of the end effector.
RECTANGLE = [[0.357, 0.191, 0.77], [0.357, 0.191, 0.47], [0.557, 0.191, 0.47], [0.557, 0.191, 0.77]]


def _via_points() -> list[list[float]]:
    """40 waypoints of a seeded random walk of the ur5, well inside its joint limits."""
    steps = np.random.default_rng(8).uniform(-0.15, 0.15, (40, 6))
    return (np.array(START) + np.cumsum(steps, axis=0)).round(4).tolist()


#: One request per family that used to run on after its 504: via points, min_cost at its
#: largest grid, the IK of a long Cartesian polyline (24 m). The collocation of a free motion and
#: jerk_limited at their largest grids now answer within the budget (the collocation's NLP is
#: built once around a mapped RNEA; jerk refinements start only where the time left allows), so
#: they are not among them; a job of either is killed with its worker process at its budget.
SLOW = {
    "via_points": {
        "robot": "ur5",
        "path": {"kind": "waypoints", "interpolation": "via", "waypoints": _via_points()},
        "timing": {"method": "quintic", "constraints": ["velocity", "acceleration", "torque"]},
    },
    "min_cost": {
        "robot": "ur5",
        "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS},
        "timing": {"method": "min_cost", "grid_points": 4000},
    },
    "cartesian": {
        "robot": "ur5",
        "path": {"kind": "cartesian", "start": START, "positions": [[0.557, 0.191, 0.77]] + RECTANGLE * 20},
        "timing": {"method": "phase_plane"},
    },
}


@pytest.fixture(scope="module")
def server():
    with LiveServer(TOPTRAJ_PLAN_BUDGET_S=str(BUDGET_S), TOPTRAJ_PRELOAD_ROBOTS="false") as live:
        assert live.request("GET", "/v1/robots/ur5")[0] == 200  # the model is loaded before the budget runs
        yield live


@pytest.mark.parametrize("family", SLOW)
def test_the_server_is_idle_after_a_504(server, family):
    server.wait_until_idle()
    status, _, body = server.request("POST", "/v1/trajectories", SLOW[family])
    before = server.cpu_seconds()
    assert status == 504, body[:300]
    time.sleep(2.0)
    used = server.cpu_seconds() - before
    assert used < 0.5, f"{used:.2f} CPU-s in the 2 s after the 504 of {family}"
