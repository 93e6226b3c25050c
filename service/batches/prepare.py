"""A batch's Ray worker made ready once, before its first line: Ray's
``worker_process_setup_hook`` (``RayPool`` sets it in the job's ``runtime_env``), and again at the
first task of a worker started without it (a Ray the caller initialized), never per line.

What a worker does once:

* its calls that would run in a child process (``min_cost``'s convex program, the collocation,
  the search) run inline (``isolated.run_inline_here``): the driver kills a task that runs past
  its lines' budgets, as a job's worker is killed. In a Ray worker, a child per call cost a fork
  server of its own (importing the solver stacks) and a fork per call: 1.6 to 10 s per
  ``min_cost`` line on a busy 2-core machine, against 0.8 s inline;
* one BLAS thread (``threads.single_blas_thread``): a worker per core already uses them all;
* the server's warm-up steps (``toptraj.service.warmup``: catalog robots, kernels loaded from
  numba's cache, the typical request), then the solver stacks every method imports on its first
  run (cvxpy, casadi, toppra, ruckig, scipy's optimizers): 3 to 5 s a worker, instead of up to
  5 s on the first line of each method; not the search's warm-up (a search of its own, paid by
  the first line that searches, not by every worker of every batch).

A step that fails is logged and skipped: its line then pays for it, or answers its own error.
"""

from __future__ import annotations

import importlib
import logging

from toptraj.planners.execution.isolated import PRELOAD, run_inline_here
from toptraj.planners.execution.threads import single_blas_thread

logger = logging.getLogger("toptraj.batches")

#: Modules of ``isolated.PRELOAD`` that compute when imported (a warm-up, not a stack): the
#: search's (``search.warm``, two small searches and a local optimization, about 1.5 s) and the
#: runner's (``runner.warm``, a ur5 path timed) are left to a worker's first line, which loads
#: the same kernels as it runs (a batch worker's calls run inline: it has no fork server to warm).
WARM_UPS = ("toptraj.planners.generators.search.warm", "toptraj.planners.runner.warm")
#: Modules a worker imports once: the fork server's (``isolated.PRELOAD``) but its warm-ups
#: (``WARM_UPS``), and the stacks of the methods that import theirs on their first run.
STACKS = [
    *(name for name in PRELOAD if name not in WARM_UPS),
    "toptraj.planners.timing.toppra_method",
    "toppra.algorithm",
    "toppra.constraint",
    "ruckig",
]
#: The hook, as Ray's ``runtime_env`` names it.
SETUP_HOOK = "toptraj.service.batches.prepare.prepare_worker"

_times = 0


def times_prepared() -> int:
    """How many times this process was prepared (1 in a worker that answered a line)."""
    return _times


def _stacks() -> None:
    for name in STACKS:
        importlib.import_module(name)


def prepare_worker() -> None:
    """Make this process a prepared batch worker (module docstring); nothing once it is."""
    global _times
    if _times:
        return
    _times += 1
    from toptraj.service import warmup

    run_inline_here()
    steps = [*warmup.install_steps(), ("importing the solver stacks", _stacks)]
    for label, step in steps:
        try:
            warmup.run_steps([(label, step)], logger.info)
        except Exception as error:  # the line that needs it answers its own error
            logger.warning("preparing a batch worker: %s failed (%s)", label, error)
    single_blas_thread()  # last: it limits the libraries loaded so far
