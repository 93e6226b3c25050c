"""The OpenAPI of the error answers: ``problem_responses`` (a route's ``responses=``) and
``declare_problems`` make the schema say what the service answers: problem+json bodies
(``Problem``) for 400, 404, 409, 413, 415, 422, 503 and 504, in place of FastAPI's default 422."""

from __future__ import annotations

import json
from typing import Any

from fastapi import FastAPI

from toptraj.service.schemas.common import Problem

PROBLEM_JSON = "application/problem+json"
_REF = "#/components/schemas/"
_DESCRIPTIONS = {
    400: "The request body cannot be read.",
    404: "No such resource (e.g. an unknown robot).",
    409: "The name is taken.",
    413: "The request body exceeds the size cap.",
    415: "The body was sent without `Content-Type: application/json`.",
    422: "Malformed or impossible input: a field out of range, wrong lengths, NaN/inf, a path "
    "that no timing can follow (the detail says where).",
    503: "The service cannot do this now (e.g. its data directory cannot be written).",
    504: "The computation ran past its time budget.",
}
#: What every operation with a body may answer, whatever it declares (FastAPI itself adds a
#: 422 to operations with parameters; its content is replaced below).
_WITH_BODY = (400, 413, 415, 422)


def _problem_content() -> dict:
    return {PROBLEM_JSON: {"schema": {"$ref": _REF + "Problem"}}}


def problem_responses(*statuses: int) -> dict[int | str, dict[str, Any]]:
    """``responses=`` of a route: each status answered with a problem+json body."""
    return {status: {"description": _DESCRIPTIONS[status], "content": _problem_content()} for status in statuses}


def _problem_schemas() -> dict[str, dict]:
    schema = Problem.model_json_schema(ref_template=_REF + "{model}")
    definitions = schema.pop("$defs", {})
    return {"Problem": schema, **definitions}


def _declare(openapi: dict) -> dict:
    components = openapi.setdefault("components", {}).setdefault("schemas", {})
    components.update(_problem_schemas())
    for operations in openapi.get("paths", {}).values():
        for operation in operations.values():
            if not isinstance(operation, dict) or "responses" not in operation:
                continue
            responses = operation["responses"]
            for status in _WITH_BODY if "requestBody" in operation else ():
                responses[str(status)] = problem_responses(status)[status]
            for status, response in responses.items():
                if status.isdigit() and int(status) >= 400:
                    response["content"] = _problem_content()
    for name in ("HTTPValidationError", "ValidationError"):
        if f'"{_REF}{name}"' not in json.dumps(openapi):
            components.pop(name, None)
    return openapi


def declare_problems(app: FastAPI) -> None:
    """Make ``app``'s OpenAPI declare its error answers as problem+json (``Problem``), with
    FastAPI's default 422 schema replaced."""

    def openapi() -> dict:
        return _declare(FastAPI.openapi(app))

    app.openapi = openapi  # type: ignore[method-assign]  # FastAPI's way to extend its schema
