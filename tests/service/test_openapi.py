"""The OpenAPI describes the API fully: every example of ``examples/`` is an example of its
endpoint, the methods are enums, and every field says what it is."""

from __future__ import annotations

import json

import pytest

from tests.paths import ROOT

EXAMPLES = ROOT / "examples"


@pytest.fixture(scope="module")
def openapi(client):
    return client.get("/openapi.json").json()


def _body_examples(openapi, path):
    content = openapi["paths"][path]["post"]["requestBody"]["content"]["application/json"]
    return {name: example["value"] for name, example in content["examples"].items()}


def test_every_example_file_is_an_example_of_its_endpoint(openapi):
    shown = {**_body_examples(openapi, "/v1/trajectories"), **_body_examples(openapi, "/v1/trajectories/compare")}
    files = {path.stem: json.loads(path.read_text()) for path in EXAMPLES.glob("*.json")}
    assert files and shown == files
    assert all("methods" in body for body in _body_examples(openapi, "/v1/trajectories/compare").values())


def test_methods_are_enums(openapi):
    schemas = openapi["components"]["schemas"]
    enum = schemas["TimingRequest"]["properties"]["method"]["enum"]
    assert {"phase_plane", "toppra", "min_cost", "collocation", "quintic", "ruckig"} <= set(enum)
    assert schemas["CompareRequest"]["properties"]["methods"]["items"]["enum"] == enum


def test_an_unknown_method_is_a_422_naming_the_choices(client):
    body = {"robot": "ur5", "path": {"waypoints": [[0.0] * 6, [0.1] * 6]}, "timing": {"method": "fastest"}}
    response = client.post("/v1/trajectories", json=body)
    assert response.status_code == 422 and "timing.method" in response.text and "phase_plane" in response.text


def test_every_field_is_described(openapi):
    undescribed = [
        f"{name}.{field}"
        for name, schema in openapi["components"]["schemas"].items()
        for field, spec in schema.get("properties", {}).items()
        if not spec.get("description")
    ]
    assert undescribed == []


def test_the_path_kind_is_a_discriminator(openapi):
    path = openapi["components"]["schemas"]["TrajectoryRequest"]["properties"]["path"]
    assert path["discriminator"]["propertyName"] == "kind"
    refs = {option["$ref"] for option in path["oneOf"]}
    assert set(path["discriminator"]["mapping"].values()) == refs


@pytest.mark.parametrize(
    ("schema", "field", "unit"),
    [("SamplesPublic", "qd", "rad/s"), ("SamplesPublic", "tau", "N m"), ("OutputRequest", "dt", "(s)"), ("PhasePlanePublic", "sd", "1/s")],
)
def test_physical_fields_state_their_units(openapi, schema, field, unit):
    assert unit in openapi["components"]["schemas"][schema]["properties"][field]["description"]


@pytest.mark.parametrize(
    "timing_or_output",
    [{"timing": {"limit_margin": False}}, {"output": {"dt": "0.01"}}, {"timing": {"grid_points": 10.0}}, {"output": {"exact_period": 1}}],
)
def test_a_value_of_another_json_type_is_refused_as_the_schema_says(client, timing_or_output):
    body = {"robot": "ur5", "path": {"waypoints": [[0.0] * 6, [0.1] * 6]}, **timing_or_output}
    assert client.post("/v1/trajectories", json=body).status_code == 422
