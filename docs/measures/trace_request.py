"""One request's way through the modules: ``toptraj.service.planning.plan_request`` traced with
``sys.setprofile`` (after a first, untraced run that compiles the kernels and loads the robot).

Run from the repository root with the project's environment:
``PYTHONPATH=$PWD python docs/measures/trace_request.py REQUEST.json [budget_s]``.
"""

from __future__ import annotations

import collections
import json
import sys

from toptraj.planners.execution.deadline import Deadline
from toptraj.service.planning import plan_request
from toptraj.service.schemas.trajectories import TrajectoryRequest

ROOTS = ("compiled", "robots", "planners", "service", "client")


def _module(frame) -> str | None:
    name = frame.f_globals.get("__name__", "").removeprefix("toptraj.")
    return name if name.split(".")[0] in ROOTS else None


def main(file: str, budget_s: float) -> None:
    with open(file) as stream:
        request = TrajectoryRequest.model_validate(json.load(stream))
    plan_request(request, Deadline(budget_s))
    entered: collections.Counter[str] = collections.Counter()
    edges: collections.Counter[tuple[str, str]] = collections.Counter()
    deepest: list[str] = []

    def profile(frame, event, arg) -> None:
        nonlocal deepest
        callee = _module(frame) if event == "call" else None
        if callee is None:
            return
        chain, caller = [callee], frame.f_back
        while caller is not None:
            module = _module(caller)
            if module is not None and chain[-1] != module:
                chain.append(module)
            caller = caller.f_back
        entered[callee] += 1
        if len(chain) > 1:
            edges[(chain[1], callee)] += 1
        if len(chain) > len(deepest):
            deepest = chain

    sys.setprofile(profile)
    plan_request(request, Deadline(budget_s))
    sys.setprofile(None)
    print(f"modules entered: {len(entered)}; distinct calls between modules: {len(edges)}")
    print(f"deepest chain ({len(deepest)} modules): {' > '.join(reversed(deepest))}")
    print("modules:", ", ".join(sorted(entered)))


if __name__ == "__main__":
    main(sys.argv[1], float(sys.argv[2]) if len(sys.argv) > 2 else 60.0)
