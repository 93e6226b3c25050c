"""The OpenAPI describes the API fully: every example of ``examples/`` is an example of its
endpoint, the methods are enums, and every field says what it is."""

from __future__ import annotations

import ast
import json
import re

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
    shown = {
        **_body_examples(openapi, "/v1/trajectories"),
        **_body_examples(openapi, "/v1/trajectories/compare"),
        **_body_examples(openapi, "/v1/cells"),
    }
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


# --- descriptions speak to the user ----------------------------------------------------------

#: The project's packages: a dotted name starting with one of them names a module.
PACKAGES = ("service", "planners", "robots", "client", "compiled")
#: Their one import name.
IMPORT_NAME = "toptraj"
#: The server's inner workings, which a description has no need to name.
INNER_WORKINGS = ("event loop", "thread pool", "interpreter lock", "fork server", "numba", "worker thread")


def _texts(node, where: str = ""):
    """Every description and summary in ``node`` (an OpenAPI document), with where it is."""
    if isinstance(node, dict):
        for key, value in node.items():
            if key in ("description", "summary") and isinstance(value, str):
                yield where, value
            elif key not in ("example", "examples", "default"):
                yield from _texts(value, f"{where}/{key}")
    elif isinstance(node, list):
        for index, value in enumerate(node):
            yield from _texts(value, f"{where}[{index}]")


def _vocabulary(node, found: set[str]) -> set[str]:
    """The API's own names: schemas, properties, parameters, enum values and path segments."""
    if isinstance(node, dict):
        for key, value in node.items():
            if key in ("properties", "schemas", "paths") and isinstance(value, dict):
                found.update(re.findall(r"\w+", " ".join(value)))
            elif key == "enum" and isinstance(value, list):
                found.update(str(v) for v in value)
            elif key == "name" and isinstance(value, str):
                found.add(value)
            _vocabulary(value, found)
    elif isinstance(node, list):
        for value in node:
            _vocabulary(value, found)
    return found


def _code_names() -> set[str]:
    """What the project's code names: modules, functions, classes and module-level constants."""
    names: set[str] = set()
    for package in PACKAGES:
        for path in (ROOT / package).rglob("*.py"):
            tree = ast.parse(path.read_text(encoding="utf-8"))
            names.add(path.stem)
            names.update(n.name for n in ast.walk(tree) if isinstance(n, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef))
            for node in tree.body:
                targets = node.targets if isinstance(node, ast.Assign) else [node.target] if isinstance(node, ast.AnnAssign) else []
                names.update(t.id for t in targets if isinstance(t, ast.Name))
    return names


def _identifier_shaped(name: str) -> bool:
    """Reads as code, not as a word: snake_case, CamelCase with two humps, a leading underscore."""
    return "_" in name or re.search(r"[a-z][A-Z]", name) is not None


def test_no_description_names_the_code(openapi):
    """Descriptions and summaries speak of the API (its fields, values, endpoints), never of the
    code behind it: no module path, no function, class or constant of the code that is not
    also a name of the API, and no inner workings of the server."""
    internal = {name for name in _code_names() - _vocabulary(openapi, set()) if _identifier_shaped(name)}
    found = []
    for where, text in _texts(openapi):
        for token in re.findall(r"[A-Za-z_][A-Za-z0-9_]*(?:\.[A-Za-z_][A-Za-z0-9_]*)*", text):
            if token.split(".")[0] in (*PACKAGES, IMPORT_NAME) and "." in token or token in internal:
                found.append(f"{where}: {token}")
        found += [f"{where}: {words}" for words in INNER_WORKINGS if words in text.lower()]
    assert found == [], "\n".join(found)
