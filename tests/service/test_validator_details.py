"""The sentence of each schema validator (service/schemas/) reaches the problem's detail as the
service's own: the field, then the sentence, without pydantic's "Value error, " before it."""

from __future__ import annotations

import json

import pytest
from pydantic import ValidationError

from tests.conftest import UR5_WAYPOINTS
from toptraj.service.problems import validation_problem
from toptraj.service.schemas.trajectories import TrajectoryRequest

PATH = {"waypoints": UR5_WAYPOINTS[:2]}
ARM = {"robot": "ur5", "waypoints": UR5_WAYPOINTS[:2]}


def _zone(**zone):
    return {"robot": "ur5", "path": PATH, "timing": {"zones": [zone]}}


#: (route, body, the field and the start of the validator's sentence), one per validator.
CASES = [
    ("/v1/trajectories", _zone(velocity_scale=0.5), "timing.zones[0]: give exactly one of s_range, sphere and box"),
    ("/v1/trajectories", _zone(s_range=[0.5, 0.2], velocity_scale=0.5), "timing.zones[0]: s_range [0.5, 0.2] runs backwards"),
    ("/v1/trajectories", _zone(s_range=[0.2, 0.5]), "timing.zones[0]: the zone sets no limit"),
    ("/v1/trajectories", {"robot": "ur5", "path": PATH, "mounting": {"orientation": [1, 1, 0, 0]}}, "mounting.orientation: orientation has norm"),
    (
        "/v1/trajectories",
        {"robot": "ur5", "path": PATH, "mounting": {"rotation": [[1, 0, 0], [0, 1, 0], [0, 0, -1]]}},
        "mounting.rotation: ",
    ),
    (
        "/v1/trajectories",
        {"robot": "ur5", "path": PATH, "mounting": {"orientation": [0, 0, 0, 1], "rotation": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]}},
        "mounting: give mounting.orientation or mounting.rotation, not both",
    ),
    ("/v1/trajectories", {"robot": "ur5", "path": PATH, "payload": {"mass": 1, "inertia": [1, 1, 5, 0, 0, 0]}}, "payload.inertia: inertia's principal"),
    ("/v1/cells", {"arms": [{**ARM, "positions": [[0, 0, 0]]}]}, "arms[0]: positions: an arm of a cell follows joint waypoints only"),
    ("/v1/jobs", {}, "body: give exactly one of `trajectory`"),
]


@pytest.mark.parametrize("route, body, start", CASES)
def test_a_validator_sentence_is_the_services_own(client, route, body, start):
    response = client.post(route, json=body)
    assert response.status_code == 422, response.text
    problem = response.json()
    assert problem["detail"].startswith(start), problem["detail"]
    assert "Value error" not in response.text
    assert problem["errors"][0]["message"] == problem["detail"].split(": ", 1)[1]


def test_the_framework_free_problem_drops_the_prefix_and_writes_places_as_the_http_one():
    """The CLI and the batches word a schema's refusal with ``validation_problem``: places as
    the HTTP 422 writes them (``timing.zones[0]``, not pydantic's ``timing.zones.0``)."""
    with pytest.raises(ValidationError) as refused:
        TrajectoryRequest.model_validate(_zone(s_range=[0.5, 0.2], velocity_scale=0.5))
    problem = validation_problem(refused.value)
    sentence = "s_range [0.5, 0.2] runs backwards: the zone covers no part of the path; give [s0, s1] with s1 > s0"
    assert problem["detail"] == f"timing.zones[0]: {sentence}"
    assert problem["errors"] == [{"field": "timing.zones[0]", "message": sentence}]


def test_the_cli_and_a_batch_line_write_places_as_the_http_422(client, tmp_path, capsys):
    from toptraj.service.batches.work import answer
    from toptraj.service.cli import main

    body = {"robot": "ur5", "path": {"kind": "waypoints", "waypoints": UR5_WAYPOINTS[:2], "obstacles": [{"kind": "sphere", "center": [0, 0], "radius": 0.1}]}}
    expected = client.post("/v1/trajectories", json=body).json()
    assert expected["errors"][0]["field"] == "path.obstacles[0].center"
    status, line = answer(json.dumps(body), 10.0)
    assert status == 422 and json.loads(line)["detail"] == expected["detail"]
    request = tmp_path / "request.json"
    request.write_text(json.dumps(body))
    assert main(["plan", str(request)]) == 1
    assert json.loads(capsys.readouterr().err)["detail"] == expected["detail"]


SHAPES = (
    "give 6 values [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] or a 3x3 matrix (3 rows of 3), in kg m^2 (principal moments [a, b, c] "
    "about the centre of mass are [a, b, c, 0, 0, 0])"
)


@pytest.mark.parametrize(
    "inertia, detail",
    [
        ([[1, 0, 0], [0, 1, 0]], f"payload.inertia: {SHAPES}"),
        ([1, 1, 1, 0, 0], f"payload.inertia: {SHAPES}"),
        ("diagonal", f"payload.inertia: {SHAPES}"),
        ([0.1, 0.1, 0.1], f"payload.inertia: {SHAPES}"),  # was read as 3 rows: "put each item's values in brackets"
        ([1e9, 1, 1, 0, 0, 0], "payload.inertia[0]: 1e+09 is not within the accepted range [-10000, 10000] kg m^2"),
        ([[1, 0, 0], [0, 1, 0], [0, 0]], "payload.inertia[2]: List should have at least 3 items, not 2"),
        ([1, 1, "a", 0, 0, 0], "payload.inertia[2]: Input should be a valid number; got the string 'a'"),
    ],
)
def test_an_inertia_of_neither_form_names_the_one_meant(client, inertia, detail):
    """An inertia is 6 values or 3 rows of 3: the 422 names the form its count points to (or
    both forms), never each form's failures under pydantic's names for them."""
    response = client.post("/v1/trajectories", json={"robot": "ur5", "path": PATH, "payload": {"mass": 1.0, "inertia": inertia}})
    assert response.status_code == 422, response.text
    assert response.json()["detail"] == detail


@pytest.mark.parametrize(
    "obstacle, field",
    [
        ({"kind": "sphere", "center": [0, 0], "radius": 0.1}, "path.obstacles[0].center"),
        ({"kind": "box", "center": [0, 0, 0], "size": [0.1, 0.1, -1]}, "path.obstacles[0].size[2]"),
    ],
)
def test_an_obstacle_field_is_named_as_the_request_names_it(client, obstacle, field):
    """The obstacle's kind chooses its schema; the 422 names the field without the kind between
    (``path.obstacles[0].center``, as the request writes it)."""
    body = {"robot": "ur5", "path": {**PATH, "obstacles": [obstacle]}}
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 422, response.text
    assert response.json()["errors"][0]["field"] == field
    assert response.json()["detail"].startswith(f"{field}: ")



@pytest.mark.parametrize(
    "path, detail",
    [
        ({"kind": "cartesian", "start": UR5_WAYPOINTS[0], "positions": [[0.4, 0.5]]}, "path.positions[0]: List should have at least 3 items, not 2"),
        ({"waypoints": UR5_WAYPOINTS[:1]}, "path.waypoints: List should have at least 2 items, not 1"),
    ],
)
def test_a_count_is_the_requests_own(client, path, detail):
    """A list of the wrong count is told by the request's count, without pydantic's "after
    validation"."""
    response = client.post("/v1/trajectories", json={"robot": "ur5", "path": path})
    assert response.status_code == 422, response.text
    assert response.json()["detail"] == detail
