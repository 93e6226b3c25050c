"""The install compiles the search's local-optimization objective and its compiled Nelder-Mead
(``service.warmup``'s ``_search_objective`` step) in the one signature that the searches of
every arm then use, so that no first search spends its budget compiling them."""

from __future__ import annotations

import numpy as np

from tests.planners.generators.test_search_objective import CASES, random_points, search_objective
from toptraj.planners.generators.search import simplex_kernels
from toptraj.planners.generators.search.objective_kernels import objective_value
from toptraj.planners.generators.search.simplex import compiled_nelder_mead
from toptraj.service.warmup import install_steps, run_steps


def test_the_install_compiles_the_signature_every_search_evaluates():
    steps = [step for step in install_steps() if "search" in step[0]]
    assert len(steps) == 1
    run_steps(steps, lambda line: None)
    kernels = (objective_value, simplex_kernels.start, simplex_kernels.iterate)
    compiled = [list(kernel.signatures) for kernel in kernels]
    assert all(len(signatures) == 1 for signatures in compiled)
    rng = np.random.default_rng(1)
    for arm in CASES:  # two, six and seven joints; one obstacle or two; friction or none
        objective = search_objective(arm)
        x = random_points(objective, 4, 0.1, rng)
        objective.value(x)
        compiled_nelder_mead(objective, np.vstack([x, x + 0.01 * np.eye(len(x))]), len(x) + 3, 1e-4, 1e-6, True)
    assert [list(kernel.signatures) for kernel in kernels] == compiled  # nothing compiled anew
