"""Geometric paths through waypoints."""

from __future__ import annotations

import numpy as np
import pytest

from toptraj.planners.errors import InvalidRequest
from toptraj.planners.paths import SplinePath, StopAndGoPath
from toptraj.service.problems import detail

WAYPOINTS = np.array([[0.0, 0.0], [1.0, 0.5], [1.5, 2.0], [3.0, 2.5]])


def test_spline_interpolates_and_is_c2():
    path = SplinePath(WAYPOINTS)
    assert path(path.knots) == pytest.approx(WAYPOINTS, abs=1e-12)
    for knot in path.knots[1:-1]:
        left = path.evaluate(np.array([knot - 1e-9]))
        right = path.evaluate(np.array([knot + 1e-9]))
        assert left.dq == pytest.approx(right.dq, abs=1e-6)
        assert left.ddq == pytest.approx(right.ddq, abs=1e-5)
    # Natural ends: no curvature, a tangent that is not zero.
    ends = path.evaluate(np.array([0.0, 1.0]))
    assert ends.ddq == pytest.approx(np.zeros((2, 2)), abs=1e-12)
    assert np.all(np.linalg.norm(ends.dq, axis=1) > 0.1)


def test_spline_derivatives_match_finite_differences():
    path = SplinePath(WAYPOINTS)
    s = np.linspace(0.05, 0.95, 7)
    h = 1e-6
    points = path.evaluate(s)
    assert points.dq == pytest.approx((path(s + h) - path(s - h)) / (2 * h), abs=1e-6)
    assert points.ddq == pytest.approx((path(s + h) - 2 * path(s) + path(s - h)) / h**2, abs=1e-3)


def test_two_waypoint_spline_is_the_straight_joint_line():
    path = SplinePath(WAYPOINTS[:2])
    s = np.linspace(0, 1, 11)
    assert path(s) == pytest.approx(WAYPOINTS[0] + s[:, None] * (WAYPOINTS[1] - WAYPOINTS[0]), abs=1e-12)


def test_linear_path_is_straight_with_corners():
    path = StopAndGoPath(WAYPOINTS)
    assert path(path.knots) == pytest.approx(WAYPOINTS, abs=1e-12)
    assert path.kinks == pytest.approx(path.knots[1:-1])
    mid = 0.5 * (path.knots[1] + path.knots[2])
    assert path(np.array([mid]))[0] == pytest.approx(0.5 * (WAYPOINTS[1] + WAYPOINTS[2]))
    corner = np.array([path.knots[1]])
    left, right = path.evaluate(corner, "left").dq[0], path.evaluate(corner, "right").dq[0]
    def cross(u, v):
        return u[0] * v[1] - u[1] * v[0]

    assert cross(left, WAYPOINTS[1] - WAYPOINTS[0]) == pytest.approx(0.0, abs=1e-12)
    assert cross(right, WAYPOINTS[2] - WAYPOINTS[1]) == pytest.approx(0.0, abs=1e-12)


def test_continuous_joints_are_not_wrapped():
    path = SplinePath(np.array([[0.0, 0.0], [0.5, -2 * np.pi]]))
    assert path(np.array([1.0]))[0] == pytest.approx([0.5, -2 * np.pi])


def test_coincident_waypoints_are_refused():
    with pytest.raises(InvalidRequest) as refused:
        SplinePath(np.array([[0.0, 0.0], [1.0, 1.0], [1.0, 1.0]]))
    assert (refused.value.field, refused.value.rule, refused.value.index) == ("waypoints[1]", "waypoints_coincide", 1)
    assert refused.value.tolerance == 1e-12
    assert detail(refused.value) == (
        "path.waypoints[1] and path.waypoints[2] coincide (no joint differs by more than 1e-12 rad or m), so the path "
        "has no direction between them: remove path.waypoints[2], or change one of its joint values by more than 1e-12"
    )


def test_waypoints_apart_by_the_advised_step_make_a_path():
    """The advice of the refusal above is followable: one joint value moved by just more than the
    tolerance makes a path."""
    path = SplinePath(np.array([[0.0, 0.0], [1.0, 1.0], [1.0, 1.0 + 2e-12]]))
    assert path.knots[-1] == 1.0


@pytest.mark.parametrize("count", [2, 3, 4, 7, 40])
def test_spline_coefficients_equal_scipys_natural_cubic_spline(count):
    """The compiled tridiagonal solve gives scipy's natural cubic spline, to rounding."""
    from scipy.interpolate import CubicSpline

    rng = np.random.default_rng(count)
    for _ in range(10):
        waypoints = rng.uniform(-3.0, 3.0, (count, 6))
        path = SplinePath(waypoints)
        reference = CubicSpline(path.knots, waypoints, axis=0, bc_type="natural")
        s = np.linspace(0.0, 1.0, 301)
        points = path.evaluate(s)
        scale = np.max(np.abs(reference.c))
        assert np.max(np.abs(points.q - reference(s))) <= 1e-12 * scale
        assert np.max(np.abs(points.dq - reference(s, 1))) <= 1e-12 * scale
        assert np.max(np.abs(points.ddq - reference(s, 2))) <= 1e-12 * scale


@pytest.mark.parametrize("seed", range(4))
def test_spline_finds_where_it_lies_farthest_outside_a_range(seed):
    """A spline's farthest point beyond a joint range, found from its pieces' extremes, is the
    one a sampling at 400,001 values of s finds (to the sampling's resolution), and a range the
    spline stays within gives none; the sampled search of other paths finds a point outside
    the same range."""
    rng = np.random.default_rng(seed)
    waypoints = rng.uniform(-1.0, 1.0, (5, 3))
    path = SplinePath(waypoints)
    dense = np.linspace(0.0, 1.0, 400_001)
    q = path(dense)
    # Each range just inside the waypoints' own span: only the overshoot between them leaves it.
    lower, upper = waypoints.min(axis=0) + 0.05, waypoints.max(axis=0) - 0.05
    excess = np.maximum(q - upper, lower - q)
    row, joint = np.unravel_index(np.argmax(excess), excess.shape)
    at, found_joint, value = path.outside_range(lower, upper, 0)
    assert found_joint == joint
    assert at == pytest.approx(dense[row], abs=2.5e-6)
    assert value == pytest.approx(q[row, joint], abs=1e-9)
    assert max(value - upper[joint], lower[joint] - value) >= excess[row, joint]
    assert path.outside_range(q.min(axis=0) - 1e-6, q.max(axis=0) + 1e-6, 0) is None
    assert StopAndGoPath(waypoints).outside_range(lower, upper, 101) is not None
