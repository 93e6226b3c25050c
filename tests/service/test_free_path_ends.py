"""A free path's start or goal that cannot be planned from is refused as a waypoint would be:
the joint, its value and its range; the link, the obstacle and the distance."""

from __future__ import annotations


def test_a_search_start_inside_an_obstacle_names_the_link_and_the_obstacle(client):
    body = {
        "robot": "ur5",
        "path": {
            "kind": "free", "start": [0.0, -1.2, 1.0, 0.0, 0.5, 0.0], "goal": [1.0, -1.2, 1.0, 0.0, 0.5, 0.0],
            "obstacles": [{"kind": "sphere", "center": [2.0, 2.0, 2.0], "radius": 0.1},
                          {"kind": "sphere", "center": [0.54, 0.11, 0.56], "radius": 0.1}],
        },
        "timing": {"method": "search"},
    }
    answer = client.post("/v1/trajectories", json=body)
    assert answer.status_code == 422, answer.text
    detail = answer.json()["detail"]
    assert detail.startswith("at path.start, link '") and " is inside path.obstacles[1] (by " in detail, detail
    assert detail.endswith("(the clearance is 0.01 m): move path.start away from the obstacle")


def test_a_collocation_goal_outside_the_joint_limits_names_joint_value_and_range(client):
    body = {
        "robot": "panda",
        "path": {"kind": "free", "start": [0.0, -0.5, 0.0, -2.0, 0.0, 1.6, 0.8], "goal": [0.0, -0.5, 0.0, 0.5, 0.0, 1.6, 0.8]},
        "timing": {"method": "collocation"},
    }
    answer = client.post("/v1/trajectories", json=body)
    assert answer.status_code == 422, answer.text
    assert answer.json()["detail"] == "path.goal[3] = 0.5 is outside the limits [-3.0718, -0.0698] of joint 'panda_joint4'"


def _ur5_free(obstacle: dict, clearance: float = 0.01) -> dict:
    return {
        "robot": "ur5",
        "path": {
            "kind": "free", "start": [0.0, -1.2, 1.0, 0.0, 0.5, 0.0], "goal": [1.0, -1.2, 1.0, 0.0, 0.5, 0.0],
            "obstacles": [obstacle], "clearance": clearance,
        },
        "timing": {"method": "search"},
    }


def test_a_start_inside_an_obstacle_names_a_link_of_the_urdf(client):
    from toptraj import robots

    answer = client.post("/v1/trajectories", json=_ur5_free({"kind": "sphere", "center": [0.54, 0.11, 0.56], "radius": 0.1}))
    assert answer.status_code == 422, answer.text
    link = answer.json()["link"]
    assert link in {frame.name for frame in robots.load("ur5").model.frames}, link


def test_an_obstacle_around_the_fixed_base_is_advised_away_not_the_start(client):
    """No start moves the base: the advice is to move the obstacle or the robot."""
    answer = client.post("/v1/trajectories", json=_ur5_free({"kind": "box", "center": [0.0, 0.0, 0.0], "size": [0.3, 0.3, 0.05]}))
    assert answer.status_code == 422, answer.text
    body = answer.json()
    assert body["link"] == "base_link", body
    assert body["detail"].endswith(
        "no joint moves that link: move path.obstacles[0] away from it, or the robot by its mounting"
    ), body["detail"]


def test_a_start_just_within_the_clearance_is_advised_a_clearance_it_keeps(client):
    """The advised clearance, followed, lets the start through."""
    obstacle = {"kind": "sphere", "center": [0.54, 0.11, 0.9], "radius": 0.05}
    first = client.post("/v1/trajectories", json=_ur5_free(obstacle, clearance=0.5))
    assert first.status_code == 422, first.text
    detail = first.json()["detail"]
    assert detail.startswith("at path.start") and "or lower path.clearance to " in detail, detail
    advised = float(detail.rsplit("or lower path.clearance to ", 1)[1].removesuffix(" m"))
    assert 0.0 < advised < 0.5
    again = client.post("/v1/trajectories", json=_ur5_free(obstacle, clearance=advised))
    assert not (again.status_code == 422 and again.json()["detail"].startswith("at path.start")), again.text
