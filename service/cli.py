"""The ``toptraj`` command: ``toptraj serve [--host H] [--port P]`` and
``toptraj plan request.json`` (prints the response JSON)."""

from __future__ import annotations

import argparse
import json
import sys

from pydantic import ValidationError


def _serve(args) -> int:
    import uvicorn

    from service.app import create_app

    uvicorn.run(create_app(), host=args.host, port=args.port)
    return 0


def _plan(args) -> int:
    from robots import ToptrajError
    from service.planning import encode_json, plan_request, trajectory_body
    from service.schemas.trajectories import TrajectoryRequest

    try:
        with open(args.request) as handle:
            request = TrajectoryRequest.model_validate_json(handle.read())
        body = trajectory_body(plan_request(request))
    except OSError as error:
        print(json.dumps({"title": "Cannot read request", "status": 400, "detail": str(error)}))
        return 2
    except ValidationError as error:
        detail = "; ".join(f"{'.'.join(map(str, e['loc']))}: {e['msg']}" for e in error.errors())
        print(json.dumps({"title": "Invalid request", "status": 422, "detail": detail}))
        return 1
    except ToptrajError as error:
        print(json.dumps({"title": error.title, "status": error.status, "detail": error.detail}))
        return 1
    sys.stdout.write(encode_json(body).decode() + "\n")
    return 0


def main(argv: list[str] | None = None) -> int:
    """Entry point of the console script."""
    parser = argparse.ArgumentParser(prog="toptraj", description=__doc__)
    commands = parser.add_subparsers(dest="command", required=True)
    serve = commands.add_parser("serve", help="run the HTTP service")
    serve.add_argument("--host", default="127.0.0.1")
    serve.add_argument("--port", type=int, default=8000)
    serve.set_defaults(run=_serve)
    plan = commands.add_parser("plan", help="plan one request from a JSON file and print the response")
    plan.add_argument("request", help="path of a JSON file shaped like POST /v1/trajectories' body")
    plan.set_defaults(run=_plan)
    args = parser.parse_args(argv)
    return args.run(args)


if __name__ == "__main__":
    sys.exit(main())
