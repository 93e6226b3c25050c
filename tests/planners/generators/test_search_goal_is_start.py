"""A search whose allowed goals include the start itself: with ``path.revolutions`` a goal
whole revolutions of the continuous joints away from the start (the start itself, or the start
plus 2 pi) is reached by staying put, so there is no motion to search. It was answered with a
full revolution of the elbow (1.15 s on the Geering arm), a motion slower than the allowed one
and stated as within 0.04 % of the optimum. The 422 says how to ask for the revolution."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from toptraj import robots
from toptraj.planners.errors import InvalidRequest
from toptraj.planners.generators.search import build_problem
from toptraj.planners.generators.search.graph import SearchOptions
from toptraj.service.problems import detail

GEERING = robots.load("geering_2r")  # phi revolute (+-2 pi), psi continuous
OPTIONS = SearchOptions(tubes=1)


def _build(goal, revolutions):
    return build_problem(
        GEERING, GEERING.limits, ("torque",), np.zeros(2), np.asarray(goal, dtype=float), OPTIONS, revolutions
    )


@pytest.mark.parametrize("goal", [[0.0, 0.0], [0.0, 2.0 * math.pi], [0.0, -2.0 * math.pi]])
def test_a_goal_that_is_the_start_up_to_revolutions_is_refused(goal):
    with pytest.raises(InvalidRequest) as refused:
        _build(goal, revolutions=True)
    assert (refused.value.field, refused.value.rule) == ("goal", "goal_is_start_turned")
    assert re.search("no motion to search.*path.revolutions false", detail(refused.value))


def test_the_advice_plans_the_revolution():
    problem = _build([0.0, 2.0 * math.pi], revolutions=False)
    goals = problem.graph.points[problem.graph.goals]
    np.testing.assert_allclose(goals, [[0.0, 2.0 * math.pi]])


def test_http_answers_422(client):
    body = {
        "robot": "geering_2r",
        "path": {"kind": "free", "start": [0.0, 0.0], "goal": [0.0, 0.0]},
        "timing": {"method": "search", "constraints": ["torque"], "search": {"tubes": 1}},
    }
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 422, response.text
    assert "no motion to search" in response.json()["detail"]
