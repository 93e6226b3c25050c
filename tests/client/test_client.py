"""The Python client against a live server (``toptraj serve`` in a subprocess): a method for every
operation of the OpenAPI, every output format, robots with their upload options, jobs with a
progress callback and cancel, batches, and problems raised with their facts. Each typed result
is checked against the service's own JSON, read apart from the client."""

from __future__ import annotations

import json
import pickle
import time

import httpx
import numpy as np
import pytest

from tests.conftest import UR5_WAYPOINTS
from tests.live_server import LiveServer
from tests.paths import ROOT
from toptraj.client import (
    ENDPOINTS,
    BatchItem,
    Client,
    Comparison,
    CsvTrajectory,
    Job,
    ProblemError,
    Trajectory,
    trajectory_request,
)

LIFT = ROOT / "tests" / "data" / "lift_rp.urdf"
QUICK = trajectory_request("ur5", UR5_WAYPOINTS, constraints=["velocity", "acceleration"])
#: A waypoint beyond the UR5's elbow limit (pi): the request is impossible.
OUTSIDE = [[0.0] * 6, [0.0, 0.0, 9.0, 0.0, 0.0, 0.0]]
#: Geering's free motion of a two-link arm: a collocation of some seconds that reports its stages.
COLLOCATION = json.loads((ROOT / "examples" / "geering_free_motion.json").read_text())
#: The global search around an obstacle: far longer than a test waits.
SEARCH = json.loads((ROOT / "examples" / "geering_search_obstacle.json").read_text())


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    env = {
        "TOPTRAJ_DATA_DIR": str(tmp_path_factory.mktemp("client-data")),
        "TOPTRAJ_PRELOAD_ROBOTS": "false",
        "TOPTRAJ_JOB_WORKERS": "1",
        "TOPTRAJ_PLAN_BUDGET_S": "120",  # the first plannings may compile kernels on a busy machine
    }
    with LiveServer(**env) as live:
        yield live


@pytest.fixture(scope="module")
def toptraj(server):
    with Client(f"http://127.0.0.1:{server.port}", timeout=180) as client:
        yield client


def _served(server: LiveServer, path: str, body: dict) -> dict:
    """The service's JSON answer to ``body``, read without the client."""
    status, _, content = server.request("POST", path, body)
    assert status == 200, content[:500]
    return json.loads(content)


def test_every_operation_of_the_openapi_has_a_method(toptraj):
    operations = {(method.upper(), path) for path, item in toptraj.openapi()["paths"].items() for method in item}
    assert operations == set(ENDPOINTS)
    assert all(callable(getattr(Client, name)) for name in ENDPOINTS.values())


def test_health_over_one_kept_alive_connection(toptraj):
    """Calls in a row reuse one connection: the same local port answers each."""
    assert toptraj.health() == "ok"
    ports = {toptraj.request("GET", "/health").extensions["network_stream"].get_extra_info("client_addr") for _ in range(3)}
    toptraj.robots()
    ports.add(toptraj.request("GET", "/v1/robots/ur5").extensions["network_stream"].get_extra_info("client_addr"))
    assert len(ports) == 1, ports


def test_plan_in_every_output_format(toptraj, server):
    """The samples, the ROS message and the CSV hold the same numbers (on whole periods), equal
    to the service's JSON; the typed parts are the body's."""
    periodic = {**QUICK, "output": {"dt": 0.05, "exact_period": True}}
    body = _served(server, "/v1/trajectories", periodic)
    samples = toptraj.plan(periodic)
    message = toptraj.plan("ur5", UR5_WAYPOINTS, constraints=["velocity", "acceleration"], dt=0.05, format="joint_trajectory")
    table = toptraj.plan("ur5", UR5_WAYPOINTS, constraints=["velocity", "acceleration"], dt=0.05, format="csv")
    assert isinstance(samples, Trajectory) and isinstance(message, Trajectory) and isinstance(table, CsvTrajectory)
    assert (samples.format, message.format) == ("samples", "joint_trajectory")
    for quantity in ("q", "qd", "qdd", "tau"):
        expected = np.array(body["samples"][quantity])
        assert expected.shape == (len(body["samples"]["t"]), 6)
        for result in (samples, message, table):
            np.testing.assert_array_equal(getattr(result, quantity), expected, err_msg=quantity)
    np.testing.assert_array_equal(samples.t, body["samples"]["t"])
    np.testing.assert_array_equal(table.t, body["samples"]["t"])
    np.testing.assert_allclose(message.t, body["samples"]["t"], rtol=0, atol=1e-9)  # whole nanoseconds
    assert table.joint_names == message.joint_names == body["joint_names"]
    assert message.joint_trajectory["points"][1]["time_from_start"] == {"sec": 0, "nanosec": 50_000_000}
    assert samples.duration == body["duration"] and samples.sampled_duration == body["sampled_duration"]
    np.testing.assert_array_equal(samples.peak_utilization.velocity, body["peak_utilization"]["velocity"])
    np.testing.assert_array_equal(samples.phase_plane.sd, body["phase_plane"]["sd"])
    assert samples.accuracy.basis == body["accuracy"]["basis"] and samples.warnings == body["warnings"]
    assert samples.conditioning.kappa_max == body["conditioning"]["kappa_max"]


def test_plan_a_whole_request_and_a_time_law_binding(toptraj, server):
    example = json.loads((ROOT / "examples" / "ur5_spline.json").read_text())
    trajectory = toptraj.plan(example)
    assert isinstance(trajectory, Trajectory)
    assert trajectory.duration == _served(server, "/v1/trajectories", example)["duration"]
    assert trajectory.t[-1] == pytest.approx(trajectory.duration, abs=1e-12) and trajectory.method == "phase_plane"
    law = toptraj.plan("ur5", UR5_WAYPOINTS, method="quintic", constraints=["velocity"])
    assert isinstance(law, Trajectory) and law.binding is not None and law.binding.kind == "velocity"
    # The binding joint's velocity limit is reached, the others are not exceeded.
    joint = law.joint_names.index(law.binding.joint)
    assert law.peak_utilization.velocity[joint] == pytest.approx(1.0, abs=5e-3)
    assert np.all(law.peak_utilization.velocity <= 1.005)


def test_compare_types_each_method_and_its_error(toptraj, server):
    body = {"robot": "ur5", "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS}, "methods": ["phase_plane", "quintic", "ruckig"]}
    served = _served(server, "/v1/trajectories/compare", body)["results"]
    results = toptraj.compare("ur5", UR5_WAYPOINTS, methods=["phase_plane", "quintic", "ruckig"])
    assert all(isinstance(result, Comparison) for result in results)
    assert [r.method for r in results] == ["phase_plane", "quintic", "ruckig"]
    assert [r.duration for r in results[:2]] == [s["duration"] for s in served[:2]]
    assert results[0].duration < results[1].duration
    np.testing.assert_array_equal(results[0].peak_utilization.torque, served[0]["peak_utilization"]["torque"])
    # ruckig moves between two waypoints only: its error is kept, the other methods stand.
    ruckig = results[2]
    assert ruckig.duration is None and isinstance(ruckig.error, ProblemError)
    assert ruckig.error.status == served[2]["error"]["status"] == 422 and ruckig.error.detail == served[2]["error"]["detail"]


def test_robots_list_describe_and_draw(toptraj):
    listed = {robot.name: robot for robot in toptraj.robots()}
    assert listed["ur5"].dof == 6 and listed["ur5"].source != "upload"
    ur5 = toptraj.robot("ur5")
    assert ur5.joint_names[2] == "elbow_joint" and ur5.limits.velocity.shape == (6,)
    assert ur5.limits.position_upper[2] == pytest.approx(np.pi)
    # The UR5 at zero: the tool at (a2 + a3, d4 + d6, d1 - d5) of its Denavit-Hartenberg table.
    figure = toptraj.skeleton("ur5", [[0.0] * 6, [0.3] * 6])
    assert figure.points[-1] == "tool0" and figure.positions.shape == (2, 7, 3)
    np.testing.assert_allclose(figure.positions[0, -1], [0.425 + 0.39225, 0.10915 + 0.0823, 0.089159 - 0.09465], atol=1e-8)
    assert not np.allclose(figure.positions[1, -1], figure.positions[0, -1])
    hanging = toptraj.skeleton("ur5", [[0.0] * 6], mounting={"position": [0.0, 0.0, 2.0], "orientation": [1.0, 0.0, 0.0, 0.0]})
    np.testing.assert_allclose(hanging.positions[0], figure.positions[0] * [1.0, -1.0, -1.0] + [0.0, 0.0, 2.0], atol=1e-12)
    single = toptraj.skeleton("ur5", [0.0] * 6)  # one configuration
    np.testing.assert_allclose(single.positions, figure.positions[:1], atol=1e-12)
    with pytest.raises(ProblemError) as caught:  # rows of different lengths: the service names the row
        toptraj.skeleton("ur5", [[0.0] * 6, [0.0] * 5])
    assert caught.value.status == 422 and caught.value.detail.startswith("q[1] holds 5 values; each row of q must hold 6")


def test_upload_with_its_options_then_delete(toptraj):
    """A file uploaded with a joint locked and limits in joint_limits.yaml form (text, then a
    dict): the robot plans its other joint under them; deleted, it is gone."""
    yaml = "joint_limits:\n  turn:\n    has_acceleration_limits: true\n    max_acceleration: 3.5\n"
    robot = toptraj.upload(LIFT, "lift_locked", locked_joints={"lift": 0.3}, joint_limits=yaml)
    assert robot.name == "lift_locked" and robot.dof == 1 and robot.joint_names == ["turn"]
    assert robot.locked_joints == {"lift": 0.3} and robot.source == "upload"
    assert robot.limits.acceleration.tolist() == [3.5] and robot.limit_sources["acceleration"] == ["joint_limits.yaml"]
    as_dict = toptraj.upload(LIFT.read_text(), "lift_jerk", joint_limits={"joint_limits": {"turn": {"has_jerk_limits": True, "max_jerk": 40.0}}})
    assert as_dict.dof == 2 and as_dict.limits.jerk[as_dict.joint_names.index("turn")] == 40.0
    assert {"lift_locked", "lift_jerk"} <= {r.name for r in toptraj.robots() if r.source == "upload"}
    planned = toptraj.plan("lift_locked", [[0.0], [1.0]], constraints=["acceleration"])
    assert isinstance(planned, Trajectory) and planned.peak_utilization.acceleration[0] == pytest.approx(1.0, abs=5e-3)
    assert np.abs(planned.qdd).max() == pytest.approx(3.5, rel=5e-3)
    toptraj.delete_robot("lift_locked")
    with pytest.raises(ProblemError) as caught:
        toptraj.robot("lift_locked")
    assert caught.value.status == 404
    with pytest.raises(ProblemError) as caught:
        toptraj.delete_robot("ur5")
    assert caught.value.status == 409 and caught.value.title


def test_numpy_values_anywhere_in_a_request_are_sent_as_numbers(toptraj, server):
    half = toptraj.robot("ur5").limits.velocity * 0.5  # an ndarray, as the client gives it
    planned = toptraj.plan("ur5", np.array(UR5_WAYPOINTS), limits={"velocity": half}, dt=np.float32(0.01),
                           constraints=list(np.array(["velocity"])))
    served = _served(server, "/v1/trajectories", {"robot": "ur5", "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS},
                     "timing": {"constraints": ["velocity"], "limits": {"velocity": half.tolist()}}, "output": {"dt": 0.01}})
    assert planned.duration == served["duration"]
    with pytest.raises(ValueError, match=r"^path\.waypoints\[1\]\[5\] is nan: JSON has no NaN or infinity"):
        toptraj.plan("ur5", [UR5_WAYPOINTS[0], [*UR5_WAYPOINTS[1][:5], float("nan")]])
    with pytest.raises(ValueError, match=r"^timing\.limits\.velocity\[0\] is inf"):
        toptraj.plan("ur5", UR5_WAYPOINTS, limits={"velocity": np.full(6, np.inf)})


def test_problems_are_raised_with_their_facts(toptraj):
    with pytest.raises(ProblemError) as caught:
        toptraj.plan("ur5", OUTSIDE)
    assert caught.value.status == 422 and "outside the limits" in caught.value.detail
    with pytest.raises(ProblemError) as caught:
        toptraj.plan("ur5", [[0.0] * 6])
    assert caught.value.status == 422 and caught.value.errors[0]["field"] == "path.waypoints"
    with pytest.raises(ProblemError) as caught:  # rows of different lengths: the service names the row
        toptraj.plan("ur5", [[0.0, -1.2, 1.0, 0.0, 0.5], [1.0, -1.0, 1.2, 0.0, 0.6, 0.0]])
    assert caught.value.status == 422 and caught.value.detail.startswith("path.waypoints[0] has 5 values; ur5 has 6 joints")
    with pytest.raises(ProblemError) as caught:
        toptraj.plan("nope", [[0.0], [1.0]])
    assert caught.value.status == 404 and caught.value.type == "about:blank"
    # Gravity holding the arm at the goal needs more torque than the limit: where, which joint, which limit.
    with pytest.raises(ProblemError) as caught:
        toptraj.plan("yamamoto_2r", [[0.0, 0.0], [1.5, 0.0]], constraints=["torque"], limits={"torque_scale": 0.1})
    problem = caught.value
    assert (problem.status, problem.joint, problem.limit) == (422, "theta1", "torque") and 0.9 <= problem.s <= 1.0
    assert problem.problem["joint"] == "theta1"


def test_timeouts_are_the_clients_and_each_calls(server):
    # a request the server takes tens of milliseconds on (jerk limits), against a 2 ms timeout for
    # that call: the quick request (a few milliseconds) was answered within a 1 ms timeout once
    jerk = json.loads((ROOT / "examples" / "ur5_jerk_limited.json").read_text())
    with Client(f"http://127.0.0.1:{server.port}", timeout=30) as quick:
        with pytest.raises(httpx.TimeoutException):
            quick.plan(jerk, timeout=0.002)
        assert quick.health() == "ok"


def test_a_job_reports_increasing_progress_and_its_answer(toptraj):
    seen: list[tuple[float, str]] = []
    job = toptraj.submit(COLLOCATION, budget_s=600)
    assert isinstance(job, Job) and job.kind == "trajectory" and job.status in ("queued", "running")
    done = toptraj.wait(job, progress=lambda fraction, stage: seen.append((fraction, stage)), poll_s=0.02, timeout_s=600)
    fractions = [fraction for fraction, _ in seen]
    assert fractions == sorted(fractions) and seen[-1] == (1.0, "done"), seen
    assert len(set(fractions)) >= 3 and any(0.0 < f < 1.0 for f in fractions), seen
    assert len(seen) == len(set(seen))  # called on changes only
    assert isinstance(done.result, Trajectory) and done.result.method == "collocation"
    alone = toptraj.job_result(job)
    assert isinstance(alone, Trajectory) and alone.duration == done.result.duration
    assert job.id in {listed.id for listed in toptraj.jobs(status="done").jobs}


def test_a_running_job_is_cancelled(toptraj):
    job = toptraj.submit(SEARCH, budget_s=600)
    give_up = time.monotonic() + 120  # a hang guard: the job worker may still be starting
    while toptraj.job(job).status == "queued" and time.monotonic() < give_up:
        time.sleep(0.05)
    with pytest.raises(TimeoutError):
        toptraj.wait(job, poll_s=0.05, timeout_s=0.5)
    assert toptraj.job(job).status == "running"
    cancelled = toptraj.cancel_job(job)
    assert cancelled is not None and cancelled.status == "cancelled" and cancelled.result is None
    with pytest.raises(ProblemError) as caught:
        toptraj.wait(job)
    assert caught.value.status == 409
    with pytest.raises(ProblemError) as caught:
        toptraj.job_result(job)
    assert caught.value.status == 409
    assert toptraj.cancel_job(job) is None  # ended: deleted
    with pytest.raises(ProblemError) as caught:
        toptraj.job(job)
    assert caught.value.status == 404


def test_job_answers_keep_their_format_and_kind(toptraj, server):
    request = {**QUICK, "output": {"dt": 0.05, "format": "joint_trajectory"}}
    planned = toptraj.plan_in_background(request, budget_s=120, poll_s=0.05)
    served = _served(server, "/v1/trajectories", request)
    assert planned.format == "joint_trajectory" and planned.joint_trajectory == served["joint_trajectory"]
    compare = {"robot": "ur5", "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS}, "methods": ["phase_plane", "cubic"]}
    job = toptraj.wait(toptraj.submit(compare), poll_s=0.05, timeout_s=300)
    assert job.kind == "compare" and [r.method for r in job.result] == ["phase_plane", "cubic"]
    assert [r.duration for r in job.result] == [r["duration"] for r in _served(server, "/v1/trajectories/compare", compare)["results"]]
    with pytest.raises(ProblemError) as caught:
        toptraj.plan_in_background({**QUICK, "path": {"kind": "waypoints", "waypoints": OUTSIDE}}, poll_s=0.05)
    assert caught.value.status == 422 and "outside the limits" in caught.value.detail


def test_a_batch_is_followed_and_read_request_by_request(toptraj, server):
    compare = {"robot": "ur5", "path": QUICK["path"], "methods": ["phase_plane", "quintic"]}
    as_csv = {**QUICK, "output": {"format": "csv"}}
    requests = [QUICK, compare, {**QUICK, "path": {"kind": "waypoints", "waypoints": OUTSIDE}}, as_csv]
    seen: list[float] = []
    items = toptraj.run_batch(requests, progress=lambda fraction, stage: seen.append(fraction), poll_s=0.02, timeout_s=300)
    assert all(isinstance(item, BatchItem) for item in items) and [item.line for item in items] == [1, 2, 3, 4]
    assert isinstance(items[0].result, Trajectory) and items[0].result.duration == _served(server, "/v1/trajectories", QUICK)["duration"]
    assert [r.method for r in items[1].result] == ["phase_plane", "quintic"]
    assert items[2].result is None and items[2].status == items[2].error.status == 422
    # a request asking CSV: its text, read as the endpoint's CSV is
    assert isinstance(items[3].result, CsvTrajectory) and items[3].result.duration == items[0].result.duration
    status, _, served_csv = server.request("POST", "/v1/trajectories", as_csv)
    assert status == 200 and items[3].body == served_csv.decode()
    assert seen == sorted(seen) and seen[-1] == 1.0
    batch = toptraj.jobs(limit=1).jobs[0]  # the newest job
    assert batch.kind == "batch" and [item.body for item in toptraj.batch_results(batch)] == [item.body for item in items]
    with pytest.raises(ProblemError) as caught:
        toptraj.submit_batch([QUICK, {"robot": "ur5"}])
    assert caught.value.status == 422 and any(e["field"].startswith("requests[1]") for e in caught.value.errors), caught.value.problem


# --- without a server ---------------------------------------------------------------------------


def test_a_problem_is_read_from_any_error_answer():
    """A problem+json with a fact the client does not know yet, a 503's Retry-After, a proxy's
    page that is no problem at all; the exception survives pickling (a worker process's)."""
    busy = httpx.Response(
        503,
        headers={"retry-after": "2", "content-type": "application/problem+json"},
        json={"type": "about:blank", "title": "Busy", "status": 503, "detail": "the queue is full", "queue": 8},
    )
    problem = ProblemError.from_response(busy)
    assert (problem.status, problem.title, problem.retry_after, problem.extras) == (503, "Busy", 2.0, {"queue": 8})
    assert problem.s is None and problem.joint is None and problem.errors == []
    copy = pickle.loads(pickle.dumps(problem))
    assert (copy.status, copy.detail, copy.retry_after, copy.extras) == (503, "the queue is full", 2.0, {"queue": 8})
    page = ProblemError.from_response(httpx.Response(502, text="<html>Bad Gateway</html>"))
    assert (page.status, page.title, page.detail) == (502, "Bad Gateway", "<html>Bad Gateway</html>")


def test_arguments_beside_a_whole_request_are_refused():
    with Client("http://127.0.0.1:9") as offline:
        with pytest.raises(ValueError, match="dt"):
            offline.plan(QUICK, dt=0.1)
        with pytest.raises(ValueError, match="methods"):
            offline.compare({**QUICK, "methods": ["quintic"]}, methods=["cubic"])
        with pytest.raises(ValueError, match="waypoints"):
            offline.plan("ur5")
        with pytest.raises(ValueError, match=r"it is a comparison; send it with compare\(body\)"):
            offline.plan({**QUICK, "methods": ["quintic"]})


def test_csv_comments_and_columns_are_read():
    text = "# method: phase_plane\n# duration = 0.5\n# a note\nt,q.a,q.b,qd.a,qd.b,qdd.a,qdd.b,tau.a,tau.b\n" + "\n".join(
        ",".join(repr(k + 0.1 * c) for c in range(9)) for k in range(3)
    ) + "\n"
    table = CsvTrajectory.from_text(text, {"content-type": "text/csv"})
    assert table.joint_names == ["a", "b"] and table.metadata == {"method": "phase_plane", "duration": "0.5"}
    assert table.comments == ["method: phase_plane", "duration = 0.5", "a note"]
    np.testing.assert_array_equal(table.t, [0.0, 1.0, 2.0])
    np.testing.assert_array_equal(table.tau[:, 1], [0.8, 1.8, 2.8])
    assert table.q.shape == table.qd.shape == table.qdd.shape == (3, 2)
    assert table.duration == 0.5 and table.warnings == []
    warned = CsvTrajectory.from_text("# duration: 1.25 s\n# warning: first\n# warning: second\n" + text.replace("# duration = 0.5\n", ""))
    assert (warned.duration, warned.warnings) == (1.25, ["first", "second"])
    assert repr(warned) == "CsvTrajectory(duration=1.25, samples=3, joints=2, warnings=2)"


def test_a_trajectory_and_a_job_print_in_a_line(toptraj):
    planned = toptraj.plan("ur5", UR5_WAYPOINTS)
    assert repr(planned) == (
        f"Trajectory(robot='ur5', method='phase_plane', duration={planned.duration!r}, samples={len(planned.t)}, joints=6, "
        f"warnings={len(planned.warnings)})"
    )
    job = toptraj.wait(toptraj.submit({"robot": "ur5", "path": {"waypoints": UR5_WAYPOINTS}}).id)
    assert "\n" not in repr(job) and len(repr(job)) < 600 and job.result is not None


def test_a_cell_through_the_client(toptraj):
    answer = toptraj.cell(ROOT / "examples" / "cell_two_ur5.json", timeout=120.0)
    assert max(answer["solo_durations"]) < answer["duration"] <= answer["sequential_duration"]
    # A file's path as a string, and its text, are the same request.
    assert toptraj.cell(str(ROOT / "examples" / "cell_two_ur5.json"), timeout=120.0)["duration"] == answer["duration"]
    assert toptraj.cell((ROOT / "examples" / "cell_two_ur5.json").read_text(), timeout=120.0)["duration"] == answer["duration"]
    marked = "\ufeff" + (ROOT / "examples" / "cell_two_ur5.json").read_text()  # a text read with its byte order mark
    assert toptraj.cell(marked, timeout=120.0)["duration"] == answer["duration"]
    assert [arm["robot"] for arm in answer["arms"]] == ["ur5", "ur5"]


def test_upload_with_allowed_collisions_as_a_list_or_an_srdf_file(toptraj, tmp_path):
    """The folding lecture_3r path is refused for self-collision on a plain upload and served on
    one whose allowed pairs, given as a list or as an SRDF file, hold the pair that touches."""
    urdf = ROOT / "robots" / "urdf" / "lecture_3r.urdf"
    folding = {"kind": "waypoints", "waypoints": [[0.0, 2.8, 0.0], [0.0, 2.8, 2.0]], "self_collision": True}
    toptraj.upload(urdf, "client_plain_3r")
    with pytest.raises(ProblemError) as caught:
        toptraj.plan("client_plain_3r", path=folding)
    assert caught.value.status == 422 and {caught.value.problem["link_a"], caught.value.problem["link_b"]} == {"turret", "forearm"}
    srdf = tmp_path / "lecture_3r.srdf"
    srdf.write_text('<?xml version="1.0"?>\n<robot name="lecture_3r"><disable_collisions link1="turret" link2="forearm"/></robot>\n')
    for name, allowed in (("client_listed_3r", [("forearm", "turret")]), ("client_srdf_3r", srdf)):
        toptraj.upload(urdf, name, allowed_collisions=allowed)
        assert toptraj.plan(name, path=folding).duration > 0.0


def test_payload_and_mounting_are_request_fields(toptraj, server):
    """plan() and compare() send payload and mounting as the request's fields: the answer is
    the service's to the body holding them, and a ceiling mount with a payload changes the torques."""
    payload, mounting = {"mass": 3.0, "center_of_mass": [0.0, 0.0, 0.05]}, {"orientation": [1.0, 0.0, 0.0, 0.0]}
    planned = toptraj.plan("ur5", UR5_WAYPOINTS, constraints=["velocity", "acceleration", "torque"], payload=payload, mounting=mounting)
    body = trajectory_request("ur5", UR5_WAYPOINTS, constraints=["velocity", "acceleration", "torque"]) | {"payload": payload, "mounting": mounting}
    served = _served(server, "/v1/trajectories", body)
    assert planned.duration == served["duration"]
    np.testing.assert_array_equal(planned.tau, np.array(served["samples"]["tau"]))
    assert planned.payload == served["payload"] and planned.payload["mass"] == 3.0
    assert planned.mounting == served["mounting"] and planned.mounting["rotation"][1] == [0.0, -1.0, 0.0]  # x turned half
    bare = toptraj.plan("ur5", UR5_WAYPOINTS, constraints=["velocity", "acceleration", "torque"])
    assert bare.payload is None and bare.mounting is None and bare.zones is None
    assert np.abs(planned.tau[0] - bare.tau[0]).max() > 1.0  # N m: the payload's weight, pulling the other way
    compared = toptraj.compare("ur5", UR5_WAYPOINTS, methods=["phase_plane"], payload=payload, mounting=mounting)
    assert compared[0].duration == served["duration"]
    with pytest.raises(ValueError, match="payload"):
        toptraj.plan(body, payload=payload)
