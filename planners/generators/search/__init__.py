"""The global search of Jeong & Lee section 2 (after Shiller & Dubowsky 1991): the position space
tessellated into a graph (``graph``), the pieces of curve its paths are made of (``pieces``),
configuration-space obstacles removed from it (``free_space``), lower bounds on the motion time
along grid paths (``bounds``) on their B-spline curves (``curve``), and branch and bound over the grid paths (``branch_and_bound``),
whose best grid path of each tube is the start of the local optimization (section 2.6)."""

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
