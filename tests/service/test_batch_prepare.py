"""A batch's Ray worker is prepared with the solver stacks, not the fork server's warm-ups: the
search's runs two small searches (about 1.5 s) that a batch of other methods never needs, and
each line loads the kernels it runs anyway."""

from __future__ import annotations

import subprocess
import sys

from tests.paths import ROOT
from toptraj.service.batches.prepare import STACKS, WARM_UPS

SEARCH_WARM = "toptraj.planners.generators.search.warm"
RUNNER_WARM = "toptraj.planners.runner.warm"


def test_the_stacks_leave_out_the_warm_ups():
    assert {SEARCH_WARM, RUNNER_WARM} <= set(WARM_UPS) and not {SEARCH_WARM, RUNNER_WARM} & set(STACKS)


def test_importing_the_stacks_runs_no_search():
    """The project's modules of ``STACKS``, imported in a fresh process, bring no search warm-up in."""
    names = [name for name in STACKS if name.startswith("toptraj.")]
    code = f"import importlib, sys\nfor name in {names!r}:\n    importlib.import_module(name)\nprint({SEARCH_WARM!r} in sys.modules, {RUNNER_WARM!r} in sys.modules)"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=300, check=True)
    assert done.stdout.strip() == "False False"
