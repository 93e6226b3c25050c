"""The request examples of ``examples/`` (kept in ``service/examples`` so that they ship with
the package), as OpenAPI examples of the endpoints they are bodies of: each is answered by the
tests (``tests/service/test_examples.py``), so every example in ``/docs`` works."""

from __future__ import annotations

import json
from pathlib import Path

DIRECTORY = Path(__file__).resolve().parents[1] / "examples"

#: A line of ``/docs`` per example file (file stem: summary).
SUMMARIES = {
    "ur5_spline": "ur5: spline through 4 waypoints, time-optimal under velocity, acceleration and torque limits",
    "lecture_cartesian_line": "lecture arm: a Cartesian straight line through inverse kinematics",
    "yamamoto_min_cost": "Yamamoto's arm: minimum time plus energy (beta = 0.03) along a straight line",
    "geering_free_motion": "Geering's arm: free path, path and timing optimized together (tens of seconds; see /v1/jobs)",
    "ur5_jerk_limited": "ur5: the spline example under a jerk limit too (jerk_limited)",
    "compare_methods": "several methods on one path",
    "ur5_spline_obstacles": "ur5: the spline example above a table and beside a pole, keeping 2 cm of clearance (min_clearance in the answer)",
    "ur5_ceiling_payload": "ur5 hanging from the ceiling with a 2.5 kg tool: the spline example, torques with the payload and gravity as the base feels it",
    "geering_search_obstacle": "Geering's arm around a sphere: the global search among obstacles, then local optimization (tens of seconds; see /v1/jobs)",
    "cell_two_ur5": "two ur5 facing each other across a table, crossing paths, kept 2 cm apart",
}


def _load() -> dict[str, dict]:
    return {path.stem: json.loads(path.read_text()) for path in sorted(DIRECTORY.glob("*.json"))}


def openapi_examples(compare: bool) -> dict[str, dict]:
    """The examples that are compare bodies (they name ``methods``), or the others (cell
    bodies, which name ``arms``, apart)."""
    return {
        stem: {"summary": SUMMARIES.get(stem, stem.replace("_", " ")), "value": body}
        for stem, body in _load().items()
        if ("methods" in body) == compare and "arms" not in body
    }


def cell_examples() -> dict[str, dict]:
    """The examples that are ``POST /v1/cells`` bodies (they name ``arms``)."""
    return {
        stem: {"summary": SUMMARIES.get(stem, stem.replace("_", " ")), "value": body}
        for stem, body in _load().items()
        if "arms" in body
    }
