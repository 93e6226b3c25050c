"""The advice of a search that finds no grid path names the settings of its graph: a roadmap
has no cells (timing.search.cells is a lattice's), so it is told to raise its points or
neighbours."""

from __future__ import annotations

UR5_START = [-1.0, -1.2, 1.5, -1.9, -1.57, 0.0]
UR5_GOAL = [1.0, -1.2, 1.5, -1.9, -1.57, 0.0]
BOX = {"kind": "box", "center": [0.626, 0.109, 0.29], "size": [0.15, 0.15, 0.15]}


def _roadmap(points: int, neighbors: int) -> dict:
    return {
        "robot": "ur5",
        "path": {"kind": "free", "start": UR5_START, "goal": UR5_GOAL, "obstacles": [BOX], "clearance": 0.02},
        "timing": {"method": "search", "search": {"graph": "roadmap", "tubes": 1, "roadmap_points": points, "neighbors": neighbors}},
    }


def test_a_roadmap_without_a_path_is_told_to_grow_its_roadmap(client):
    response = client.post("/v1/trajectories", json=_roadmap(2, 1))
    assert response.status_code == 422, response.text
    detail = response.json()["detail"]
    assert "raise timing.search.roadmap_points or timing.search.neighbors" in detail
    assert "cells" not in detail
