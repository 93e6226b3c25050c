"""``output.format`` (samples, ROS ``joint_trajectory``, CSV) and ``output.exact_period``:
every shape carries the same numbers, and a controller's samples lie on whole periods."""

from __future__ import annotations

import csv
import io
import time

import numpy as np
import pytest

from tests.conftest import UR5_WAYPOINTS
from toptraj import robots
from toptraj.service.formats import chosen_format, time_from_start

PATH = {"kind": "waypoints", "waypoints": UR5_WAYPOINTS, "interpolation": "spline"}


def _request(**output):
    return {"robot": "ur5", "path": PATH, "timing": {"method": "phase_plane"}, "output": {"dt": 0.01, **output}}


def _post(client, body, **headers):
    response = client.post("/v1/trajectories", json=body, headers=headers)
    assert response.status_code == 200, response.text
    return response


def _from_points(trajectory: dict) -> dict[str, np.ndarray]:
    points = trajectory["points"]
    return {
        "t": np.array([p["time_from_start"]["sec"] + p["time_from_start"]["nanosec"] * 1e-9 for p in points]),
        "q": np.array([p["positions"] for p in points]),
        "qd": np.array([p["velocities"] for p in points]),
        "qdd": np.array([p["accelerations"] for p in points]),
        "tau": np.array([p["effort"] for p in points]),
    }


def test_a_joint_trajectory_holds_the_samples_numbers(client):
    samples = _post(client, _request(exact_period=True)).json()
    ros = _post(client, _request(format="joint_trajectory")).json()  # exact_period by default
    assert "samples" not in ros and ros["joint_trajectory"]["joint_names"] == samples["joint_names"]
    points = _from_points(ros["joint_trajectory"])
    for key in ("q", "qd", "qdd", "tau"):
        np.testing.assert_array_equal(points[key], np.array(samples["samples"][key]))
    np.testing.assert_allclose(points["t"], samples["samples"]["t"], rtol=0, atol=1e-9)  # nanosecond stamps
    assert ros["duration"] == samples["duration"] and ros["sampled_duration"] == samples["sampled_duration"]


def test_the_csv_parses_to_the_same_numbers(client):
    samples = _post(client, _request(exact_period=True)).json()
    response = _post(client, _request(format="csv"))
    assert response.headers["content-type"].startswith("text/csv")
    rows = list(csv.reader(line for line in io.StringIO(response.text) if not line.startswith("#")))
    names = samples["joint_names"]
    assert rows[0] == ["t"] + [f"{k}.{n}" for k in ("q", "qd", "qdd", "tau") for n in names]
    table = np.array(rows[1:], dtype=float)
    n = len(names)
    np.testing.assert_array_equal(table[:, 0], samples["samples"]["t"])
    for j, key in enumerate(("q", "qd", "qdd", "tau")):
        np.testing.assert_array_equal(table[:, 1 + j * n : 1 + (j + 1) * n], np.array(samples["samples"][key]))


def test_accept_text_csv_chooses_csv(client):
    assert _post(client, _request(), accept="text/csv").headers["content-type"].startswith("text/csv")
    assert _post(client, _request(), accept="application/json, text/csv;q=0.5").headers["content-type"] == "application/json"
    assert _post(client, _request(), accept="text/csv;q=0.9, application/json;q=0.2").text.startswith("t,")
    # an explicit format wins over the header
    assert "joint_trajectory" in _post(client, _request(format="joint_trajectory"), accept="text/csv").json()


@pytest.mark.parametrize(
    ("accept", "chosen"),
    [(None, "samples"), ("*/*", "samples"), ("text/*", "csv"), ("application/json", "samples"), ("text/csv;q=0", "samples")],
)
def test_the_accept_header_rule(accept, chosen):
    assert chosen_format("samples", accept) == chosen


def test_exact_period_samples_end_on_a_period_at_rest_within_the_limits(client):
    plain = _post(client, _request()).json()
    exact = _post(client, _request(exact_period=True)).json()
    t_plain, t = np.array(plain["samples"]["t"]), np.array(exact["samples"]["t"])
    assert t_plain[-1] - t_plain[-2] < 0.01 - 1e-6  # the uneven last step this option removes
    periods = len(t) - 1
    np.testing.assert_allclose(t, 0.01 * np.arange(periods + 1), rtol=0, atol=1e-12)
    assert exact["duration"] == plain["duration"] <= exact["sampled_duration"] < plain["duration"] + 0.01
    assert exact["sampled_duration"] == pytest.approx(0.01 * periods, abs=1e-12)
    q, qd = np.array(exact["samples"]["q"]), np.array(exact["samples"]["qd"])
    np.testing.assert_allclose(q[-1], UR5_WAYPOINTS[-1], atol=1e-9)
    np.testing.assert_allclose(qd[[0, -1]], 0.0, atol=1e-9)
    limits = robots.load("ur5").limits
    for key, limit in (("qd", limits.velocity), ("qdd", limits.acceleration), ("tau", limits.torque)):
        assert np.all(np.abs(np.array(exact["samples"][key])) <= limit * 1.005), key
    # slowed uniformly: the same path, the peak speed lower by the stretch factor
    k = exact["sampled_duration"] / exact["duration"]
    assert np.abs(qd).max() == pytest.approx(np.abs(np.array(plain["samples"]["qd"])).max() / k, rel=2e-3)


def test_time_from_start_splits_seconds_and_nanoseconds():
    assert time_from_start(np.array([0.0, 0.01, 1.0, 2.5, 1.999999999])) == [
        {"sec": 0, "nanosec": 0},
        {"sec": 0, "nanosec": 10_000_000},
        {"sec": 1, "nanosec": 0},
        {"sec": 2, "nanosec": 500_000_000},
        {"sec": 1, "nanosec": 999_999_999},
    ]


def test_exact_period_with_moving_ends_is_refused(client):
    body = _request(exact_period=True)
    body["path"] = {"kind": "waypoints", "waypoints": [[0.0] * 6, [0.5] * 6], "interpolation": "spline"}
    body["timing"]["boundary"] = {"end_velocity": [0.1] * 6}
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 422 and "exact_period" in response.json()["detail"]


def _metadata(text: str) -> dict[str, list[str]]:
    """The ``# key: value`` lines of a CSV answer, each key with its values in order."""
    found: dict[str, list[str]] = {}
    for line in text.splitlines():
        if line.startswith("# "):
            key, value = line[2:].split(": ", 1)
            found.setdefault(key, []).append(value)
    return found


def test_the_csv_carries_its_metadata_and_numpy_reads_it(client):
    """Method, durations, peak utilization and warnings in ``#`` lines after the header: the
    JSON answer's values, and numpy's readers (as pandas' ``comment="#"``) skip them."""
    body = _request(exact_period=True)
    body["path"]["waypoints"] = [[0.0, -1.2, 1.0, 0.0, 0.0, 0.0], *UR5_WAYPOINTS[1:]]  # starts in a singularity: a warning
    answer = _post(client, body).json()
    assert answer["warnings"]
    text = _post(client, {**body, "output": {"dt": 0.01, "format": "csv"}}).text
    meta = _metadata(text)
    assert meta["robot"] == ["ur5"] and meta["method"] == ["phase_plane"]
    assert meta["duration"] == [f"{answer['duration']!r} s"] and meta["sampled_duration"] == [f"{answer['sampled_duration']!r} s"]
    assert meta["warnings"] == [str(len(answer["warnings"]))] and meta["warning"] == answer["warnings"]
    for kind, values in answer["peak_utilization"].items():
        assert [float(v) for v in meta[f"peak_utilization.{kind}"][0].split(",")] == values
    table = np.loadtxt(io.StringIO(text), delimiter=",", skiprows=1)
    np.testing.assert_array_equal(table[:, 0], answer["samples"]["t"])
    np.testing.assert_array_equal(table[:, 1:7], answer["samples"]["q"])
    named = np.genfromtxt(io.StringIO(text), delimiter=",", names=True, deletechars="")
    np.testing.assert_array_equal(named["tau.wrist_3_joint"], np.array(answer["samples"]["tau"])[:, 5])


def test_a_binding_limit_is_in_the_csv(client):
    body = {**_request(format="csv"), "timing": {"method": "quintic"}}
    answer = _post(client, {**body, "output": {"dt": 0.01}}).json()
    binding = answer["binding"]
    assert _metadata(_post(client, body).text)["binding"] == [f"{binding['kind']}, joint {binding['joint']}, s = {binding['s']!r}"]


def _job_answer(client, job: dict, **headers):
    response = client.post("/v1/jobs", json=job)
    assert response.status_code == 202, response.text
    job_id, give_up = response.json()["id"], time.monotonic() + 120.0
    while client.get(f"/v1/jobs/{job_id}").json()["status"] in ("queued", "running"):
        assert time.monotonic() < give_up, f"job {job_id} still running"
        time.sleep(0.05)
    return client.get(f"/v1/jobs/{job_id}/result", headers=headers)


def test_a_job_answers_in_the_format_asked_as_the_synchronous_endpoint(client):
    synchronous = _post(client, _request(format="csv"))
    asked = _job_answer(client, {"trajectory": _request(format="csv")}, accept="application/json")
    assert asked.headers["content-type"] == synchronous.headers["content-type"] and asked.text == synchronous.text
    accepted = _job_answer(client, {"trajectory": _request(exact_period=True)}, accept="text/csv")
    assert accepted.headers["content-type"].startswith("text/csv") and accepted.text == synchronous.text
    assert _job_answer(client, {"trajectory": _request(exact_period=True)}).headers["content-type"] == "application/json"
    ros = _job_answer(client, {"trajectory": _request(format="joint_trajectory")}, accept="text/csv")  # the format asked wins
    assert ros.json()["joint_trajectory"] == _post(client, _request(format="joint_trajectory")).json()["joint_trajectory"]
    compared = _job_answer(client, {"compare": {"robot": "ur5", "path": PATH, "methods": ["quintic"]}}, accept="text/csv")
    assert compared.headers["content-type"] == "application/json" and compared.json()["results"][0]["method"] == "quintic"
