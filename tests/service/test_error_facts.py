"""Errors carry facts; the service words them (docs/design.md §2.3).

The library raises with its own field names and the facts of the rule broken (value, bounds,
lengths, the method and what it serves); ``toptraj.service.problems`` maps the fields to the request's,
words every rule and picks the status. Checked here: the facts of a representative set of
errors raised by ``plan`` and the checks it calls, that every rule raised in ``planners/`` and
``robots/`` has a wording and every wording a rule, that advice given as data lies in its
field's range, and that ``docs/measures/vocabulary.py`` finds no request field and no HTTP
status in the library.
"""

from __future__ import annotations

import ast
import pickle
import subprocess
import sys

import numpy as np
import pytest

from tests.paths import ROOT
from toptraj import robots
from toptraj.planners import (
    BoundaryStates,
    Deadline,
    LimitRequest,
    Sampling,
    TimeLaw,
    WaypointPath,
    build_problem,
    plan,
)
from toptraj.planners.checks.gate import limit_exceeded
from toptraj.planners.checks.limit_check import Excess
from toptraj.planners.errors import (
    BudgetExceeded,
    Conflicting,
    InfeasiblePath,
    InvalidRequest,
    LimitExceeded,
    NotOneOf,
    NotServed,
    OutOfRange,
    OutsideJointRange,
    TooLarge,
    WrongLength,
)
from toptraj.planners.execution.memory import MEMORY_CAP_BYTES
from toptraj.planners.generators.search.graph import DEFAULT_SEARCH_MEMORY
from toptraj.planners.paths import SplinePath
from toptraj.planners.paths.grid import MAX_POINTS
from toptraj.planners.problem.ranges import DT, SCALE
from toptraj.planners.timing import METHODS
from toptraj.robots.errors import InvalidInput, ToptrajError, UnknownRobot
from toptraj.robots.notes import Note
from toptraj.service.mapping import method_of
from toptraj.service.problems import REQUEST_FIELD, STATUS, detail, note_text, request_field, status_of
from toptraj.service.schemas.trajectories import TimingRequest
from toptraj.service.wordings import WORDING

UR5 = robots.load("ur5")
START = np.array([0.0, -1.5, 1.0, 0.0, 0.5, 0.0])
TWO = WaypointPath(np.array([START, START + 0.4]))


def _refused(path, timing, dt=0.01, **kwargs) -> ToptrajError:
    with pytest.raises(ToptrajError) as caught:
        plan(build_problem(UR5, path, **timing, sampling=Sampling(dt=dt), **kwargs))
    return caught.value


def test_a_value_out_of_range_carries_field_value_and_bounds():
    error = _refused(TWO, dict(method=METHODS["phase_plane"]), dt=5e-324)
    assert type(error) is OutOfRange
    assert (error.field, error.value, error.low, error.high, error.unit) == ("sampling.dt", 5e-324, DT.low, DT.high, "s")
    assert detail(error) == "output.dt = 5e-324 is outside the accepted range [1e-06, 10] s"


def test_a_boundary_entry_out_of_range_names_its_index_and_sign():
    velocity = np.zeros(6)
    velocity[3] = -2e3
    error = _refused(TWO, dict(method=METHODS["quintic"], boundary=BoundaryStates(start_velocity=velocity)))
    assert isinstance(error, OutOfRange)
    assert (error.field, error.value, error.signed) == ("boundary.start_velocity[3]", -2e3, True)
    assert error.low == -error.high
    assert detail(error).startswith("timing.boundary.start_velocity[3] = ")


def test_a_waypoint_outside_its_joint_range_names_the_entry_and_the_joint():
    waypoints = np.array([START, START + 0.4])
    waypoints[1, 2] = 10.0  # elbow_joint: [-pi, pi]
    error = _refused(WaypointPath(waypoints), dict(method=METHODS["phase_plane"]))
    assert isinstance(error, OutOfRange)
    assert (error.field, error.value, error.joint_name) == ("waypoints[1][2]", 10.0, "elbow_joint")
    assert (error.low, error.high) == pytest.approx((-np.pi, np.pi))
    assert detail(error).startswith("path.waypoints[1][2] = 10 is outside the limits [-3.14159, 3.14159] of joint 'elbow_joint'")


def test_a_waypoint_that_looks_given_in_degrees_is_told_its_value_in_radians(client):
    """ur5's elbow at 90 (degrees, meant): the 422 gives 1.5708 rad, which plans; 4 rad, just outside
    [-pi, pi], gets no such hint (it is no angle in degrees within the range that is likely meant)."""
    waypoints = [[0.0, -1.2, 1.0, 0.0, 0.5, 0.0], [0.5, -1.0, 90.0, -0.5, 0.9, 0.3]]
    refused = client.post("/v1/trajectories", json={"robot": "ur5", "path": {"waypoints": waypoints}})
    detail_ = refused.json()["detail"]
    assert detail_.endswith("; joint values are in rad: if it is in degrees, give 1.5708 rad"), detail_
    waypoints[1][2] = 1.5708
    assert client.post("/v1/trajectories", json={"robot": "ur5", "path": {"waypoints": waypoints}}).status_code == 200
    waypoints[1][2] = 4.0
    assert "degrees" not in client.post("/v1/trajectories", json={"robot": "ur5", "path": {"waypoints": waypoints}}).json()["detail"]


def test_a_waypoint_of_the_wrong_length_says_given_and_expected():
    error = _refused(WaypointPath(np.array([[0.0, 0.1, 0.2, 0.3], [0.5, 0.1, 0.2, 0.3]])), dict(method=METHODS["phase_plane"]))
    assert isinstance(error, WrongLength)
    assert (error.field, error.given, error.expected) == ("waypoints[0]", 4, 6)


def _mapped(timing: TimingRequest) -> ToptrajError:
    """The error of mapping ``timing`` into the library's method object."""
    with pytest.raises(ToptrajError) as caught:
        method_of(timing, TWO, DEFAULT_SEARCH_MEMORY)
    return caught.value


def test_an_unknown_method_lists_the_names_served():
    error = _mapped(TimingRequest.model_construct(method="fastest"))
    assert isinstance(error, NotOneOf)
    assert (error.field, error.value) == ("method", "fastest")
    assert {"phase_plane", "toppra", "search", "collocation"} <= set(error.allowed)


def test_an_option_of_another_method_says_which_serves_it():
    error = _mapped(TimingRequest.model_validate({"method": "toppra", "cost": {"torque_weight": 1e-3}}))
    assert isinstance(error, NotServed)
    assert (error.field, error.value, error.method, error.alternatives) == ("method.torque_weight", 1e-3, "toppra", ("min_cost",))
    assert detail(error) == "timing.cost.torque_weight is not used by timing.method 'toppra'; use min_cost"


def test_conflicting_inputs_name_each_other():
    timing = dict(method=TimeLaw("quintic", supporting_points=8).method(), boundary=BoundaryStates(start_velocity=np.full(6, 0.1)))
    error = _refused(TWO, timing)
    assert isinstance(error, Conflicting)
    assert (error.field, error.value, error.fields, error.rule) == ("law.supporting_points", 8, ("boundary",), "law_from_rest")


def test_a_grid_beyond_the_method_cap_advises_the_largest_served():
    cap = METHODS["jerk_limited"].max_grid_intervals(UR5.dof)
    error = _refused(TWO, dict(method=METHODS["jerk_limited"], limits=LimitRequest(kinds=("velocity", "acceleration", "jerk")), grid=cap + 1))
    assert isinstance(error, TooLarge)
    assert (error.field, error.value, error.largest, error.unit) == ("grid.intervals", cap + 1, cap, "bytes")
    assert error.estimate > error.cap == MEMORY_CAP_BYTES  # the one cap of every planning's memory
    assert 2 <= error.largest <= MAX_POINTS  # the advice lies in the field's own range
    assert detail(error).endswith(f"use timing.grid_points <= {cap}")


def test_too_many_samples_advises_a_period_in_range():
    error = _refused(TWO, dict(method=METHODS["cubic"], duration=1e4), dt=1e-6)
    assert isinstance(error, TooLarge)
    assert (error.field, error.value, error.unit) == ("sampling.dt", 1e-6, "samples")
    assert error.estimate > error.cap
    assert DT.low <= error.smallest_dt <= DT.high
    assert error.duration / error.smallest_dt <= error.cap - 2 + 1e-9
    assert f"use output.dt >= {error.smallest_dt:g} s" in detail(error)


def test_a_scale_out_of_range_advises_factors_in_range():
    timing = dict(method=METHODS["ruckig"], limits=LimitRequest(kinds=("velocity", "acceleration", "jerk"), overrides={"velocity": [1e3] * 6}, scales={"velocity": 2.0}))
    error = _refused(TWO, timing, dt=10.0)
    assert isinstance(error, OutOfRange)
    assert (error.field, error.value, error.kind, error.scaled) == ("limits.velocity_scale", 2.0, "velocity", 2e3)
    low, high = error.advised
    assert SCALE.low <= low <= high <= SCALE.high
    assert error.low <= 1e3 * low and 1e3 * high <= error.high


def test_infeasible_keeps_where_and_which_limit():
    arm = robots.load("yamamoto_2r")
    timing = dict(method=METHODS["phase_plane"], limits=LimitRequest(kinds=("torque",), scales={"torque": 0.1}))
    with pytest.raises(InfeasiblePath) as caught:
        plan(build_problem(arm, WaypointPath(np.array([[0.0, 0.0], [1.5, 0.0]])), **timing, sampling=Sampling(dt=0.01)))
    assert (caught.value.joint, caught.value.limit) == ("theta1", "torque")
    assert 0.0 <= caught.value.s <= 1.0


def test_budget_exceeded_carries_the_budget():
    deadline = Deadline(1.73)
    deadline.cancel()
    with pytest.raises(BudgetExceeded) as caught:
        deadline.check()
    assert caught.value.budget_s == 1.73


def test_the_library_holds_no_status_or_title():
    """Statuses and titles are the service's: no error class of ``planners`` or ``robots``
    defines them."""
    import toptraj.planners.collision.clearance
    import toptraj.planners.errors
    import toptraj.planners.generators.search.outcome
    import toptraj.robots.errors
    import toptraj.robots.upload_options

    modules = (toptraj.planners.errors, toptraj.robots.errors, toptraj.planners.collision.clearance, toptraj.planners.generators.search.outcome, toptraj.robots.upload_options)
    classes = [value for module in modules for value in vars(module).values()
               if isinstance(value, type) and issubclass(value, ToptrajError)]
    assert len(classes) >= 15
    for cls in classes:
        assert "status" not in vars(cls) and "title" not in vars(cls), cls
    assert status_of(UnknownRobot("x", [])) == 404 and STATUS[ToptrajError] == 422
    assert status_of(BudgetExceeded("late")) == 504


@pytest.mark.parametrize(
    "library, request_",
    [
        ("grid.intervals", "timing.grid_points"),
        ("sampling.dt", "output.dt"),
        ("boundary.start_velocity[2]", "timing.boundary.start_velocity[2]"),
        ("waypoints[2][4]", "path.waypoints[2][4]"),
        ("method.torque_weight", "timing.cost.torque_weight"),
        ("limits.margin", "timing.limit_margin"),
        ("limits.jerk_scale", "timing.limits.jerk_scale"),
        ("law.trapezoid.tau1", "timing.trapezoid.tau1"),
        ("obstacles[3].orientation", "path.obstacles[3].orientation"),
        ("search.cells", "timing.search.cells"),
        ("nowhere", "nowhere"),
    ],
)
def test_request_fields(library, request_):
    assert request_field(library) == request_


def _raised_rules() -> set[str]:
    """Every ``rule="..."`` given to a constructor in ``planners/`` and ``robots/`` and in the
    service's mapping of a request into the library's objects, every class's own
    ``rule_of_class`` and the rule of every ``Note(text, rule, ...)``."""
    rules = set()
    for folder, pattern in (("planners", "*.py"), ("robots", "*.py"), ("service", "mapping.py")):
        for path in (ROOT / folder).rglob(pattern):
            for node in ast.walk(ast.parse(path.read_text())):
                if isinstance(node, ast.keyword) and node.arg == "rule" and isinstance(node.value, ast.Constant):
                    rules.add(node.value.value)
                if (isinstance(node, ast.Call) and getattr(node.func, "id", None) == "Note" and len(node.args) > 1
                        and isinstance(node.args[1], ast.Constant)):
                    rules.add(node.args[1].value)
                if isinstance(node, ast.Assign) and any(getattr(t, "id", None) == "rule_of_class" for t in node.targets):
                    rules.add(node.value.value)  # type: ignore[attr-defined]
    return rules


#: Rules whose errors the service shows in the library's own sentence: internal checks of
#: arguments no request gives (seeds of the local search, B-spline control points, the
#: catalog's own limit files), and the base class's default.
LIBRARY_WORDED = {
    "invalid_input", "seed_shape", "seed_ends_coincide", "not_a_power_of_two", "grid_too_coarse", "off_the_grid",
    "bspline_control_points", "bspline_knots", "catalog_limit", "ruckig_straight_only", "collocation_needs_free_path",
}


def test_every_rule_has_a_wording_and_every_wording_a_rule():
    raised = _raised_rules()
    assert len(raised) > 60
    assert raised - LIBRARY_WORDED - set(WORDING) == set()
    assert set(WORDING) - raised == set()


def test_library_sentences_name_no_request_field():
    """``str(error)`` is in the library's words; ``detail`` in the request's."""
    error = _mapped(TimingRequest.model_validate({"method": "toppra", "cost": {"torque_weight": 1e-3}}))
    assert "timing." not in str(error) and "method.torque_weight" in str(error)
    assert isinstance(error, InvalidInput) and isinstance(error, InvalidRequest)


def test_every_request_field_is_one_the_schema_knows():
    """The request fields of ``REQUEST_FIELD`` are paths of the request's schema."""
    from toptraj.service.schemas.trajectories import TrajectoryRequest

    schema = TrajectoryRequest.model_json_schema()
    text = str(schema)
    for name in REQUEST_FIELD.values():
        assert name.split(".")[-1] in text, name


def test_the_library_holds_no_request_vocabulary_and_no_status():
    output = subprocess.run(
        [sys.executable, "docs/measures/vocabulary.py"], cwd=ROOT, capture_output=True, text=True, check=True
    ).stdout
    assert "\n0 strings naming a request field" in "\n" + output, output
    assert "0 HTTP statuses" in output, output


def test_a_spline_leaving_the_joint_range_says_where_and_by_how_much():
    waypoints = np.array([[0, 0, 0, 0, 0, 0], [0, 0, 3.1, 0, 0, 0], [0, 0, 3.14, 0, 0, 0], [0, 0, 0, 0, 0, 0]], dtype=float)
    error = _refused(WaypointPath(waypoints), dict(method=METHODS["phase_plane"]))
    assert isinstance(error, OutsideJointRange) and isinstance(error, InfeasiblePath)
    assert error.joint == "elbow_joint" and 0.0 < error.s < 1.0
    assert (error.lower, error.upper) == pytest.approx((-np.pi, np.pi))
    assert not error.lower <= error.value <= error.upper


def test_limit_exceeded_carries_the_ratio():
    excess = Excess(ratio=1.0123, kind="acceleration", joint=2, s=0.25)
    error = limit_exceeded("toppra", excess, UR5, SplinePath(np.array([START, START + 0.4])))
    assert isinstance(error, LimitExceeded) and isinstance(error, InfeasiblePath)
    assert (error.ratio, error.joint, error.limit, error.method) == (1.0123, "elbow_joint", "acceleration", "toppra")
    assert "by 1.23 %" in detail(error)


def test_a_note_crosses_processes_with_its_facts():
    note = Note("waypoints [2] repeat the waypoint before them", "waypoints_dropped", field="waypoints", indices=(2,))
    copy = pickle.loads(pickle.dumps(note))
    assert (str(copy), copy.rule, copy.facts) == (str(note), "waypoints_dropped", {"field": "waypoints", "indices": (2,)})
    assert note_text(copy) == "path.waypoints[2] repeats the waypoint before it and was dropped"
