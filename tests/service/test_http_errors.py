"""Every class of bad input gets a problem+json 4xx that says what and where, never a 500."""

from __future__ import annotations

import pytest

from tests.conftest import UR5_WAYPOINTS
from toptraj.service.app import create_app
from toptraj.service.settings import Settings

GOOD_PATH = {"kind": "waypoints", "waypoints": UR5_WAYPOINTS[:2]}


def _post(client, body, **kwargs):
    response = client.post("/v1/trajectories", json=body, **kwargs)
    assert response.headers["content-type"] == "application/problem+json", response.text
    problem = response.json()
    assert problem["status"] == response.status_code
    assert {"type", "title", "status", "detail"} <= set(problem)
    return response.status_code, problem["detail"], problem


@pytest.mark.parametrize(
    "body, status, words",
    [
        ({"robot": "nope", "path": GOOD_PATH}, 404, ["no robot named 'nope'", "ur5"]),
        ({"robot": "ur5", "path": {"waypoints": [[0.0] * 5, [0.1] * 5]}}, 422, ["waypoints[0] has 5 values", "6 joints"]),
        ({"robot": "ur5", "path": {"waypoints": [[0.0] * 6, [0.1] * 5]}}, 422, ["waypoints[1] has 5 values"]),
        ({"robot": "ur5", "path": {"waypoints": [[0.0] * 6]}}, 422, ["path.waypoints", "at least 2"]),
        ({"robot": "ur5", "path": {"waypoints": []}}, 422, ["path.waypoints", "at least 2"]),
        ({"robot": "ur5", "path": {"waypoints": [[0.0] * 6, [0.0] * 6]}}, 422, ["waypoints[0] and path.waypoints[1] coincide", "give a waypoint that differs from path.waypoints[0] by more than 1e-12 rad or m in some joint"]),
        ({"robot": "ur5", "path": {"waypoints": [[0.0] * 6, [0, 0, 3.5, 0, 0, 0]]}}, 422, ["waypoints[1][2] = 3.5", "elbow_joint"]),
        ({"robot": "ur5", "path": GOOD_PATH, "timing": {"method": "magic"}}, 422, ["timing.method", "not 'magic'", "toppra"]),
        ({"robot": "ur5", "path": GOOD_PATH, "timing": {"constraints": ["jerkiness"]}}, 422, ["timing.constraints[0]"]),
        ({"robot": "ur5", "path": GOOD_PATH, "timing": {"constraints": []}}, 422, ["timing.constraints is empty"]),
        ({"robot": "ur5", "path": {"kind": "teleport", "waypoints": UR5_WAYPOINTS}}, 422, ["path.kind"]),
        ({"robot": "ur5", "path": {"waypoints": [[0.0] * 6] + [[0.001 * k] * 6 for k in range(1, 1001)]}}, 422, ["path.waypoints", "at most 1000"]),
        ({"robot": "ur5", "path": GOOD_PATH, "timing": {"grid_points": 10**7}}, 422, ["timing.grid_points"]),
        ({"robot": "ur5", "path": GOOD_PATH, "output": {"dt": 0}}, 422, ["output.dt"]),
        ({"robot": "ur5", "path": GOOD_PATH, "output": {"dt": 1e-9}}, 422, ["output.dt"]),
        ({"robot": "ur5", "path": GOOD_PATH, "timing": {"limits": {"velocity": [1.0, 1.0]}}}, 422, ["timing.limits.velocity has 2 values"]),
        ({"robot": "ur5", "path": GOOD_PATH, "timing": {"limits": {"torque_scale": -1}}}, 422, ["timing.limits.torque_scale"]),
        ({"robot": "ur5", "path": GOOD_PATH, "timing": {"boundary": {"start_velocity": [0.1, 0, 0, 0, 0, 0]}}}, 422, ["start_velocity is not tangent"]),
        ({"robot": "ur5", "path": GOOD_PATH, "timing": {"duration": 2.0}}, 422, ["timing.duration is not used"]),
        ({"robot": "ur5", "path": GOOD_PATH, "surprise": 1}, 422, ["surprise"]),
        ({"path": GOOD_PATH}, 422, ["robot", "Field required"]),
        ({"robot": "geering_2r", "path": {"waypoints": [[0, 0], [0, 1e300]]}}, 422, ["path.waypoints[1][1]", "within"]),
        ({"robot": "ur5", "path": GOOD_PATH, "timing": {"method": "min_cost", "cost": {"torque_weight": 1e12}}}, 422, ["timing.cost.torque_weight"]),
        ({"robot": "ur5", "path": GOOD_PATH, "timing": {"method": "trapezoidal", "trapezoid": {"tau1": 0.8, "tau2": 0.2}}}, 422, ["tau1 <= tau2"]),
        (
            {"robot": "ur5", "path": GOOD_PATH, "timing": {"method": "ruckig", "constraints": ["velocity", "torque"]}}, 422,
            ["cannot limit torque", "drop 'torque' from timing.constraints (e.g. ['velocity'])", "use timing.method 'jerk_limited'"],
        ),
        ({"robot": "ur5", "path": GOOD_PATH, "timing": {"method": "phase_plane", "constraints": ["jerk"]}}, 422, ["cannot limit jerk"]),
        ({"robot": "ur5", "path": {"waypoints": UR5_WAYPOINTS, "interpolation": "via"}, "timing": {"method": "toppra"}}, 422, ["via points need"]),
    ],
)
def test_bad_input_is_a_clear_4xx(client, body, status, words):
    code, detail, _ = _post(client, body)
    assert code == status, detail
    for word in words:
        assert word in detail, detail


@pytest.mark.parametrize("literal", [b"NaN", b"Infinity", b"-Infinity", b"1e999"])
def test_non_finite_numbers_are_refused(client, literal):
    body = b'{"robot": "ur5", "path": {"waypoints": [[0, 0, 0, 0, 0, 0], [0.1, 0.2, ' + literal + b', 0, 0, 0]]}}'
    response = client.post("/v1/trajectories", content=body, headers={"content-type": "application/json"})
    assert response.status_code == 422
    assert "path.waypoints[1][2]" in response.json()["detail"]


def test_malformed_json(client):
    response = client.post("/v1/trajectories", content=b'{"robot": ', headers={"content-type": "application/json"})
    assert response.status_code == 422
    assert response.headers["content-type"] == "application/problem+json"


def test_spline_overshooting_joint_limits_says_where(client):
    waypoints = [[0, 0, 0, 0, 0, 0], [0, 0, 3.1, 0, 0, 0], [0, 0, 3.14, 0, 0, 0], [0, 0, 0, 0, 0, 0]]
    code, detail, problem = _post(client, {"robot": "ur5", "path": {"waypoints": waypoints}})
    assert code == 422
    assert "leaves the range" in detail and "elbow_joint" in detail and "s = " in detail
    assert problem["joint"] == "elbow_joint"


def test_gravity_above_the_torque_limit_says_where_and_which_joint(client):
    body = {
        "robot": "yamamoto_2r",
        "path": {"waypoints": [[0.0, 0.0], [1.5, 0.0]]},
        "timing": {"constraints": ["torque"], "limits": {"torque_scale": 0.1}},
    }
    code, detail, problem = _post(client, body)
    assert code == 422
    assert "holding still at s = 1.0000 needs 3.914 N m on joint 'theta1'" in detail
    assert problem["joint"] == "theta1" and 0.9 <= problem["s"] <= 1.0


def test_body_too_large(client):
    response = client.post(
        "/v1/trajectories", content=b" " * 3_000_000, headers={"content-type": "application/json"}
    )
    assert response.status_code == 413
    assert response.headers["content-type"] == "application/problem+json"


def test_body_too_large_without_content_length(client):
    def chunks():
        for _ in range(40):
            yield b" " * 100_000

    response = client.post("/v1/trajectories", content=chunks(), headers={"content-type": "application/json"})
    assert response.status_code == 413


def test_unknown_route_and_method(client):
    assert client.get("/v2/nothing").status_code == 404
    assert client.get("/v2/nothing").headers["content-type"] == "application/problem+json"
    assert client.delete("/health").status_code == 405


def test_over_the_time_budget_is_504():
    from fastapi.testclient import TestClient

    app = create_app(Settings(preload_robots=False, plan_budget_s=0.001))
    waypoints = [[0.001 * k, -1.5 + 0.002 * k, 1.0, 0, 0, 0] for k in range(400)]
    with TestClient(app) as slow_client:
        code, detail, _ = _post(
            slow_client,
            {"robot": "ur5", "path": {"waypoints": waypoints}, "timing": {"grid_points": 20000}},
        )
    assert code == 504
    assert "time budget" in detail


def test_the_service_picks_the_status_not_the_library(client, monkeypatch):
    """The HTTP status of a library error comes from the service's table (``toptraj.service.problems.STATUS``),
    never from an attribute of the library's class: changing that attribute changes no answer."""
    from toptraj.planners.errors import BudgetExceeded
    from toptraj.robots.errors import UnknownRobot
    from toptraj.service.problems import status_of

    monkeypatch.setattr(UnknownRobot, "status", 418, raising=False)
    monkeypatch.setattr(BudgetExceeded, "status", 418, raising=False)
    status, detail, _ = _post(client, {"robot": "nope", "path": GOOD_PATH})
    assert (status, "no robot named 'nope'" in detail) == (404, True)
    assert status_of(BudgetExceeded("spent")) == 504


@pytest.mark.parametrize(
    ("path", "method", "words"),
    [
        ({"kind": "waypoints", "waypoints": [[0, -1.2, 1, 0, 0.5, 0], [1, -1, 1.4, -0.5, 0.9, 0.3]]}, "collocation",
         "timing.method 'collocation' finds the path itself: give a free path (path.kind 'free', start and goal)"),
        ({"kind": "free", "start": [0, -1.2, 1, 0, 0.5, 0], "goal": [1, -1, 1.4, -0.5, 0.9, 0.3]}, "toppra",
         "needs timing.method 'collocation' or 'search', not 'toppra'; for 'toppra' give the path itself"),
    ],
)
def test_a_method_and_a_path_kind_that_do_not_pair_say_which_fits(client, path, method, words):
    response = client.post("/v1/trajectories", json={"robot": "ur5", "path": path, "timing": {"method": method}})
    assert response.status_code == 422, response.text
    assert words in response.json()["detail"], response.json()["detail"]


def test_a_cartesian_line_of_a_frame_the_robot_lacks_names_the_nearest_and_all(client):
    path = {"kind": "cartesian", "frame": "tool1", "start": [0.0, -1.2, 1.0, 0.0, 0.5, 0.0],
            "positions": [[0.4, 0.1, 0.4], [0.4, 0.2, 0.4]]}
    response = client.post("/v1/trajectories", json={"robot": "ur5", "path": path})
    assert response.status_code == 422, response.text
    detail = response.json()["detail"]
    assert "path.frame 'tool1' is not a frame of ur5 (did you mean 'tool0'?); its frames are" in detail, detail
    assert "'ee_link'" in detail


def test_empty_constraints_say_what_to_list_and_the_advice_plans(client):
    path = {"kind": "waypoints", "waypoints": [[0, -1.2, 1, 0, 0.5, 0], [1, -1, 1.4, -0.5, 0.9, 0.3]]}
    refused = client.post("/v1/trajectories", json={"robot": "ur5", "path": path, "timing": {"constraints": []}})
    assert refused.status_code == 422
    assert 'e.g. ["velocity", "acceleration", "torque"], or leave it out' in refused.json()["detail"]
    for timing in ({"constraints": ["velocity", "acceleration", "torque"]}, {}):
        assert client.post("/v1/trajectories", json={"robot": "ur5", "path": path, "timing": timing}).status_code == 200
