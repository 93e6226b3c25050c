"""The work a server does before it answers, step by step and said aloud: the catalog robots
built, and the compiled kernels (numba, ``cache=True``) compiled into numba's cache or loaded
from it.

Compiling the kernels takes a minute or more on two cores; loading them from the cache, a
second or two. So the install writes toptraj's bytecode (``write_bytecode``) and compiles them
(``python -m toptraj.service.warmup``: ``make install``, the Dockerfile's build), each server
process (and ``toptraj plan``) then only loads them (``server_steps``, from the app's
lifespan), and neither is silent meanwhile: a line when a step begins, one every ``HEARTBEAT_S``
while it lasts, and one when it ends with its seconds and how many kernels it compiled (0 when
the cache held them all).

The solver stacks that only some methods use (cvxpy, casadi, toppra, scipy's optimizers) are
not imported here: each method imports its own when it first runs (in the fork server's
children for cvxpy and casadi, ``toptraj.planners.execution.isolated.PRELOAD``).

    python -m toptraj.service.warmup     # what the install runs: every step, a line per step
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager

#: Seconds between two lines while a step lasts.
HEARTBEAT_S = 3.0
#: The typical request (``benchmarks/end_to_end.py``): ur5, 4 spline waypoints, velocity,
#: acceleration and torque limits, ``phase_plane``, samples every 10 ms.
TYPICAL = {
    "robot": "ur5",
    "path": {
        "kind": "waypoints",
        "waypoints": [
            [0.0, -1.2, 1.0, 0.0, 0.0, 0.0],
            [0.8, -1.0, 1.4, -0.5, 0.6, 0.3],
            [1.5, -0.5, 0.8, -1.0, 1.0, 0.8],
            [2.0, -1.3, 1.2, 0.2, 0.4, 1.2],
        ],
        "interpolation": "spline",
    },
    "timing": {"method": "phase_plane", "constraints": ["velocity", "acceleration", "torque"]},
    "output": {"dt": 0.01},
}

Report = Callable[[str], None]
#: A label and its work; the work may return what its done-line says instead of the count of
#: numba's compilations.
Step = tuple[str, Callable[[], "str | None"]]

_imported = threading.Event()


def say_while_importing(report: Report) -> None:
    """``report`` that this process imports the service now, and again every ``HEARTBEAT_S``
    until ``imports_done``: the seconds a server process spends importing before its app exists
    (its event loop factory calls this, before uvicorn imports the app; ``toptraj serve`` with
    one process, where uvicorn imports it before it makes the loop). Nothing once imported."""
    if _imported.is_set():
        return
    started = time.monotonic()
    report("importing the service (the planners, the web framework) ...")

    def beat() -> None:
        while not _imported.wait(HEARTBEAT_S):
            report(f"still importing the service: {time.monotonic() - started:.0f} s")

    threading.Thread(target=beat, name="toptraj-import-heartbeat", daemon=True).start()


def imports_done() -> None:
    """The service is imported (its app is being made): ``say_while_importing`` stops."""
    _imported.set()


def _catalog_robots() -> None:
    from toptraj import robots

    for name in robots.catalog_names():
        robots.load(name)


def _phase_plane() -> None:
    import numpy as np

    from toptraj import robots
    from toptraj.planners import METHODS, LimitRequest, WaypointPath, build_problem, plan

    arm = robots.load("yamamoto_2r")
    path = WaypointPath(np.array([[0.0, 0.0], [0.1, 0.0]]))
    plan(build_problem(arm, path, METHODS["phase_plane"], limits=LimitRequest(kinds=("torque",))))


def _conditioning() -> None:
    """Conditioning's kernel (its Gram matrices), on a singular Jacobian, which the singular values then decide."""
    import numpy as np

    from toptraj.planners.kinematics.conditioning import frobenius_condition_number

    frobenius_condition_number(np.zeros((6, 6)))


def _typical() -> None:
    from toptraj.service.planning import plan_request, render
    from toptraj.service.schemas.trajectories import TrajectoryRequest

    request = TrajectoryRequest.model_validate(TYPICAL)
    render(plan_request(request), request)


def _search_objective() -> None:
    """The search's local-optimization objective (``toptraj.planners.generators.search.objective_kernels``)
    and its compiled Nelder-Mead (``simplex_kernels``): one evaluation and a few steps on the
    Geering arm around a sphere, in the signature every search's takes (compiling them takes
    about a minute on a busy two-core machine, which a first search would otherwise spend of its
    budget)."""
    import numpy as np

    from toptraj import robots
    from toptraj.planners.collision import SphereObstacle
    from toptraj.planners.execution.deadline import NO_DEADLINE
    from toptraj.planners.generators.search.local_objective import Objective
    from toptraj.planners.generators.search.local_outcome import LocalSettings
    from toptraj.planners.generators.search.simplex import compiled_nelder_mead

    arm = robots.load("geering_2r")
    sphere = SphereObstacle(np.array([0.52, 0.28, 0.0]), 0.05)
    objective = Objective(arm, arm.limits, ("torque",), np.zeros(2), np.array([0.76, 0.0]), (sphere,), 0.01, LocalSettings(), NO_DEADLINE)
    x = np.array([0.25, 0.0, 0.5, 0.0])
    objective.value(x)
    compiled_nelder_mead(objective, np.vstack([x, x + 0.02 * np.eye(4)]), 12, 1e-4, 1e-6, False)


def _ahead_of_time() -> str | None:
    """The typical request's kernels compiled ahead of time into one library
    (``toptraj.compiled.build``): ``toptraj plan`` of such a request then runs without importing
    numba. A machine without a C compiler keeps numba's cache alone, and says so."""
    from toptraj.compiled.build import BuildFailed, build

    try:
        exported = build(_typical)
    except BuildFailed as failure:
        return f"not built, the kernels run from numba's cache: {failure}"
    return f"compiled {exported} functions into the library"


def _search_graph() -> None:
    """The search's graph kernels (``toptraj.planners.generators.search``: the arm's capsules,
    the box and self-collision distances, the samples along the spans, the pieces' bounds):
    a small roadmap of ur5 around a box where the tool passes halfway, whose pieces near the box
    are refined (compiling them takes tens of seconds on a busy two-core machine, which a first
    search of a six- or seven-joint arm would otherwise spend of its budget)."""
    import numpy as np

    from toptraj import robots
    from toptraj.planners.collision import BoxObstacle
    from toptraj.planners.generators.search.graph import SearchOptions
    from toptraj.planners.generators.search.problem import build_problem

    arm = robots.load("ur5")
    start, goal = np.array([-1.0, -1.2, 1.5, -1.9, -1.57, 0.0]), np.array([1.0, -1.2, 1.5, -1.9, -1.57, 0.0])
    box = BoxObstacle(np.array([0.626, 0.109, 0.29]), np.array([0.15, 0.15, 0.15]))
    options = SearchOptions(graph="roadmap", roadmap_points=8, neighbors=3, lazy=False)  # every span checked, refinement too
    build_problem(arm, arm.limits, ("velocity", "acceleration", "torque"), start, goal, options, True, (box,), 0.02)


def server_steps() -> list[Step]:
    """What each server process does before it answers (kernels loaded from the cache)."""
    return [
        ("building the catalog robots", _catalog_robots),
        ("compiling or loading the phase-plane kernels", _phase_plane),
        ("compiling or loading the conditioning kernel", _conditioning),
    ]


def write_bytecode() -> None:
    """The bytecode of every module of toptraj written beside its source (``__pycache__``, or
    under ``PYTHONPYCACHEPREFIX``), as pip writes it when it installs a package: each start then
    reads it instead of compiling the sources again, even where the environment forbids Python
    to write it as it imports (``PYTHONDONTWRITEBYTECODE``, set in the Dockerfile). Up-to-date
    files are left as they are; a folder that cannot be written is left without."""
    import compileall
    from pathlib import Path

    import toptraj

    package = Path(toptraj.__file__).parent
    compileall.compile_dir(package, maxlevels=0, quiet=2)
    # The sub-packages one by one: in a checkout they are links, which compile_dir does not enter.
    for folder in sorted(path for path in package.iterdir() if path.is_dir() and not path.name.startswith("__")):
        compileall.compile_dir(folder, quiet=2)


def install_steps() -> list[Step]:
    """What the install does: toptraj's bytecode written, the server's steps, then the kernels
    of the typical request (velocity and acceleration rows, sampling, dense checks), the
    search's objective and its graph kernels, compiled into the cache."""
    return [
        ("writing the bytecode of toptraj's modules", write_bytecode),
        *server_steps(),
        ("compiling the typical request's kernels (ur5, spline, velocity, acceleration, torque)", _typical),
        ("compiling them ahead of time into one library (toptraj plan then starts without numba)", _ahead_of_time),
        ("compiling the search's local-optimization objective", _search_objective),
        ("compiling the search's graph kernels (ur5 around a box: distances, span samples, bounds)", _search_graph),
    ]


@contextmanager
def _compilations() -> Iterator[list]:
    """The numba compilations (not cache loads) that happen inside the block, as events."""
    from numba.core import event

    with event.install_recorder("numba:compile") as recorder:
        yield recorder.buffer


def _compiled(events: list) -> int:
    """Kernels compiled among numba's compile ``events`` (a start and an end each)."""
    return sum(1 for _, item in list(events) if item.is_end)


@contextmanager
def _heartbeat(label: str, events: list, report: Report) -> Iterator[None]:
    """``report`` a line every ``HEARTBEAT_S`` while the block runs, with the kernels compiled
    so far (``events``: numba's compile events)."""
    done = threading.Event()
    started = time.monotonic()

    def beat() -> None:
        while not done.wait(HEARTBEAT_S):
            report(f"still {label}: {time.monotonic() - started:.0f} s, {_compiled(events)} functions compiled so far "
                   "(a minute or more the first time; seconds once numba's cache holds them)")

    thread = threading.Thread(target=beat, name="toptraj-warm-up-heartbeat", daemon=True)
    thread.start()
    try:
        yield
    finally:
        done.set()
        thread.join()


def run_steps(steps: list[Step], report: Report) -> int:
    """Run ``steps`` in order, ``report``-ing each (module docstring); the number of kernels
    compiled (0: every kernel came from the cache)."""
    compiled = 0
    for label, step in steps:
        report(f"{label} ...")
        started = time.monotonic()
        with _compilations() as events, _heartbeat(label, events, report):
            note = step()
        count = _compiled(events)
        compiled += count
        source = f"compiled {count} functions" if count else "nothing to compile"
        source = note or source
        report(f"{label}: done in {time.monotonic() - started:.1f} s ({source})")
    return compiled


def main() -> int:
    """``python -m toptraj.service.warmup``: every install step, a line each on standard output."""

    def report(line: str) -> None:
        print(f"toptraj warm-up: {line}", flush=True)

    started = time.monotonic()
    compiled = run_steps(install_steps(), report)
    report(f"ready in {time.monotonic() - started:.1f} s ({compiled} functions compiled into numba's cache)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
