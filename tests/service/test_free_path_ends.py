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
