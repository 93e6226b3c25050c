"""``global_search``: the search itself (``toptraj.planners.generators.search``), from a free
motion to its best grid paths, their statistics and, for planar arms among obstacles, the
obstacle shadows."""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass

import numpy as np

from toptraj.planners.collision import Obstacle
from toptraj.planners.errors import ShareSpent
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.planners.generators.search.branch_and_bound import branch_and_bound
from toptraj.planners.generators.search.graph import DEFAULT_OPTIONS, LATTICE_MAX_JOINTS, SearchOptions
from toptraj.planners.generators.search.outcome import NoGridPath, SearchResult, SearchStatistics
from toptraj.planners.generators.search.problem import SearchProblem, build_problem, toward_goal, with_spans_checked
from toptraj.planners.generators.search.report import LocalReport, SearchReport
from toptraj.planners.generators.search.shadows import obstacle_shadows
from toptraj.robots import JointLimits, Robot

#: A goal variant is searched only for grid paths faster than this multiple of the best grid
#: path of the variants searched before it (the local optimization takes a grid path down by
#: at most about a third: 1.51 -> 0.98 s and 2.23 -> 1.00 s on the Geering arm around a sphere).
VARIANT_CAP = 2.0
#: Share of the time left that the branch and bound of the goal variants may take together;
#: the rest is the local optimization's and the final timing's.
SEARCH_SHARE = 0.25
#: Searches of a lazy problem (``build_problem``) whose grid paths may meet obstacles unseen
#: before every span is checked at once: each search after one that timed a blocked span
#: starts over without it (Lazy PRM's loop), and where the obstacles block that many best
#: paths in turn, checking all spans costs less than more searches (ur5 and panda around a
#: box: 2 and 4 searches; the Geering arm's lattice, checked at once, would take 10).
LAZY_ATTEMPTS = 6


@dataclass(frozen=True)
class GlobalSearch:
    """A search's result, its region of joint space ((n_dof,) corners) and, for a planar arm
    among obstacles, its obstacle shadows (``toptraj.planners.generators.search.shadows``)."""

    result: SearchResult
    low: np.ndarray
    high: np.ndarray
    shadows: dict | None

    def report(self, chosen: int, local: tuple[LocalReport, ...], final_time: float) -> SearchReport:
        """The search's report, ``chosen`` the tube whose path is returned, with the tubes' local
        optimizations and the returned motion's duration (s)."""
        return SearchReport(
            self.result.statistics, self.result.tube_radius, self.result.tubes, chosen, self.low, self.high, self.shadows,
            local, final_time,
        )


def global_search(
    robot: Robot,
    limits: JointLimits,
    kinds: tuple[str, ...],
    start: np.ndarray,
    goal: np.ndarray,
    options: SearchOptions | None = None,
    revolutions: bool = True,
    obstacles: tuple[Obstacle, ...] = (),
    clearance: float = 0.01,
    deadline: Deadline = NO_DEADLINE,
) -> GlobalSearch:
    """The best grid paths from ``start`` to ``goal`` at rest: the problem built once
    (``build_problem``), then ``branch_and_bound`` toward each revolution variant of the goal
    in turn (grid paths that end one revolution apart are never in one tube, so each variant
    is a homotopy class with its own upper bound). The tubes are the best grid path of each
    variant, best first, then the next tubes of the variants by time, ``options.tubes`` in all.
    The variants are searched by their least time to go, and each after the first only for grid
    paths faster than ``VARIANT_CAP`` times the best found before it (the cap prunes its
    subsets from the start). With a budget, the variants' searches share ``SEARCH_SHARE`` of
    the time left, each stopping at its part with the grid paths it found: that is what ends
    a variant that no grid path reaches though the graph does (the cost to go allows loops), which
    would otherwise run until ``max_expansions``. A variant the graph does not reach is
    discarded at once: its cost to go is infinite from every start.

    On a lazy problem (a roadmap's, by default: ``build_problem``) the spans of every grid path
    the searches timed are then checked (``with_spans_checked``); where one is blocked, the
    searches run again without it (Bohlin & Kavraki's Lazy PRM loop), and after
    ``LAZY_ATTEMPTS`` searches every span left is checked before the last. The answer is that
    of a search whose timed grid paths all keep the clearance, on a graph that holds every
    span that does: the best grid path of the fully checked graph (the costs to go over the
    unchecked spans are lower bounds of it).

    The search's memory is admitted before it by the runner (``Search.estimate``, against
    ``options.memory_bytes``: ``toptraj.planners.runner.admission``).

    Raises:
        InvalidRequest, InfeasiblePath: see ``build_problem`` and ``branch_and_bound`` (the
            latter when no variant has a grid path).
        BudgetExceeded: ``deadline`` passed; ``ShareSpent``, the searches' share of it ended
            before they found a grid path toward some goal variant (more time may find one).
    """
    options = options or DEFAULT_OPTIONS
    if options.lazy is None:  # lazily on a roadmap
        roadmap = options.graph == "roadmap" or (options.graph == "auto" and robot.dof > LATTICE_MAX_JOINTS)
        options = dataclasses.replace(options, lazy=roadmap)
    problem = build_problem(
        robot, limits, kinds, start, goal, options, revolutions, obstacles, clearance, deadline.within(0.0, 0.4)
    )
    problem, result = _lazily_searched(problem, options, deadline)
    points = problem.graph.points
    low, high = points.min(axis=0), points.max(axis=0)
    shadows = obstacle_shadows(robot, list(obstacles), clearance, low, high) if obstacles else None
    return GlobalSearch(result, low, high, shadows)


def _lazily_searched(problem: SearchProblem, options: SearchOptions, deadline: Deadline) -> tuple[SearchProblem, SearchResult]:
    """The searches of ``global_search``, run again while their timed grid paths meet spans
    found blocked when checked (its docstring): the problem with the spans checked, and the
    merged result of the last searches, its counts and seconds those of all of them. Together
    they take ``SEARCH_SHARE`` of the time left."""
    remaining = deadline.remaining()
    share_ends = None if remaining is None else time.monotonic() + SEARCH_SHARE * remaining
    earlier: list[SearchStatistics] = []
    for attempt in range(LAZY_ATTEMPTS + 1):
        if attempt == LAZY_ATTEMPTS:  # the grid paths keep meeting obstacles: every span checked at once
            problem, _ = with_spans_checked(problem, np.flatnonzero(~problem.checked), deadline, states=False)
        results, failures = _searched(problem, options, deadline, share_ends)
        timed = np.concatenate([r.timed for r in results] + [np.asarray(f.timed, dtype=int) for f in failures])
        problem, blocked = with_spans_checked(problem, timed, deadline, states=False)  # toward_goal redoes them
        if not blocked:  # every grid path timed keeps the clearance: the answer of the checked graph
            break
        earlier += [r.statistics for r in results] + [f.statistics for f in failures]
    checked = int(problem.checked.sum())
    if not results:
        failures[0].statistics.spans_checked, failures[0].statistics.searches = checked, attempt + 1
        if any(getattr(failure, "stopped", "") == "time" for failure in failures):  # more time may find one: a 504
            expanded = sum(failure.statistics.expanded for failure in failures)
            raise ShareSpent(
                f"the search found no grid path within its share of the time budget ({expanded} partial paths expanded)",
                stage="search: branch and bound",
            ) from failures[0]
        raise failures[0]
    result = _merged(results, [f.statistics for f in failures], problem.prepare_s, options.tubes, earlier)
    result.statistics.spans_checked, result.statistics.searches = checked, attempt + 1
    return problem, result


def _searched(
    problem: SearchProblem, options: SearchOptions, deadline: Deadline, share_ends: float | None,
) -> tuple[list[SearchResult], list[NoGridPath]]:
    """``branch_and_bound`` toward each goal variant of ``problem`` (``global_search``), the
    variants sharing the time until ``share_ends`` (``time.monotonic()``; ``None``: no limit):
    the results, and the failures of the variants without a grid path."""
    # the variants by their least time to go (h2 from the start), the likeliest best first, so
    # that its t~ caps the searches of the others
    toward = [toward_goal(problem, index, deadline) for index in range(len(problem.graph.goals))]
    toward.sort(key=lambda one: float(np.min(one.h2[[state for _, state, _ in one.start_moves if state >= 0]], initial=np.inf)))
    results: list[SearchResult] = []
    failures: list[NoGridPath] = []
    left = None if share_ends is None else max(share_ends - time.monotonic(), 0.0)
    for index, variant in enumerate(toward):
        part = deadline.within(0.4 + 0.6 * index / len(toward), 0.4 + 0.6 * (index + 1) / len(toward))
        cap = VARIANT_CAP * min((r.tubes[0].time for r in results), default=np.inf)
        allowance = None if left is None else left / len(toward)
        try:
            results.append(branch_and_bound(variant, options, part, cap, allowance))
        except NoGridPath as error:
            failures.append(error)
    return results, failures


def _merged(
    results: list[SearchResult], failed: list[SearchStatistics], prepare_s: float, count: int,
    earlier: list[SearchStatistics] | None = None,
) -> SearchResult:
    """One result of the searches toward each goal variant (and the statistics of those that
    found no grid path): statistics summed (the upper bound is that of the best variant's
    search), tubes as ``global_search`` says; the counts and seconds of the ``earlier``
    searches of a lazy problem added."""
    firsts = sorted((r.tubes[0] for r in results), key=lambda tube: tube.time)
    rest = sorted((tube for r in results for tube in r.tubes[1:]), key=lambda tube: tube.time)
    tubes = tuple(sorted([*firsts, *rest][: max(1, count)], key=lambda tube: tube.time))
    candidates = tuple(sorted((c for r in results for c in r.candidates), key=lambda c: c.time))
    best = min(results, key=lambda r: r.tubes[0].time)
    last = [r.statistics for r in results] + failed
    every = last + (earlier or [])
    statistics = dataclasses.replace(
        best.statistics,
        expanded=sum(s.expanded for s in every),
        generated=sum(s.generated for s in every),
        pruned={key: sum(s.pruned[key] for s in every) for key in best.statistics.pruned},
        t4_evaluations=sum(s.t4_evaluations for s in every),
        candidates=len(candidates),
        best_grid_time=tubes[0].time,
        complete=all(s.complete for s in last),
        prepare_s=prepare_s,
        search_s=sum(s.search_s for s in every),
        goal_variants=len(last),
    )
    return SearchResult(tubes, candidates, statistics, best.tube_radius)
