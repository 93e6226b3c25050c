"""A field put in the wrong place: the 422 says where a field of that name belongs in the body's
schema (``toptraj.service.field_hints``), and nothing for a name the schema does not have."""

from __future__ import annotations

import json

import pytest

from tests.paths import ROOT
from toptraj.service.field_hints import field_places

WAYPOINTS = {"robot": "ur5", "path": {"waypoints": [[0.0] * 6, [0.1] * 6]}}


@pytest.mark.parametrize(
    ("body", "detail"),
    [
        ({**WAYPOINTS, "format": "csv"}, "format: Extra inputs are not permitted: 'format' belongs in output.format"),
        ({**WAYPOINTS, "timing": {"dt": 0.01}}, "timing.dt: Extra inputs are not permitted: 'dt' belongs in output.dt"),
        ({**WAYPOINTS, "timing": {"bogus": 1}}, "timing.bogus: Extra inputs are not permitted"),
    ],
    ids=["top-level format", "dt under timing", "unknown name"],
)
def test_a_misplaced_field_is_refused_with_where_it_belongs(client, body, detail):
    answer = client.post("/v1/trajectories", json=body)
    assert answer.status_code == 422
    assert answer.json()["detail"] == detail


def test_the_advised_place_is_accepted(client):
    """Moving the field where the hint says gives a 200."""
    answer = client.post("/v1/trajectories", json={**WAYPOINTS, "output": {"format": "csv"}})
    assert answer.status_code == 200


def test_places_inside_lists_are_written_with_an_index():
    from toptraj.service.schemas.trajectories import TrajectoryRequest

    places = field_places(TrajectoryRequest)
    assert "timing.zones[i].tool_speed" in places["tool_speed"]
    assert places["format"] == ("output.format",)


def _set(body: dict, place: tuple, value) -> dict:
    """``body`` with ``value`` at ``place`` (keys and indices), copied."""
    body = json.loads(json.dumps(body))
    holder = body
    for part in place[:-1]:
        holder = holder[part]
    holder[place[-1]] = value
    return body


ZONED = {**WAYPOINTS, "timing": {"zones": [{"s_range": [0.2, 0.6], "velocity_scale": 0.5}]}}


@pytest.mark.parametrize(
    ("body", "typo", "meant"),
    [
        (WAYPOINTS, ("timng",), "timing"),
        ({**WAYPOINTS, "timing": {}}, ("timing", "methd"), "method"),
        ({**WAYPOINTS, "output": {}}, ("output", "formt"), "format"),
        (ZONED, ("timing", "zones", 0, "velocity_scal"), "velocity_scale"),
        ({"robot": "ur5", "path": {"waypoints": [[0.0] * 6, [0.1] * 6]}}, ("path", "interpolaton"), "interpolation"),
    ],
)
def test_a_misspelt_field_is_refused_with_the_name_meant_and_the_advice_works(client, body, typo, meant):
    value = {"method": "toppra", "format": "csv", "interpolation": "linear", "velocity_scale": 0.4, "timing": {}}[meant]
    if typo[-1] == "velocity_scal":
        body = _set(body, typo[:-1], {"s_range": [0.2, 0.6]})
    answer = client.post("/v1/trajectories", json=_set(body, typo, value))
    assert answer.status_code == 422
    place = ".".join(str(part) for part in typo).replace(".0.", "[0].")
    assert answer.json()["detail"] == f"{place}: Extra inputs are not permitted: did you mean {meant!r}?"
    followed = client.post("/v1/trajectories", json=_set(body, (*typo[:-1], meant), value))
    assert followed.status_code == 200, followed.text


def test_no_name_is_offered_when_none_is_close_or_none_is_allowed_there(client):
    far = client.post("/v1/trajectories", json={**WAYPOINTS, "timing": {"frobnicate": 1}})
    assert far.json()["detail"] == "timing.frobnicate: Extra inputs are not permitted"
    # A cartesian path has points, not waypoints: the member of the path union is the one named.
    cartesian = client.post("/v1/trajectories", json={"robot": "ur5", "path": {"kind": "cartesian", "points": [[0.4, 0, 0.4]], "waypont": 1}})
    assert "did you mean" not in cartesian.text
    assert "path.waypont: Extra inputs are not permitted" in cartesian.json()["detail"]


def test_a_batch_request_and_the_cli_get_the_name_meant_too(client, tmp_path, capsys):
    from toptraj.service.cli import main

    body = {**WAYPOINTS, "timing": {"methd": "toppra"}}
    answer = client.post("/v1/batches", json={"requests": [WAYPOINTS, body]})
    assert answer.json()["detail"] == "requests[1].timing.methd: Extra inputs are not permitted: did you mean 'method'?"
    request = tmp_path / "request.json"
    request.write_text(json.dumps(body))
    assert main(["plan", str(request)]) == 1
    assert json.loads(capsys.readouterr().err)["detail"] == "timing.methd: Extra inputs are not permitted: did you mean 'method'?"


#: Unknown keys under ``timing`` in a body meant to be refused quickly.
MANY_UNKNOWN = 3000


def _counted(monkeypatch, module) -> list:
    """``module.unknown_field_hint`` replaced by itself with a count of its calls (the list's length)."""
    calls: list = []
    original = module.unknown_field_hint

    def counting(*args):
        calls.append(args)
        return original(*args)

    monkeypatch.setattr(module, "unknown_field_hint", counting)
    return calls


def test_hints_are_worked_out_only_for_the_errors_a_problem_lists(client, monkeypatch):
    """Thousands of unknown keys: each is counted in the detail, only the listed ones get a hint."""
    from toptraj.service import problems

    calls = _counted(monkeypatch, problems)
    body = {**WAYPOINTS, "timing": {f"bogus{k}": 1 for k in range(MANY_UNKNOWN)}}
    answer = client.post("/v1/trajectories", json=body)
    assert answer.status_code == 422
    assert answer.json()["detail"].endswith(f"and {MANY_UNKNOWN - 5} more")
    assert len(answer.json()["errors"]) == problems.LISTED_ERRORS
    assert len(calls) == problems.LISTED_ERRORS


def test_a_batch_hints_only_the_errors_a_problem_lists(client, monkeypatch):
    from toptraj.service.problems import LISTED_ERRORS
    from toptraj.service.routes import batches

    calls = _counted(monkeypatch, batches)
    request = {**WAYPOINTS, "timing": {f"bogus{k}": 1 for k in range(MANY_UNKNOWN)}}
    answer = client.post("/v1/batches", json={"requests": [request]})
    assert answer.status_code == 422
    assert answer.json()["detail"].endswith(f"and {MANY_UNKNOWN - 5} more")
    assert len(calls) == LISTED_ERRORS


def test_the_names_at_a_place_are_walked_once(monkeypatch):
    """Many unknown keys at one place (list items apart) walk the schema for that place once."""
    from toptraj.service import field_hints
    from toptraj.service.schemas.trajectories import TrajectoryRequest

    field_hints._names_at.cache_clear()
    for k in range(50):
        field_hints.nearest(TrajectoryRequest, ("timing", "zones", k, f"velocity_scal{k}"))
    assert field_hints._names_at.cache_info().misses == 1


@pytest.mark.parametrize(("route", "wrap"), [("/v1/trajectories", None), ("/v1/trajectories/compare", None), ("/v1/jobs", "cell")])
def test_a_cell_body_sent_elsewhere_is_pointed_to_the_cells_route(client, route, wrap):
    cell = json.loads((ROOT / "examples" / "cell_two_ur5.json").read_text())
    response = client.post(route, json={wrap: cell} if wrap else cell)
    assert response.status_code == 422, response.text
    detail = response.json()["detail"]
    assert "is planned by POST /v1/cells or `toptraj plan FILE`" in detail, detail
    if wrap is None:  # the one thing said: not where each of the cell's own fields would go in this body
        assert [error["field"] for error in response.json()["errors"]] == ["arms"] and "path.clearance" not in detail
    assert client.post("/v1/cells", json=cell).status_code == 200  # the advice, followed
