"""The shortcuts of the typical request compute the numbers of the long way, to rounding: the
spline's one-pass evaluation against SciPy's ``CubicSpline``, the dense check's states against
their array formulas, and its torques read from the grid rows against Pinocchio's RNEA at every
state (friction included); more on the rows' interpolation between grid points in
``test_torque_interpolation.py``."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import CubicSpline

from tests.paths import DATA
from toptraj import robots
from toptraj.planners.checks.limit_check import _torques, check_limits, joint_motion
from toptraj.planners.checks.limit_kernels import utilization_pass
from toptraj.planners.constraints.path_constraints import build_path_constraints
from toptraj.planners.paths import SplinePath
from toptraj.planners.paths.grid import path_grid
from toptraj.planners.timing import PhasePlaneMethod, ToppraMethod
from toptraj.planners.timing.base import TimeScaling
from toptraj.robots.catalog import robot_from_model
from toptraj.robots.urdf_check import check_urdf

KINDS = ("velocity", "acceleration", "torque")
#: Largest error of a torque interpolated from the rows, as a fraction of the joint's torque
#: limit (``test_torque_interpolation.py`` states the same).
INTERPOLATION = 1e-5


@pytest.mark.parametrize("count", [2, 3, 5, 12])
def test_spline_evaluation_matches_scipy(count):
    rng = np.random.default_rng(count)
    path = SplinePath(rng.normal(size=(count, 6)))
    reference = CubicSpline(path.knots, path.waypoints, axis=0, bc_type="natural")
    s = np.concatenate([rng.uniform(0.0, 1.0, 500), path.knots])
    points = path.evaluate(s)
    for order, values in enumerate([points.q, points.dq, points.ddq, path.third_derivative(s)]):
        expected = reference(s, order)
        assert np.abs(values - expected).max() <= 1e-12 * max(1.0, np.abs(expected).max())


def _friction_pendulum():
    text = (DATA / "pendulum_1r.urdf").read_text()
    return robot_from_model("pendulum_1r", check_urdf(text), "upload", None)


@pytest.mark.parametrize("name", ["ur5", "panda", "yamamoto_2r", "pendulum_1r"])
@pytest.mark.parametrize("method", [PhasePlaneMethod(), ToppraMethod()], ids=["phase_plane", "toppra"])
def test_dense_check_torques_from_rows_equal_rnea(name, method):
    """At the grid points the torques are the rows' own numbers; between them the rows'
    interpolation stays within its tolerance of RNEA (Coulomb friction included)."""
    robot = _friction_pendulum() if name == "pendulum_1r" else robots.load(name)
    assert name != "pendulum_1r" or np.any(robot.coulomb_friction) and np.any(robot.viscous_friction)
    rng = np.random.default_rng(5)
    lower = np.maximum(robot.limits.position_lower, -2.0)
    upper = np.minimum(robot.limits.position_upper, 2.0)
    path = SplinePath(rng.uniform(0.5 * lower, 0.5 * upper, (4, robot.dof)))
    constraints = build_path_constraints(path, robot, robot.limits, KINDS, path_grid(path))
    timing = method.solve(constraints)
    states = timing.dense_states(7, constraints.s)
    q, qd, qdd, _ = joint_motion(path, states)
    from_rows = _torques(robot, states, q, qd, qdd, constraints)
    everywhere = robot.inverse_dynamics(q, qd, qdd)
    on_grid = np.isin(states.s, constraints.s)
    assert np.abs(from_rows - everywhere)[on_grid].max() <= 1e-12 * np.abs(everywhere).max()
    assert np.all(np.abs(from_rows - everywhere) <= INTERPOLATION * robot.limits.torque)
    fast = check_limits(path, timing, robot, robot.limits, KINDS, 1.003, constraints.s, constraints)
    slow = check_limits(path, timing, robot, robot.limits, KINDS, 1.003, constraints.s)
    for kind in ("velocity", "acceleration"):
        np.testing.assert_array_equal(fast.utilization[kind], slow.utilization[kind])
    np.testing.assert_allclose(fast.utilization["torque"], slow.utilization["torque"], rtol=0, atol=INTERPOLATION)


def test_utilization_pass_equals_the_numpy_reduction():
    """The compiled pass of the dense check against |value| / limit in numpy: the peak of each
    joint, the worst state and joint, and the states beyond the threshold, with unlimited
    joints (inf), a zero limit, infinite and NaN values (NaN ratios count as 0)."""
    rng = np.random.default_rng(8)
    value = rng.normal(0.0, 1.0, (400, 5))
    value[17, 2], value[30, 1], value[41, 4], value[50, 0] = np.inf, np.nan, np.inf, 0.0
    limit = np.array([0.0, 2.0, 1.5, np.inf, np.inf])
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.nan_to_num(np.abs(value) / limit, nan=0.0, posinf=np.inf)
    over = np.zeros(400, dtype=bool)
    over[3] = True  # set by an earlier kind: kept
    peak = np.empty(5)
    worst, state, joint = utilization_pass(value, limit, 1.2, peak, over)
    np.testing.assert_array_equal(peak, ratio.max(axis=0))
    per_state = ratio.max(axis=1)
    assert (worst, state, joint) == (per_state.max(), int(np.argmax(per_state)), int(np.argmax(ratio[np.argmax(per_state)])))
    expected = per_state > 1.2
    expected[3] = True
    np.testing.assert_array_equal(over, expected)


def _dense_states_in_numpy(s, sd, sdd, reference, points):
    """The dense states as array operations: each interval split into ceil((points - 1) w / w_ref)
    parts (at least one; w_ref the width of the reference interval holding its middle), x = sd^2
    linear in s across it."""
    widths = np.diff(s)
    if reference is None:
        parts = np.full(len(widths), points - 1)
    else:
        holder = np.clip(np.searchsorted(reference, 0.5 * (s[:-1] + s[1:])) - 1, 0, len(reference) - 2)
        parts = np.clip(np.ceil((points - 1) * widths / np.diff(reference)[holder] - 1e-9), 1, None).astype(int)
    interval = np.repeat(np.arange(len(widths)), parts + 1)
    step = np.arange(len(interval)) - np.repeat(np.cumsum(parts + 1) - (parts + 1), parts + 1)
    fraction = step / parts[interval]
    x = sd[interval] ** 2 + fraction * (sd[interval + 1] ** 2 - sd[interval] ** 2)
    return (s[interval] + fraction * widths[interval], np.sqrt(np.maximum(x, 0.0)), sdd[interval], step == parts[interval], interval)


@pytest.mark.parametrize("seed", range(6))
def test_dense_states_of_a_grid_timing_equal_the_array_formulas(seed):
    """``TimeScaling.dense_states`` (one compiled pass) against the same states built with
    array operations, bit for bit: random grids and speeds, with and without a coarser reference
    grid, 2 to 7 states per interval."""
    rng = np.random.default_rng(seed)
    s = np.unique(np.concatenate(([0.0, 1.0], rng.uniform(0.0, 1.0, int(rng.integers(1, 80))))))
    sd = rng.uniform(0.05, 3.0, len(s))
    sd[0] = sd[-1] = 0.0
    timing = TimeScaling(s, sd)
    inner = rng.choice(s[1:-1], size=min(len(s) - 2, int(rng.integers(0, 12))), replace=False)
    for reference in (None, np.unique(np.concatenate(([0.0, 1.0], inner)))):
        for points in (2, 5, 7):
            states = timing.dense_states(points, reference)
            expected = _dense_states_in_numpy(s, sd, timing.sdd, reference, points)
            for got, want in zip((states.s, states.sd, states.sdd, states.left, states.interval), expected):
                np.testing.assert_array_equal(got, want)


def test_dense_torques_do_not_depend_on_the_order_of_the_states():
    """The torque interpolation steps from one state's grid interval to the next; states in
    random order (searched for) get the torques and the RNEA marks they get in order."""
    robot = robots.load("ur5")
    path = SplinePath(np.array([[0.0, -1.2, 1.0, 0.0, 0.5, 0.0], [0.8, -1.0, 1.4, -0.5, 0.6, 0.3], [1.5, -0.5, 0.8, -1.0, 1.0, 0.8]]))
    constraints = build_path_constraints(path, robot, robot.limits, KINDS, path_grid(path))
    timing = PhasePlaneMethod().solve(constraints)
    states = timing.dense_states(5, constraints.s)
    q, qd, qdd, _ = joint_motion(path, states)
    in_order = _torques(robot, states, q, qd, qdd, constraints)
    shuffle = np.random.default_rng(3).permutation(len(states.s))
    shuffled = type(states)(*(None if field is None else field[shuffle] for field in
                              (states.s, states.sd, states.sdd, states.sddd, states.left, states.interval)))
    np.testing.assert_array_equal(_torques(robot, shuffled, q[shuffle], qd[shuffle], qdd[shuffle], constraints), in_order[shuffle])
