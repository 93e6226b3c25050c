"""No 5xx for any input: numbers outside their physical range get a 422 naming the range, a
numerical breakdown inside a planner is a 422 "timing method failed", nothing non-finite reaches
the JSON encoder, and an unexpected error is a problem+json 500 that keeps the connection."""

from __future__ import annotations

import socket
import threading
import time

import httpx
import numpy as np
import pytest
import uvicorn

from tests.conftest import UR5_WAYPOINTS
from tests.service.answer_limits import assert_limits_held
from toptraj import robots
from toptraj.planners import (
    METHODS,
    BoundaryStates,
    Deadline,
    LimitRequest,
    Sampling,
    TimeLaw,
    TimingFailed,
    WaypointPath,
    build_problem,
    plan,
)
from toptraj.planners.errors import OutOfRange
from toptraj.planners.paths.grid import path_grid
from toptraj.planners.results import require_finite
from toptraj.planners.timing.laws.profiles import quintic_coefficients
from toptraj.service.app import create_app
from toptraj.service.finite import FiniteJSONResponse
from toptraj.service.problems import NonFiniteAnswer, detail, non_finite_answer
from toptraj.service.settings import Settings

DIRECTION = [0.8, 0.2, 0.4, -0.5, 0.6, 0.3]
TWO = UR5_WAYPOINTS[:2]


def _problem(response, status: int) -> str:
    assert response.status_code == status, response.text
    assert response.headers["content-type"] == "application/problem+json"
    body = response.json()
    assert body["status"] == status and {"type", "title", "detail"} <= set(body)
    return body["detail"]


# Each of these answered 500 before numbers were held to their ranges.
OUT_OF_RANGE = [
    *[
        pytest.param({"path": {"waypoints": UR5_WAYPOINTS}, "timing": {"method": method, "duration": 1e-300}},
                     "timing.duration", "[0.001, 10000] s", id=f"{method}-duration-1e-300")
        for method in ("cubic", "quintic", "trapezoidal", "cycloidal")
    ],
    *[
        pytest.param({"path": {"waypoints": UR5_WAYPOINTS, "interpolation": "via"}, "timing": {"method": method, "duration": duration}},
                     "timing.duration", "[0.001, 10000] s", id=f"via-{method}-duration-{duration:g}")
        for method in ("cubic", "quintic")
        for duration in (1e-300, 1e300)
    ],
    pytest.param({"path": {"waypoints": TWO}, "timing": {"method": "phase_plane", "boundary": {"start_velocity": [1e300 * x for x in DIRECTION]}}},
                 "timing.boundary.start_velocity[0]", "[-1000, 1000] rad/s", id="start-velocity-1e300"),
    pytest.param({"path": {"waypoints": TWO}, "timing": {"method": "quintic", "boundary": {"start_acceleration": [1e308 * x for x in DIRECTION]}}},
                 "timing.boundary.start_acceleration[0]", "[-100000, 100000] rad/s^2", id="start-acceleration-1e308"),
    pytest.param({"path": {"waypoints": TWO}, "timing": {"method": "trapezoidal", "trapezoid": {"tau1": 5e-324}}},
                 "timing.trapezoid.tau1", "[0.001, 0.999]", id="tau1-subnormal"),
    pytest.param({"path": {"waypoints": TWO}, "timing": {"limits": {"velocity": [5e-324] * 6}}},
                 "timing.limits.velocity[0]", "[1e-06, 1000] rad/s", id="velocity-limit-subnormal"),
    pytest.param({"path": {"waypoints": TWO}, "timing": {"limits": {"torque_scale": 1e300}}},
                 "timing.limits.torque_scale", "[0.001, 1000]", id="torque-scale-1e300"),
    pytest.param({"path": {"waypoints": TWO}, "output": {"dt": 5e-324}},
                 "output.dt", "[1e-06, 10] s", id="dt-subnormal"),
]


@pytest.mark.parametrize("body, field, accepted", OUT_OF_RANGE)
def test_numbers_outside_their_range_are_a_422_naming_the_range(client, body, field, accepted):
    detail = _problem(client.post("/v1/trajectories", json={"robot": "ur5", **body}), 422)
    assert f"{field}: " in detail and f"not within the accepted range {accepted}" in detail, detail


def test_compare_whose_durations_overflowed_the_grid_is_a_422(client):
    """A via-point duration of 1e308 made the path's knots NaN ("cannot convert float NaN to
    integer" in path_grid)."""
    body = {
        "robot": "ur5",
        "path": {"waypoints": UR5_WAYPOINTS, "interpolation": "via"},
        "methods": ["cubic", "quintic"],
        "timing": {"duration": 1e308, "limits": {"velocity_scale": 100, "acceleration_scale": 100}},
    }
    detail = _problem(client.post("/v1/trajectories/compare", json=body), 422)
    assert "timing.duration" in detail and "[0.001, 10000] s" in detail


def test_the_library_holds_the_same_ranges():
    """The library's option objects and ``build_problem``, called without the service, check the
    ranges too."""
    arm = robots.load("geering_2r")
    path = WaypointPath(np.array([[0.0, 0.0], [1.0, 1.0]]))
    for problem, field, words in [
        (lambda: build_problem(arm, path, METHODS["cubic"], duration=1e-300), "duration", "timing.duration = 1e-300"),
        (lambda: build_problem(arm, path, TimeLaw("trapezoidal", fractions=(5e-324, 0.5)).method()), "law.trapezoid.tau1",
         "timing.trapezoid.tau1"),
        (lambda: build_problem(arm, path, METHODS["quintic"], boundary=BoundaryStates(start_acceleration=np.array([1e308, 1e308]))),
         "boundary.start_acceleration[0]", "timing.boundary.start_acceleration[0]"),
        (lambda: build_problem(arm, path, METHODS["phase_plane"], limits=LimitRequest(scales={"torque": 1e-300})), "limits.torque_scale",
         "timing.limits.torque_scale"),
        (lambda: build_problem(arm, path, METHODS["phase_plane"], sampling=Sampling(dt=5e-324), deadline=Deadline()), "sampling.dt",
         "output.dt"),
    ]:
        with pytest.raises(OutOfRange) as caught:
            plan(problem())
        assert caught.value.field == field and not caught.value.low <= abs(caught.value.value) <= caught.value.high
        assert words in detail(caught.value) and "accepted range" in detail(caught.value)


def test_extreme_numbers_inside_the_ranges_plan_or_fail_cleanly(client):
    """The corners of the accepted ranges: every answer is a 200 with finite numbers within the
    limits it was asked to hold, or a 4xx."""
    bodies = []
    for method in ("cubic", "quintic", "trapezoidal", "cycloidal"):
        for duration in (1e-3, 1e4):
            bodies.append({"path": {"waypoints": UR5_WAYPOINTS}, "timing": {"method": method, "duration": duration}, "output": {"dt": 10.0}})
    for method in ("cubic", "quintic"):
        for duration in (1e-3, 1e4):
            bodies.append({"path": {"waypoints": UR5_WAYPOINTS, "interpolation": "via"}, "timing": {"method": method, "duration": duration}, "output": {"dt": 10.0}})
    for scale in (1e-3, 1e3):
        limits = {f"{kind}_scale": scale for kind in ("velocity", "acceleration", "torque", "jerk")}
        bodies.append({"path": {"waypoints": UR5_WAYPOINTS, "interpolation": "via"}, "timing": {"method": "quintic", "limits": limits}})
        bodies.append({"path": {"waypoints": TWO}, "timing": {"method": "trapezoidal", "limits": limits, "trapezoid": {"tau1": 1e-3, "tau2": 0.999}}})
    for speed in (1e3, 1e-300):
        bodies.append({"path": {"waypoints": TWO}, "timing": {"method": "quintic", "boundary": {
            "start_velocity": [speed * x for x in DIRECTION], "start_acceleration": [1e5 * x for x in DIRECTION]}}})
        bodies.append({"path": {"waypoints": TWO}, "timing": {"method": "phase_plane", "boundary": {"end_velocity": [speed * x for x in DIRECTION]}}})
    for body in bodies:
        response = client.post("/v1/trajectories", json={"robot": "ur5", **body})
        assert response.status_code < 500, (body, response.text)
        if response.status_code == 200:
            samples = response.json()["samples"]
            assert all(np.all(np.isfinite(np.asarray(samples[key], dtype=float))) for key in ("t", "q", "qd", "qdd", "tau"))
            assert_limits_held({"robot": "ur5", **body}, response.json())


# --- the guards behind the ranges ----------------------------------------------------------


def test_quintic_coefficients_never_solve_a_singular_system():
    """Closed form: a tiny duration gives huge coefficients or a ZeroDivisionError, never a
    LinAlgError from a singular 3 x 3 system."""
    coefficients = quintic_coefficients(0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1e-20)
    assert np.all(np.isfinite(coefficients)) and coefficients[3] == pytest.approx(10.0 / 1e-60)


def test_non_finite_path_knots_are_a_timing_failure():
    class Broken:
        knots = np.array([0.0, np.nan, 1.0])

    with pytest.raises(TimingFailed, match="segment boundaries"):
        path_grid(Broken())


def test_non_finite_results_are_a_timing_failure():
    require_finite("cubic", duration=2.0, samples=[np.ones((3, 2))], cost=None)
    with pytest.raises(TimingFailed, match="timing method 'cubic' failed: its samples holds inf"):
        require_finite("cubic", samples=[np.array([[1.0, np.inf]])])


def test_json_encoder_refuses_non_finite_numbers_and_says_where():
    assert FiniteJSONResponse({"a": [1.0, 2.5]}).body == b'{"a":[1.0,2.5]}'
    with pytest.raises(NonFiniteAnswer, match=r"holds nan at samples\.qd\[1\]\[0\]"):
        FiniteJSONResponse({"samples": {"qd": [[0.0], [float("nan")]]}})


@pytest.mark.parametrize(
    ("body", "named"),
    [
        ({"ok": 1.5, "peaks": [{"joint": "a", "ratio": 0.5}, {"joint": "b", "ratio": -np.inf}]}, "peaks[1].ratio = -inf"),
        ({"n": 3, "flag": True, "note": None, "q": np.array([[0.0, 1.0], [2.0, np.nan]])}, "q[1][1] = nan"),
        ({"s": "x", "pair": (1, np.float64(np.inf))}, "pair[1] = inf"),
        ([{"fine": [0.0, 1.0]}, {"t": [0.5, np.nan, np.inf]}], "[1].t[1] = nan"),
        (np.array([1.0, 2.0]), None),
        ({"i": np.arange(3), "text": "nan", "deep": [[{"x": [1.0]}]]}, None),
    ],
)
def test_the_first_non_finite_number_is_named_wherever_it_sits(body, named):
    """Strings, integers, booleans and None are passed over; floats, numpy scalars and arrays
    at any depth of dicts, lists and tuples are tested, and the first bad one is named."""
    error = non_finite_answer(body)
    if named is None:
        assert error is None
    else:
        place, value = named.split(" = ")
        assert f"holds {value} at {place or 'its top level'}," in str(error)


def test_a_numerical_breakdown_in_a_planner_is_a_422(client, monkeypatch):
    """Whatever overflows or turns singular inside a timing method is its failure, not a 500."""
    import toptraj.planners.timing.laws.method as classical

    def singular(*args, **kwargs):
        raise np.linalg.LinAlgError("Singular matrix")

    monkeypatch.setattr(classical, "quintic_coefficients", singular)
    body = {"robot": "ur5", "path": {"waypoints": TWO}, "timing": {"method": "quintic", "boundary": {"start_velocity": [0.1 * x for x in DIRECTION]}}}
    detail = _problem(client.post("/v1/trajectories", json=body), 422)
    assert "timing method 'quintic' failed: numerical breakdown (LinAlgError: Singular matrix)" in detail


# --- an unexpected error keeps the connection ----------------------------------------------


@pytest.fixture
def live_server(monkeypatch):
    """A uvicorn server in a thread whose trajectory planning raises an unexpected error."""
    import toptraj.service.routes.trajectories as routes

    def broken(*args, **kwargs):
        raise RuntimeError("a planner bug")

    monkeypatch.setattr(routes, "plan_request", broken)
    listener = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    listener.bind(("127.0.0.1", 0))
    app = create_app(Settings(preload_robots=False))
    server = uvicorn.Server(uvicorn.Config(app, log_level="critical", lifespan="on"))
    thread = threading.Thread(target=server.run, kwargs={"sockets": [listener]}, daemon=True)
    thread.start()
    started = time.monotonic()
    while not server.started:
        assert time.monotonic() - started < 30, "the server did not start"
        time.sleep(0.02)
    yield f"http://127.0.0.1:{listener.getsockname()[1]}"
    server.should_exit = True
    thread.join(10)
    listener.close()


def test_an_unexpected_error_is_a_problem_500_and_keeps_the_connection(live_server):
    with httpx.Client(base_url=live_server, timeout=30) as http:
        first = http.post("/v1/trajectories", json={"robot": "ur5", "path": {"waypoints": TWO}})
        assert "a planner bug" not in first.text
        assert "RuntimeError" in _problem(first, 500)
        assert first.headers.get("connection", "").lower() != "close"
        second = http.get("/health")
        assert second.status_code == 200 and second.json() == {"status": "ok"}
        # The same TCP connection served both requests.
        ports = [response.extensions["network_stream"].get_extra_info("client_addr") for response in (first, second)]
        assert ports[0] == ports[1]


# --- HTTP errors keep their headers and the OpenAPI says what is answered -------------------


@pytest.mark.parametrize(
    "method, path, allowed",
    [("PUT", "/v1/trajectories", "POST"), ("OPTIONS", "/v1/robots", "GET, POST"), ("TRACE", "/health", "GET")],
)
def test_405_is_a_problem_with_an_allow_header_listing_every_method(client, method, path, allowed):
    """Found by schemathesis: OPTIONS /v1/robots answered `Allow: GET`, leaving out POST."""
    response = client.request(method, path)
    assert f"use {allowed.replace(', ', ' or ')}" in _problem(response, 405)
    assert response.headers["allow"] == allowed


def test_openapi_declares_problem_answers(client):
    schema = client.get("/openapi.json").json()
    components = schema["components"]["schemas"]
    assert "HTTPValidationError" not in components and "ValidationError" not in components
    assert {"type", "title", "status", "detail"} <= set(components["Problem"]["properties"])
    expected = {
        ("post", "/v1/trajectories"): {"400", "404", "413", "422", "504"},
        ("post", "/v1/trajectories/compare"): {"400", "404", "413", "422", "504"},
        ("post", "/v1/robots"): {"400", "409", "413", "422"},
        ("get", "/v1/robots/{name}"): {"404"},
    }
    for (method, path), statuses in expected.items():
        responses = schema["paths"][path][method]["responses"]
        assert statuses <= set(responses), (method, path, sorted(responses))
        for status, response in responses.items():
            if int(status) >= 400:
                assert list(response["content"]) == ["application/problem+json"], (method, path, status)
                assert response["content"]["application/problem+json"]["schema"] == {"$ref": "#/components/schemas/Problem"}
    duration = components["TimingRequest"]["properties"]["duration"]["anyOf"][0]
    assert duration == {"type": "number", "minimum": 1e-3, "maximum": 1e4}
    assert components["TimingRequest"]["additionalProperties"] is False
