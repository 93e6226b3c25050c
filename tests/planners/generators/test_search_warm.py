"""The fork server of the isolated workers preloads the search's warm-up
(``toptraj.planners.generators.search.warm``), which leaves the local optimization's compiled
objective loaded in its process in the signature the searches of every arm call, so that no
search's worker loads it from numba's cache again."""

from __future__ import annotations

import importlib

import numpy as np

from tests.planners.generators.test_search_objective import CASES, random_points, search_objective
from toptraj.planners.execution.isolated import PRELOAD
from toptraj.planners.generators.search.objective_kernels import objective_value


def test_the_fork_server_preloads_the_search_and_its_objective():
    assert "toptraj.planners.generators.search.warm" in PRELOAD
    importlib.import_module("toptraj.planners.generators.search.warm")
    loaded = list(objective_value.signatures)
    assert len(loaded) == 1
    rng = np.random.default_rng(4)
    for arm in CASES:
        objective = search_objective(arm)
        objective.value(random_points(objective, 5, 0.1, rng))
    assert list(objective_value.signatures) == loaded
