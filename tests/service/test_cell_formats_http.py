"""POST /v1/cells in every output format of the trajectory endpoint (samples, one
JointTrajectory per arm, CSV), every arm on the same times; its torques by an independent
Pinocchio RNEA (the payload as a link of the URDF, the world's gravity as each base feels it);
and the 422 of a payload no timing holds and of an arm's path that folds onto itself."""

from __future__ import annotations

import copy
import io
import json

import numpy as np
import pinocchio as pin
import pytest

from tests.paths import ROOT
from tests.planners.collision.test_self_collision import FOLDING
from tests.robots.test_equipment import COM, INERTIA, MASS, _ur5_with_load_link
from toptraj.planners.errors import InvalidRequest
from toptraj.robots.catalog import example_urdf_path
from toptraj.service import problems
from toptraj.service.cell_answers import sample_times

EXAMPLE = json.loads((ROOT / "examples" / "cell_two_ur5.json").read_text())
#: Gravity tilted in the world: the second base, turned half a turn about z, feels it as [-1, 0, -9.7].
GRAVITY = [1.0, 0.0, -9.7]
INERTIA6 = [INERTIA[0, 0], INERTIA[1, 1], INERTIA[2, 2], INERTIA[0, 1], INERTIA[0, 2], INERTIA[1, 2]]


def _body(format_: str, **fields) -> dict:
    body = copy.deepcopy(EXAMPLE) | {"format": format_, "gravity": GRAVITY, "dt": 0.02} | fields
    body["arms"][0]["payload"] = {"mass": MASS, "center_of_mass": list(COM), "inertia": INERTIA6}
    return body


@pytest.fixture(scope="module")
def answers(patient_client):
    out = {}
    for format_ in ("samples", "joint_trajectory", "csv"):
        response = patient_client.post("/v1/cells", json=_body(format_))
        assert response.status_code == 200, response.text
        out[format_] = response
    out["periods"] = patient_client.post("/v1/cells", json=_body("samples", exact_period=True))
    assert out["periods"].status_code == 200, out["periods"].text
    return out


def test_the_controller_formats_sample_on_whole_periods_to_the_final_state(answers):
    free, exact = answers["samples"].json(), answers["periods"].json()
    assert exact["duration"] == free["duration"] and free["sampled_duration"] == free["duration"]
    t = np.array(exact["t"])
    assert np.allclose(t, 0.02 * np.arange(len(t)), atol=1e-12) and 0.0 <= exact["sampled_duration"] - exact["duration"] < 0.02
    assert exact["sampled_duration"] == t[-1]
    for arm, given in zip(exact["arms"], EXAMPLE["arms"]):
        q = np.array(arm["samples"]["q"])
        assert np.allclose(q[-1], given["waypoints"][-1], atol=1e-9) and np.allclose(arm["samples"]["qd"][-1], 0.0, atol=1e-9)
        assert max(max(values) for values in arm["peak_utilization"].values()) <= 1.005


def _rnea(model: pin.Model, gravity, q, qd, qdd) -> np.ndarray:
    model.gravity = pin.Motion(np.asarray(gravity, dtype=float), np.zeros(3))
    data = model.createData()
    return np.array([pin.rnea(model, data, *state) for state in zip(q, qd, qdd)])


def test_each_arms_torques_are_an_independent_rnea_with_its_payload_and_gravity(answers):
    answer = answers["samples"].json()
    references = ((_ur5_with_load_link(), GRAVITY), (pin.buildModelFromUrdf(example_urdf_path("ur5")), [-1.0, 0.0, -9.7]))
    for arm, (model, gravity) in zip(answer["arms"], references):
        samples = arm["samples"]
        q, qd, qdd, tau = (np.array(samples[key]) for key in ("q", "qd", "qdd", "tau"))
        assert np.abs(tau - _rnea(model, gravity, q, qd, qdd)).max() <= 1e-9
        assert samples["t"] == answer["t"]
        assert set(arm["peak_utilization"]) == {"velocity", "acceleration", "torque"}
        assert max(max(values) for values in arm["peak_utilization"].values()) <= 1.005


def test_one_joint_trajectory_per_arm_with_the_samples_and_efforts(answers):
    samples = answers["periods"].json()
    answer = answers["joint_trajectory"].json()
    assert answer["t"] == samples["t"]
    for arm, same in zip(answer["arms"], samples["arms"]):
        message = arm["joint_trajectory"]
        assert message["joint_names"] == same["joint_names"] and "samples" not in arm
        points = message["points"]
        stamps = [p["time_from_start"]["sec"] + 1e-9 * p["time_from_start"]["nanosec"] for p in points]
        assert np.allclose(stamps, samples["t"], atol=1e-9)
        for field, key in (("positions", "q"), ("velocities", "qd"), ("accelerations", "qdd"), ("effort", "tau")):
            assert np.array_equal(np.array([p[field] for p in points]), np.array(same["samples"][key]))


def test_csv_holds_every_arm_on_one_clock_and_the_answers_facts(answers, patient_client):
    response = answers["csv"]
    assert response.headers["content-type"].startswith("text/csv")
    samples = answers["periods"].json()
    text = response.text
    header = text.splitlines()[0].split(",")
    names = samples["arms"][0]["joint_names"]
    assert (
        header[:2] == ["t", f"arms[0].q.{names[0]}"] and header[-1] == f"arms[1].tau.{names[-1]}" and len(header) == 1 + 2 * 4 * 6
    )
    table = np.loadtxt(io.StringIO(text), delimiter=",", comments="#", skiprows=1)
    expected = np.column_stack(
        [samples["t"]] + [np.array(arm["samples"][key]) for arm in samples["arms"] for key in ("q", "qd", "qdd", "tau")]
    )
    assert np.array_equal(table, expected)
    assert (
        f"# duration: {samples['duration']!r} s" in text
        and f"# sampled_duration: {samples['sampled_duration']!r} s" in text
        and f"# time_lost: {samples['time_lost']!r} s" in text
    )
    assert "# peak_utilization.arms[1].torque: " in text
    by_accept = patient_client.post("/v1/cells", json=_body("samples"), headers={"Accept": "text/csv"})
    assert by_accept.status_code == 200 and by_accept.text == text


def test_a_payload_no_timing_holds_is_a_422_naming_the_arm_joint_and_s(patient_client):
    body = copy.deepcopy(EXAMPLE)
    body["arms"][0]["payload"] = {"mass": 40.0, "center_of_mass": [0.0, 0.0, 0.1]}
    response = patient_client.post("/v1/cells", json=body)
    assert response.status_code == 422, response.text
    detail = response.json()["detail"]
    assert detail.startswith("arms[0] (ur5)") and "torque" in detail and "joint '" in detail and "s = " in detail


def test_an_arm_whose_path_folds_onto_itself_is_a_422_naming_the_links_and_s(patient_client):
    body = copy.deepcopy(EXAMPLE)
    body["arms"][1] = {"robot": "ur5", "base": {"position": [0.0, 3.0, 0.0]}, "waypoints": FOLDING.tolist()}
    response = patient_client.post("/v1/cells", json=body)
    assert response.status_code == 422, response.text
    detail = response.json()["detail"]
    assert detail.startswith("arms[1] (ur5): links 'shoulder_link' and 'forearm_link' touch at s = ")


def test_too_many_samples_are_a_422_saying_the_least_dt():
    """31.94 s at dt = 1 ms is 31,940 samples, above 20,000: the refusal names dt and the least
    dt that serves (31.94 / 20,000 = 1.597 ms, up to the next 0.1 ms), and that dt serves."""
    with pytest.raises(InvalidRequest) as refused:
        sample_times(31.94, 0.001)
    assert refused.value.field == "dt"
    assert problems.detail(refused.value) == (
        "the cell's motion lasts 31.94 s: 31940 samples of dt = 0.001 s exceed 20000; give dt >= 0.0016 s"
    )
    assert len(sample_times(31.94, 0.0016)) <= 20_001


def test_the_clients_cell_docstring_names_what_the_answer_holds(answers):
    """``Client.cell`` promises the answer's keys, each arm's too, and no ``trajectory`` key."""
    from toptraj.client import Client

    doc = Client.cell.__doc__ or ""
    answer = answers["samples"].json()
    keys = set(answer) | set(answer["arms"][0]) | set(answers["joint_trajectory"].json()["arms"][0])
    assert [key for key in sorted(keys) if f"``{key}``" not in doc] == []
    assert "``trajectory``" not in doc and "two to four arms" in doc
