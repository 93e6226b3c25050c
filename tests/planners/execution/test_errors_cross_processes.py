"""Errors raised in a worker process (``toptraj.planners.execution.isolated.run_isolated``: the search, min_cost,
collocation) cross back to the caller by pickling. An error whose constructor takes more than
its detail (the search's NoGridPath, with its statistics) failed to unpickle, and the request
became a 500 ("an unexpected TypeError"): ur5 with a roadmap of 2 points. Every ToptrajError
now crosses whole: its class, detail and attributes."""

from __future__ import annotations

import pickle

import pytest

from toptraj.planners.errors import InfeasiblePath, OutOfRange, OverMemory, WrongLength
from toptraj.planners.generators.search.outcome import NoGridPath
from toptraj.robots.errors import UnknownRobot

UR5_START = [-1.0, -1.2, 1.5, -1.9, -1.57, 0.0]
UR5_GOAL = [1.0, -1.2, 1.5, -1.9, -1.57, 0.0]


@pytest.mark.parametrize(
    "error",
    [
        NoGridPath("no grid path reaches the goal", statistics=None),  # type: ignore[arg-type]
        InfeasiblePath("cannot follow", s=0.25, joint="elbow_joint", limit="torque"),
        UnknownRobot("nope", ["ur5", "panda"]),
        OverMemory("x" * 5_000),
        OutOfRange("sampling.dt", 5e-324, 1e-6, 10.0, "s"),
        WrongLength("waypoints[0]", [0.0], 1, 6, robot="ur5"),
    ],
    ids=lambda error: type(error).__name__,
)
def test_an_error_survives_pickling_whole(error):
    copy = pickle.loads(pickle.dumps(error))
    assert type(copy) is type(error)
    assert str(copy) == str(error)
    assert copy.__dict__ == error.__dict__


@pytest.mark.parametrize("roadmap", [{"roadmap_points": 2, "neighbors": 1}, {"roadmap_points": 1, "neighbors": 50}])
def test_a_search_with_no_grid_path_in_its_worker_is_a_422(client, roadmap):
    body = {
        "robot": "ur5",
        "path": {"kind": "free", "start": UR5_START, "goal": UR5_GOAL,
                 "obstacles": [{"kind": "box", "center": [0.626, 0.109, 0.29], "size": [0.15, 0.15, 0.15]}]},
        "timing": {"method": "search", "search": {"graph": "roadmap", "tubes": 1, **roadmap}},
    }
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 422, response.text
    assert "grid path" in response.json()["detail"]
