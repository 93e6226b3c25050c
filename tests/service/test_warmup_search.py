"""The install compiles the search's local-optimization objective (``service.warmup``'s
``_search_objective`` step) in the one signature that the searches of every arm then use, so
that no first search spends its budget compiling it."""

from __future__ import annotations

import numpy as np

from tests.planners.generators.test_search_objective import CASES, random_points, search_objective
from toptraj.planners.generators.search.objective_kernels import objective_value
from toptraj.service.warmup import install_steps, run_steps


def test_the_install_compiles_the_signature_every_search_evaluates():
    steps = [step for step in install_steps() if "search" in step[0]]
    assert len(steps) == 1
    run_steps(steps, lambda line: None)
    compiled = list(objective_value.signatures)
    assert len(compiled) == 1
    rng = np.random.default_rng(1)
    for arm in CASES:  # two, six and seven joints; one obstacle or two; friction or none
        objective = search_objective(arm)
        objective.value(random_points(objective, 4, 0.1, rng))
    assert list(objective_value.signatures) == compiled  # nothing compiled anew
