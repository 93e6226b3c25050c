"""The install compiles the search's local-optimization objective and its compiled Nelder-Mead
(``service.warmup``'s ``_search_objective`` step) and its graph kernels (``_search_graph``) in
the one signature each that the searches of every arm then use, so that no first search spends
its budget compiling them."""

from __future__ import annotations

import numpy as np

from tests.planners.generators.test_search_objective import CASES, random_points, search_objective
from toptraj import robots
from toptraj.planners.collision import BoxObstacle, SphereObstacle
from toptraj.planners.constraints.admissible_kernels import interval_bounds, point_bounds
from toptraj.planners.generators.search import simplex_kernels
from toptraj.planners.generators.search.distance_kernels import capsule_ends, lower_distances, pair_minimum
from toptraj.planners.generators.search.graph import SearchOptions
from toptraj.planners.generators.search.objective_kernels import objective_value
from toptraj.planners.generators.search.problem import build_problem
from toptraj.planners.generators.search.simplex import compiled_nelder_mead
from toptraj.planners.generators.search.span_kernels import span_points
from toptraj.service.warmup import install_steps, run_steps

GRAPH_KERNELS = (capsule_ends, lower_distances, pair_minimum, span_points, interval_bounds, point_bounds)


def test_the_install_compiles_the_signature_every_search_evaluates():
    steps = [step for step in install_steps() if "objective" in step[0]]
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


def test_the_install_compiles_the_search_graphs_kernels_every_roadmap_calls():
    """After the graph step, roadmaps of panda around a box and of ur5 around a sphere (pieces
    refined near each) call every kernel of the build in a signature it holds."""
    steps = [step for step in install_steps() if "graph kernels" in step[0]]
    assert len(steps) == 1
    run_steps(steps, lambda line: None)
    compiled = [list(kernel.signatures) for kernel in GRAPH_KERNELS]
    # loaded from numba's cache, or from the install's library (the typical request's types);
    # other tests in this process may have added signatures of their own
    assert all(kernel.loaded() for kernel in GRAPH_KERNELS)
    kinds = ("velocity", "acceleration", "torque")
    panda = robots.load("panda")
    start, goal = np.array([-0.8, -0.3, 0.0, -2.0, 0.0, 1.8, 0.8]), np.array([0.8, -0.3, 0.0, -2.0, 0.0, 1.8, 0.8])
    box = BoxObstacle(np.array([0.4854, 0.0, 0.491]), np.array([0.1, 0.1, 0.1]))
    problem = build_problem(panda, panda.limits, kinds, start, goal, SearchOptions(roadmap_points=10, neighbors=4, lazy=False), True, (box,), 0.01)
    ur5 = robots.load("ur5")
    start, goal = np.array([-1.0, -1.2, 1.5, -1.9, -1.57, 0.0]), np.array([1.0, -1.2, 1.5, -1.9, -1.57, 0.0])
    sphere = SphereObstacle(np.array([0.626, 0.109, 0.29]), 0.08)
    other = build_problem(ur5, ur5.limits, kinds, start, goal, SearchOptions(roadmap_points=10, neighbors=4, lazy=False), True, (sphere,), 0.02)
    assert problem.removed > 0 and other.removed > 0  # pieces near the obstacles were refined
    assert [list(kernel.signatures) for kernel in GRAPH_KERNELS] == compiled  # nothing compiled anew
