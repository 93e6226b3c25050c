"""One request answered as the service answers it, on whichever process runs it (a Ray
worker): the same schemas and the same path through ``toptraj.service.planning``, so a batch's result
equals the synchronous endpoint's answer."""

from __future__ import annotations

import logging
import tempfile

import orjson
from pydantic import ValidationError

from toptraj import robots
from toptraj.planners.execution.deadline import Deadline
from toptraj.robots import ToptrajError
from toptraj.robots.upload_options import UploadOptions
from toptraj.service.batches.lines import problem_body
from toptraj.service.batches.prepare import prepare_worker
from toptraj.service.planning import compare_request, encode_json, plan_request, render
from toptraj.service.problems import detail, status_of, title_of, validation_problem
from toptraj.service.schemas.trajectories import CompareRequest, TrajectoryRequest

logger = logging.getLogger("toptraj.batches")

_configured = False


def _uploads_here(uploads: dict[str, tuple[str, str]]) -> None:
    """Make the uploaded robots a batch uses available in this process: a worker on another
    machine has no access to the server's data directory, so their URDF texts and options
    (``UploadOptions.to_json``) travel with the tasks and are registered in a store of the
    worker's own."""
    global _configured
    if not uploads:
        return
    if not _configured:
        robots.configure_uploads(tempfile.mkdtemp(prefix="toptraj-batch-uploads-"))
        _configured = True
    for name, (urdf, options) in uploads.items():
        robots.register_urdf(urdf, name, UploadOptions.from_json(options))


def answer(text: str, budget_s: float, max_body_bytes: int | None = None) -> tuple[int, bytes]:
    """(status, body as JSON bytes) of one request line (a JSON object, ``lines.parse_line``):
    200 and the answer, or the problem's status and problem+json; anything unexpected is
    this line's 500, never the batch's. ``budget_s`` bounds the computation as the synchronous
    budget does, and ``max_body_bytes`` the answer's samples as the synchronous body cap does.
    The answer stays the bytes the endpoint would send (never decoded and re-encoded)."""
    try:
        body = orjson.loads(text)
    except orjson.JSONDecodeError as error:
        return 422, problem_body(422, "Invalid request", f"the line is not JSON: {str(error)[:200]}")
    schema = CompareRequest if isinstance(body, dict) and "methods" in body else TrajectoryRequest
    try:
        if schema is CompareRequest:
            return 200, encode_json(compare_request(CompareRequest.model_validate_json(text), Deadline(budget_s)))
        request = TrajectoryRequest.model_validate_json(text)
        content, media_type = render(plan_request(request, Deadline(budget_s), max_body_bytes), request)
        return 200, content if media_type == "application/json" else orjson.dumps(content.decode())
    except ValidationError as error:
        return 422, orjson.dumps(validation_problem(error, schema))
    except ToptrajError as error:
        extra = {key: getattr(error, key) for key in ("s", "joint", "limit", "link", "obstacle") if hasattr(error, key)}
        status = status_of(error)
        return status, orjson.dumps({"type": "about:blank", "title": title_of(error), "status": status, "detail": detail(error), **extra})
    except Exception as error:  # a solver's own failure: this line's answer, logged
        logger.error("a batch line failed unexpectedly", exc_info=error)
        return 500, problem_body(500, "Internal error", f"an unexpected {type(error).__name__} occurred while planning this line")


def answer_chunk(
    chunk: list[tuple[str, str]], uploads: dict[str, tuple[str, str]], budget_s: float, max_body_bytes: int | None = None
) -> list[tuple[str, int, bytes]]:
    """(key, status, body) of each (key, request text) of a chunk."""
    _uploads_here(uploads)
    return [(key, *answer(text, budget_s, max_body_bytes)) for key, text in chunk]


def answer_on_worker(
    chunk: list[tuple[str, str]], uploads: dict[str, tuple[str, str]], budget_s: float, max_body_bytes: int | None
) -> tuple[str, list[tuple[str, int, bytes]]]:
    """What a Ray task of a batch runs: ``answer_chunk`` on a worker prepared once
    (``prepare.prepare_worker``, whose calls then run inline: never in another process), and
    the id of the Ray node that answered."""
    import ray

    prepare_worker()
    answers = answer_chunk(chunk, uploads, budget_s, max_body_bytes)
    return ray.get_runtime_context().get_node_id(), answers
