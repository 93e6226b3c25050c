"""The global search of Jeong & Lee section 2 (after Shiller & Dubowsky 1991): the position space
tessellated into a graph (``graph``), the pieces of curve its paths are made of (``pieces``),
configuration-space obstacles removed from it (``free_space``), lower bounds on the motion time
along grid paths (``bounds``) on their B-spline curves (``curve``), and branch and bound over the grid paths (``branch_and_bound``),
whose best grid path of each tube is the start of the local optimization (section 2.6).

Jeong & Lee close by asking for "a simpler and computationally efficient algorithm", having
found the local optimization the long part. The search here keeps their algorithm and its
answers (the same subsets expanded in the same order, the same grid paths and times) and makes
its two inner loops compiled code: the branch and bound runs over a node table and an array
heap (``search_kernels``, ``node_table``) instead of Python objects, and the arm's distance to
the obstacles (forward kinematics of the link capsules, golden-section box distances) is one
compiled pass per configuration (``distance_kernels``). Measured on a shared 2-core machine
(``benchmarks/search_growth.py``, under similar load before and after): the Geering arm's 33 x 31
lattice, 530,648 subsets expanded, 47 s -> 4.4 s of branch and bound (about 8 us a subset);
ur5's roadmap of 150 points (32,869 pieces) built in 14.0 s -> 6.0 s, panda's (28,632) in
45 s -> 7.8 s, the bounds of the pieces (one RNEA pass per sample) now the larger part. What
remains long is what they found long: the local optimization, thousands of path-constrained
timings (``local``), which runs until it converges or its share of the budget is spent. Each
of them is now one compiled call too (``objective_kernels``: the spline from basis weights
computed once per round, then the rows, the sweeps and the distances of the reference
computation without its objects), equal to the reference to rounding, so the optimizer takes
the same steps: the Geering example's 12,501 evaluations from 0.5 ms to 0.18 ms each, and with
the search's kernels preloaded in the workers' fork server (``warm``), its request
(``benchmarks/search_speed.py``, alternating runs on the shared machine) from about 1,700 to
about 950 times one bare TOPP-RA solve.
"""

from toptraj.planners.generators.search.branch_and_bound import branch_and_bound, enumerate_grid_paths
from toptraj.planners.generators.search.curve import GridSplinePath
from toptraj.planners.generators.search.graph import SearchOptions
from toptraj.planners.generators.search.outcome import GridPath, SearchResult, SearchStatistics
from toptraj.planners.generators.search.problem import SearchProblem, build_problem

__all__ = [
    "GridPath",
    "GridSplinePath",
    "SearchOptions",
    "SearchProblem",
    "SearchResult",
    "SearchStatistics",
    "branch_and_bound",
    "build_problem",
    "enumerate_grid_paths",
]
