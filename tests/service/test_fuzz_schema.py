"""Property-based fuzzing from the OpenAPI schema: no answer is a 5xx, and every answer is what
the schema declares (status, content type, body).

Seeded (derandomized) and bounded, so that CI runs the same examples every time, in well
under a minute:

* schemathesis generates requests for every operation straight from ``/openapi.json`` (valid
  and invalid ones, undeclared methods) and checks each answer against the schema. Valid
  trajectory bodies are steered toward the planners: a real arm, known methods, joint vectors
  of the arm's length, waypoints inside its joint range, a small grid, so that about half of
  them are planned instead of stopping at a 404 or a length error.
* A hand-written Hypothesis strategy builds trajectory and compare requests the way a user
  would (waypoints within the joint limits, any method, random limits, scales, durations,
  boundary states, sample periods) and asserts that every answer is below 500, that every
  number of a 200 is finite, and that every 200 holds the limits it was asked to hold within
  0.5 % (``assert_limits_held``: its samples, the differences between them, and the peak
  utilization it states).
* The same requests with one physical number replaced by any magnitude a double can hold, from
  5e-324 to 1.8e308: out of range they get a 422, in range a plan or a 4xx, never a 5xx.
"""

from __future__ import annotations

import json
import math
import zlib

import hypothesis.strategies as st
import numpy as np
import pytest
import schemathesis
from fastapi.testclient import TestClient
from hypothesis import HealthCheck, given, settings
from schemathesis.generation.modes import GenerationMode

from tests.service.answer_limits import assert_limits_held
from toptraj import robots
from toptraj.planners import METHODS
from toptraj.planners.problem.ranges import ACCELERATION, DURATION, SCALE, TRAPEZOID_FRACTION, VELOCITY
from toptraj.service.app import create_app
from toptraj.service.settings import Settings

#: A budget that small requests meet with room to spare even on a busy machine: a 504 here is a
#: finding too. schemathesis waits longer than the budget (``request_timeout``), so a request
#: answers its 504 before the client gives up. Fuzzed requests come one after another; a request
#: past its budget keeps its planning thread until the thread reaches its next deadline check,
#: so the next one gets threads of its own.
BUDGET_S = 20.0
APP = create_app(Settings(preload_robots=False, plan_budget_s=BUDGET_S, plan_workers=8))
SCHEMA = schemathesis.openapi.from_asgi("/openapi.json", APP)
SCHEMA.config.request_timeout = 3 * BUDGET_S
# The OpenAPI's examples are the files of examples/, answered by tests/service/test_examples.py with the
# budget a free-path collocation needs; here they would only meet the short fuzz budget.
SCHEMA.config.phases.examples.enabled = False
# A body over the size cap (a string far beyond its maxLength) is refused with 413 before its
# fields are read: that is a rejection of invalid data too.
_REJECTION = SCHEMA.config.checks.negative_data_rejection
_REJECTION.expected_statuses = [*_REJECTION.expected_statuses, "413"]
ROBOTS = ("ur5", "geering_2r", "yamamoto_2r")
DOF = {name: robots.load(name).dof for name in ROBOTS}
#: Joint ranges the steered waypoints are wrapped into (rad or m; continuous joints: one turn
#: either way).
LOWER = {name: np.maximum(robots.load(name).limits.position_lower, -2 * np.pi).tolist() for name in ROBOTS}
UPPER = {name: np.minimum(robots.load(name).limits.position_upper, 2 * np.pi).tolist() for name in ROBOTS}
MAX_GRID_POINTS = 200
#: Methods on given paths (collocation optimizes a free path, which these requests do not give).
PLANNED_METHODS = sorted(set(METHODS) - {"collocation"})
FUZZ_SETTINGS = settings(
    max_examples=30,
    derandomize=True,
    database=None,
    deadline=None,
    suppress_health_check=list(HealthCheck),
)

#: Joint-vector fields of a trajectory body, as (parent keys..., field).
_VECTORS = [
    ("path", "start"),
    ("path", "goal"),
    ("timing", "limits", "velocity"),
    ("timing", "limits", "acceleration"),
    ("timing", "limits", "jerk"),
    ("timing", "limits", "torque"),
    ("timing", "boundary", "start_velocity"),
    ("timing", "boundary", "end_velocity"),
    ("timing", "boundary", "start_acceleration"),
    ("timing", "boundary", "end_acceleration"),
]


def _fit(values, dof: int):
    """``values`` cut or repeated to ``dof`` entries."""
    if not isinstance(values, list) or not values:
        return values
    return [values[k % len(values)] for k in range(dof)]


def _steer(body: dict) -> dict:
    """A valid trajectory or compare body aimed at the planners: a real robot and known
    methods (picked from the body's own bytes, so the choice is as deterministic as the body),
    joint vectors of the robot's length, waypoints wrapped into its joint range, free paths
    turned into their two waypoints (collocation is too slow for a fuzz budget), and a grid
    small enough to plan within the budget."""
    body = json.loads(json.dumps(body))
    pick = zlib.crc32(json.dumps(body, sort_keys=True).encode())
    robot = ROBOTS[pick % len(ROBOTS)]
    body["robot"], dof = robot, DOF[robot]
    lower, upper = LOWER[robot], UPPER[robot]
    path = body.get("path") or {}
    if path.get("kind") == "free":
        path = body["path"] = {"kind": "waypoints", "waypoints": [path["start"], path["goal"]]}
    if isinstance(path.get("waypoints"), list):
        path["waypoints"] = [
            [float(lo + (value - lo) % (hi - lo)) for value, lo, hi in zip(_fit(row, dof), lower, upper)]
            for row in path["waypoints"]
        ]
    for keys in _VECTORS:
        parent = body
        for key in keys[:-1]:
            parent = parent.get(key) if isinstance(parent, dict) else None
        if isinstance(parent, dict) and keys[-1] in parent:
            parent[keys[-1]] = _fit(parent[keys[-1]], dof)
    timing = body.get("timing") or {}
    if timing.get("method", "phase_plane") not in PLANNED_METHODS:
        timing["method"] = PLANNED_METHODS[pick // 7 % len(PLANNED_METHODS)]
    if "methods" in body:
        # at most three methods, each once: ten real timings of one path do not fit the budget
        methods = [m if m in PLANNED_METHODS else PLANNED_METHODS[(pick + k) % len(PLANNED_METHODS)] for k, m in enumerate(body["methods"])]
        body["methods"] = list(dict.fromkeys(methods))[:3]
    if isinstance(timing.get("grid_points"), int):
        timing["grid_points"] = min(timing["grid_points"], MAX_GRID_POINTS)
    return body


@SCHEMA.hook("map_case")
def steer_toward_the_planners(context, case):
    planned = case.operation.path.startswith("/v1/trajectories") and case.method.upper() == "POST"
    if planned and isinstance(case.body, dict) and case.meta is not None and case.meta.generation.mode == GenerationMode.POSITIVE:
        case.body = _steer(case.body)
    return case


@SCHEMA.parametrize()
@FUZZ_SETTINGS
def test_every_operation_answers_as_its_schema_says(case):
    """schemathesis' checks (no 5xx, declared status, content type, headers and body schema,
    invalid input refused), except positive_data_acceptance: a request can fit the schema and
    still ask the impossible (a waypoint outside the joint limits, a path gravity forbids),
    which is a 422 by design. A planned 200 in JSON holds the limits it was asked to hold."""
    from schemathesis.checks import positive_data_acceptance

    response = case.call_and_validate(excluded_checks=[positive_data_acceptance])
    planned = case.operation.path.startswith("/v1/trajectories") and case.method.upper() == "POST"
    kind = response.headers.get("content-type") or [""]
    if planned and response.status_code == 200 and (kind[0] if isinstance(kind, list) else kind).startswith("application/json"):
        answers = response.json().get("results", [response.json()])
        for answer in answers:
            assert_limits_held(case.body, answer)


# --- requests the way a user writes them ---------------------------------------------------

CLIENT = TestClient(APP)
LAWS = ("cubic", "quintic", "trapezoidal", "cycloidal")


def _log_uniform(accepted, low=None, high=None):
    """Floats spread over the decades of ``accepted`` (or of [low, high] inside it)."""
    low, high = math.log10(low or accepted.low), math.log10(high or accepted.high)
    return st.floats(low, high).map(lambda exponent: 10.0**exponent)


#: Magnitudes from the smallest subnormal to the largest double.
HOSTILE = st.one_of(
    st.sampled_from([5e-324, 2.2e-308, 1e-300, 1e-30, 1e30, 1e300, 1e308, 1.7976931348623157e308]),
    st.floats(-323.0, 308.0).map(lambda exponent: 10.0**exponent),
)


@st.composite
def trajectory_bodies(draw):
    """A trajectory request on a real arm: waypoints within its joint limits, any method and
    interpolation, and random limits, scales, durations, boundary states and sample period."""
    name = draw(st.sampled_from(ROBOTS))
    arm = robots.load(name)
    lower = np.maximum(arm.limits.position_lower, -2 * np.pi)
    upper = np.minimum(arm.limits.position_upper, 2 * np.pi)
    joints = st.tuples(*[st.floats(float(lo), float(hi)) for lo, hi in zip(lower, upper)]).map(list)
    distinct = lambda rows: all(np.ptp(pair, axis=0).max() > 1e-3 for pair in zip(rows, rows[1:]))  # noqa: E731
    waypoints = draw(st.lists(joints, min_size=2, max_size=4).filter(distinct))
    method = draw(st.sampled_from(PLANNED_METHODS))
    interpolation = draw(st.sampled_from(["spline", "linear", *(["via"] if method in ("cubic", "quintic") else [])]))
    timing: dict = {"method": method, "grid_points": draw(st.integers(20, MAX_GRID_POINTS))}
    if draw(st.booleans()):
        kinds = ["velocity", "acceleration", "torque", *(["jerk"] if method in (*LAWS, "ruckig") else [])]
        timing["constraints"] = draw(st.lists(st.sampled_from(kinds), min_size=1, max_size=len(kinds), unique=True))
    limits = {}
    for kind in ("velocity", "acceleration", "torque", "jerk"):
        if draw(st.integers(0, 4)) == 4:
            limits[f"{kind}_scale"] = draw(_log_uniform(SCALE))
    if draw(st.integers(0, 4)) == 4:
        limits["velocity"] = draw(st.lists(_log_uniform(VELOCITY, 1e-2), min_size=arm.dof, max_size=arm.dof))
    if draw(st.integers(0, 4)) == 4:
        limits["acceleration"] = draw(st.lists(_log_uniform(ACCELERATION, 1e-2), min_size=arm.dof, max_size=arm.dof))
    if limits:
        timing["limits"] = limits
    if method in LAWS and draw(st.booleans()):
        timing["duration"] = draw(_log_uniform(DURATION))
    if method == "trapezoidal" and draw(st.booleans()):
        tau1, tau2 = sorted(draw(st.lists(st.floats(TRAPEZOID_FRACTION.low, TRAPEZOID_FRACTION.high), min_size=2, max_size=2)))
        timing["trapezoid"] = {"tau1": tau1, "tau2": tau2}
    if draw(st.integers(0, 3)) == 3:
        # Tangent to the straight line between the last two waypoints (spline ends are not,
        # and get a 422 for it): a speed of either sign and any magnitude in range.
        direction = np.subtract(waypoints[-1], waypoints[-2])
        if np.linalg.norm(direction) > 0:
            speed = draw(st.one_of(st.just(0.0), _log_uniform(VELOCITY)))
            end = (speed * direction / np.linalg.norm(direction)).tolist()
            timing["boundary"] = {"end_velocity": end}
            if method == "quintic" and draw(st.booleans()):
                timing["boundary"]["end_acceleration"] = (draw(_log_uniform(ACCELERATION)) * direction / np.linalg.norm(direction)).tolist()
    body = {
        "robot": name,
        "path": {"kind": "waypoints", "waypoints": waypoints, "interpolation": interpolation},
        "timing": timing,
        "output": {"dt": draw(st.sampled_from([1e-3, 0.01, 0.1, 1.0, 10.0]))},
    }
    return body


@st.composite
def hostile_bodies(draw):
    """A user's trajectory request with one physical number replaced by any magnitude a double
    can hold (durations, switching fractions, limits and their scales, boundary states, the
    sample period), set where it takes effect: a time law for a duration, two waypoints for a
    boundary state along the line."""
    body = draw(trajectory_bodies())
    timing, value = body["timing"], draw(HOSTILE)
    timing.pop("boundary", None)
    field = draw(st.sampled_from(["duration", "tau1", "tau2", "scale", "limit", "velocity", "acceleration", "dt"]))
    if field == "duration":
        timing["method"] = draw(st.sampled_from(LAWS)) if timing["method"] not in LAWS else timing["method"]
        if timing["method"] not in ("cubic", "quintic") and body["path"]["interpolation"] == "via":
            body["path"]["interpolation"] = "spline"
        timing["duration"] = value
    elif field in ("tau1", "tau2"):
        timing["method"] = "trapezoidal"
        body["path"]["interpolation"] = "spline"
        timing["trapezoid"] = {"tau1": 1 / 3, "tau2": 2 / 3, field: value}
    elif field == "scale":
        timing.setdefault("limits", {})[f"{draw(st.sampled_from(['velocity', 'acceleration', 'torque', 'jerk']))}_scale"] = value
    elif field == "limit":
        kind = draw(st.sampled_from(["velocity", "acceleration", "torque", "jerk"]))
        dof = len(body["path"]["waypoints"][0])
        timing.setdefault("limits", {})[kind] = [1.0] * (dof - 1) + [value]
    elif field in ("velocity", "acceleration"):
        timing["method"] = draw(st.sampled_from(["quintic", "cubic", "phase_plane", "toppra", "min_cost"]))
        if field == "acceleration":
            timing["method"] = "quintic"
        body["path"] = {"kind": "waypoints", "waypoints": body["path"]["waypoints"][:2]}
        direction = np.subtract(*body["path"]["waypoints"][::-1])
        sign = draw(st.sampled_from([1.0, -1.0]))
        timing["boundary"] = {f"start_{field}": (direction / np.linalg.norm(direction) * sign * value).tolist()}
    else:
        body["output"]["dt"] = value
    return body


def _assert_finite(value, where="body"):
    if isinstance(value, float):
        assert math.isfinite(value), where
    elif isinstance(value, dict):
        for key, item in value.items():
            _assert_finite(item, f"{where}.{key}")
    elif isinstance(value, list):
        for index, item in enumerate(value):
            _assert_finite(item, f"{where}[{index}]")


@given(body=trajectory_bodies())
@settings(FUZZ_SETTINGS, max_examples=60)
def test_trajectory_requests_never_answer_5xx(body):
    response = CLIENT.post("/v1/trajectories", json=body)
    assert response.status_code < 500, (body, response.text)
    if response.status_code == 200:
        _assert_finite(response.json())
        assert_limits_held(body, response.json())
    else:
        assert response.headers["content-type"] == "application/problem+json", response.text


@given(body=hostile_bodies())
@FUZZ_SETTINGS
def test_any_magnitude_is_planned_or_refused_never_a_5xx(body):
    """Out of range: a 422 naming the range; in range: a plan or a 4xx, never a 5xx."""
    response = CLIENT.post("/v1/trajectories", json=body)
    assert response.status_code < 500, (body, response.text)
    if response.status_code == 200:
        _assert_finite(response.json())
        assert_limits_held(body, response.json())
    compare = {"robot": body["robot"], "path": body["path"], "methods": ["cubic", "quintic", body["timing"]["method"]],
               "timing": dict(body["timing"], method="phase_plane")}
    response = CLIENT.post("/v1/trajectories/compare", json=compare)
    assert response.status_code < 500, (compare, response.text)
    if response.status_code == 200:
        _assert_finite(response.json())
        for answer in response.json()["results"]:
            assert_limits_held(compare, answer)


@given(body=trajectory_bodies(), methods=st.lists(st.sampled_from(PLANNED_METHODS), min_size=1, max_size=3))
@FUZZ_SETTINGS
def test_compare_requests_never_answer_5xx(body, methods):
    timing = dict(body["timing"], method="phase_plane")
    compare = {"robot": body["robot"], "path": body["path"], "methods": methods, "timing": timing}
    response = CLIENT.post("/v1/trajectories/compare", json=compare)
    assert response.status_code < 500, (body, methods, response.text)
    if response.status_code == 200:
        _assert_finite(response.json())
        for answer in response.json()["results"]:
            assert_limits_held(compare, answer)


@pytest.fixture(scope="module", autouse=True)
def _app_lifespan():
    import cvxpy  # noqa: F401  (imported once here rather than inside a request's budget)
    import toppra  # noqa: F401

    with CLIENT:
        yield
