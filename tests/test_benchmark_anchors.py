"""The benchmarks' toppra anchor solves the service's own path: ``benchmarks/anchors.py``'s
spline through the typical request's waypoints is the service's ``SplinePath`` (chord-length
knots, natural ends), positions and both derivatives, to rounding."""

from __future__ import annotations

import numpy as np

from benchmarks.anchors import typical_spline
from tests.conftest import UR5_WAYPOINTS
from toptraj.planners.paths.waypoints import SplinePath


def test_the_toppra_anchor_follows_the_services_spline():
    waypoints = np.array(UR5_WAYPOINTS)
    ours, anchor = SplinePath(waypoints), typical_spline(waypoints)
    s = np.linspace(0.0, 1.0, 1001)
    points = ours.evaluate(s)
    scale = np.abs(waypoints).max()
    assert np.max(np.abs(anchor(s) - points.q)) <= 1e-12 * scale
    assert np.max(np.abs(anchor(s, 1) - points.dq)) <= 1e-10 * scale
    assert np.max(np.abs(anchor(s, 2) - points.ddq)) <= 1e-8 * scale
