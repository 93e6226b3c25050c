"""Timing a free motion, whose path the planner finds: the collocation's path re-timed along
itself (with the exact bang-bang refinement of its switching times), and the global search
among obstacles with its local optimization (Jeong & Lee sections 2 and 4).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from toptraj.planners.checks.gate import TimedStretch, checked, gated
from toptraj.planners.collision import check_clearance
from toptraj.planners.collision.self_collision import check_self_collision
from toptraj.planners.constraints.path_constraints import build_path_constraints
from toptraj.planners.errors import InfeasiblePath, InvalidRequest, OverMemory
from toptraj.planners.execution.deadline import Deadline
from toptraj.planners.execution.isolated import LOW_PRIORITY, run_isolated
from toptraj.planners.generators.collocation import FreeMotion, collocation_path, optimize_motion
from toptraj.planners.generators.collocation.switching import refine_collocation, switched_path, switching_times
from toptraj.planners.generators.search.curve import GridSplinePath
from toptraj.planners.generators.search.graph import DEFAULT_OPTIONS
from toptraj.planners.generators.search.local import optimize_locally
from toptraj.planners.generators.search.local_outcome import LocalOptimum
from toptraj.planners.generators.search.memory import check_search_memory
from toptraj.planners.generators.search.method import global_search
from toptraj.planners.paths import GeometricPath
from toptraj.planners.paths.grid import path_grid
from toptraj.planners.problem.requests import Timing
from toptraj.planners.runner.given_path import Timed, moving_velocity, path_boundary, timed_path, timing_grid
from toptraj.planners.timing.base import GAP_TARGET
from toptraj.planners.timing.min_cost import MinCostMethod
from toptraj.planners.timing.phase_plane.method import PhasePlaneMethod

#: Most collocation intervals a request may ask for (timing.grid_points).
MAX_INTERVALS = 100
#: A search's worker process may grow its address space by this multiple of its memory
#: estimate, plus ``SEARCH_MEMORY_SLACK`` (the solver stacks' arenas and libraries' own
#: mappings): beyond, ``MemoryError`` there, answered as ``OverMemory``.
SEARCH_MEMORY_ROOM = 2
SEARCH_MEMORY_SLACK = 2**30


def _free_motion(robot, path_spec, method, timing: Timing, limits, deadline):
    """Path and timing optimized together (``path.kind = "free"`` with ``collocation``)."""
    if not isinstance(path_spec, FreeMotion) or method.name != "collocation":
        raise InvalidRequest(
            "a free path (start and goal only) needs timing.method 'collocation' or 'search', and collocation a free path"
        )
    if timing.grid_points is not None and not 4 <= timing.grid_points <= MAX_INTERVALS:
        raise InvalidRequest(f"timing.grid_points sets the collocation intervals, 4 to {MAX_INTERVALS}; got {timing.grid_points}")
    if timing.grid_points is not None:
        path_spec = dataclasses.replace(path_spec, intervals=timing.grid_points)
    unlimited = np.full(robot.dof, np.inf)
    limits = dataclasses.replace(
        limits,
        velocity=limits.velocity if "velocity" in timing.constraints else unlimited,
        acceleration=limits.acceleration if "acceleration" in timing.constraints else unlimited,
    )
    result = optimize_motion(robot, limits, path_spec, timing.torque_weight, deadline)
    path, timed = collocation_path(result)
    return path, _solver_report(result), timed, result


def _solver_report(result) -> dict:
    """The collocation's figures for the answer's ``solver``."""
    return {
        "cost": result.cost,
        "duration": float(result.t[-1]),
        "status": result.status,
        "iterations": result.iterations,
        "initial_guess": result.initial_guess,
        "solve_s": result.solve_s,
    }


def timed_free_motion(robot, spec, method, timing, kinds, limits, deadline, threshold) -> Timed:
    """A free motion: the collocation's path, re-timed exactly along itself (phase_plane, or
    min_cost for beta > 0) so that every limit holds between the collocation instants too."""
    path, solver, collocation_timing, collocation = _free_motion(robot, spec, method, timing, limits, deadline.within(0.0, 0.8))
    retiming = deadline.within(0.8, 0.9, "re-timing along the collocation's path")
    retiming.progress(0.0, "constraints")
    retimer = PhasePlaneMethod() if timing.torque_weight == 0.0 else MinCostMethod(timing.torque_weight)
    constraints = build_path_constraints(path, robot, limits, kinds, timing_grid(path, None, retimer, robot), deadline)
    moving = dataclasses.replace(
        timing, start_velocity=moving_velocity(spec.start_velocity), end_velocity=moving_velocity(spec.end_velocity), duration=None
    )
    notes: tuple[str, ...] = ()
    try:
        result, constraints, check = gated(
            robot, path, retimer, constraints, path_boundary(path, moving, retimer), None, kinds, limits, threshold,
            retiming.within(0.1, 1.0),
        )
        stretch = TimedStretch(path, result, constraints, check)
    except InfeasiblePath as error:
        # A boundary state right at a limit may be out of reach of the conservative re-timing;
        # the collocation's own timing is then returned, if it holds the limits.
        result = collocation_timing
        stretch = checked(robot, path, result, "collocation", kinds, limits, threshold, constraints)
        notes = (f"the collocation's own timing is returned (re-timing along its path failed: {error.detail})",)
    switching = None
    source = collocation
    if timing.torque_weight == 0.0:
        deadline.progress(0.9, "refining the switching times")
        path, result, stretch, switching, notes, winner, source = _switched(
            robot, spec, collocation, (path, result, stretch), kinds, limits, threshold, notes, deadline
        )
        solver = {**solver, **_solver_report(winner), "switching": "refined" if switching is not None else "read off the samples"}
    solver = {**solver, "optimality_gap": source.optimality_gap, "gap_basis": source.gap_basis}
    if timing.torque_weight == 0.0 and source.optimality_gap is not None and source.optimality_gap > GAP_TARGET:
        advice = (
            f": more timing.grid_points (collocation intervals, up to {MAX_INTERVALS}) bring it closer"
            if len(collocation.t) - 1 < MAX_INTERVALS else ""
        )
        notes = (
            *notes,
            f"the duration may lie up to {100 * source.optimality_gap:.2g} % above the optimum ({source.gap_basis}){advice}",
        )
    cost = getattr(result, "cost", None) if timing.torque_weight else result.duration
    return Timed(
        path, result, (stretch,), "collocation", notes, cost, solver, switching_times=switching,
        motion_gap=(source.optimality_gap, source.gap_basis),
    )


def _switched(robot, spec, collocation, timed, kinds, limits, threshold, notes, deadline):
    """The time-optimal free motion with exact bang-bang torques (``toptraj.planners.generators.collocation.switching``)
    in place of ``timed`` (path, timing, stretch) when it reaches the goal, is not longer and
    passes the limit gate; with its switching times (else ``None``). The collocation's rivals
    (``CollocationResult.rivals``) are refined too and the shortest refined motion wins; the
    collocation result it came from is returned, and the result whose ``optimality_gap`` the
    answer states (the refined motion, or else the collocation)."""
    path, result, stretch = timed
    refined, winner = None, collocation
    # The rivals (other goals the fine grid found close) are compared on exact terms too: the
    # collocation's grid error can exceed their difference.
    for candidate in (collocation, *collocation.rivals):
        motion = refine_collocation(robot, limits, spec, candidate, deadline)
        if motion is not None and (refined is None or motion.duration < refined.duration):
            refined, winner = motion, candidate
    if refined is None or (winner is collocation and refined.duration > result.duration):
        return path, result, stretch, None, notes, collocation, collocation
    switched, timing = switched_path(refined)
    constraints = build_path_constraints(switched, robot, limits, kinds, path_grid(switched), deadline)
    try:
        stretch = checked(robot, switched, timing, "collocation", kinds, limits, threshold, constraints)
    except InfeasiblePath as error:
        return path, result, stretch, None, (*notes, f"the bang-bang refinement is not returned: {error.detail}"), collocation, collocation
    return switched, timing, stretch, switching_times(refined.controls, robot.joint_names), notes, winner, refined


def timed_search(robot, spec, timing, kinds, limits, deadline, threshold, obstacles, clearance) -> Timed:
    """The global search (``toptraj.planners.generators.search``, Jeong & Lee section 2): the best grid path of
    each tube, then each one's local optimization (section 2.6) within its share of the budget;
    the fastest optimized path that keeps the clearance is timed by phase_plane through the
    limit gate. The grid path's own curve stands in where its optimization finds nothing.

    The search's memory is estimated from its settings first (``toptraj.planners.generators.search.memory``,
    ``OverMemory`` beyond ``timing.search.memory_bytes``). Under a deadline the whole search
    runs in a worker process (``toptraj.planners.execution.isolated``) at a lower CPU priority
    (``toptraj.planners.execution.isolated.LOW_PRIORITY``), its address space capped at ``SEARCH_MEMORY_ROOM`` times the estimate:
    killed when the budget is spent or the caller cancels, its memory gone with it."""
    if not isinstance(spec, FreeMotion):
        raise InvalidRequest("timing.method 'search' finds the path itself: give a free path (path.kind 'free', start and goal)")
    if moving_velocity(spec.start_velocity) is not None or moving_velocity(spec.end_velocity) is not None or timing.duration is not None:
        raise InvalidRequest("the search plans the fastest motion from rest to rest: leave timing.boundary and timing.duration out")
    options = timing.search or DEFAULT_OPTIONS
    if robot.outside_position_limits(spec.start) is None and robot.outside_position_limits(spec.goal) is None:
        need = check_search_memory(robot, spec.start, spec.goal, options, spec.revolutions)
    else:  # refused by the search itself, with the joint named
        need = 0
    try:
        return run_isolated(
            _searched, robot, spec, timing, kinds, limits, deadline.end, deadline.budget_s, threshold, obstacles, clearance,
            deadline=deadline, progress=True, memory_bytes=SEARCH_MEMORY_ROOM * need + SEARCH_MEMORY_SLACK, nice=LOW_PRIORITY,
        )
    except OverMemory as error:
        raise OverMemory(
            f"the search needed more memory than its estimate of {need / 2**30:.3g} GiB allowed ({error.detail}): "
            "lower timing.search.roadmap_points or neighbors (cells on a lattice)"
        ) from None


def _searched(robot, spec, timing, kinds, limits, end, budget_s, threshold, obstacles, clearance, progress) -> Timed:
    """``timed_search``'s work, in its worker process under the caller's deadline (ending at
    ``end``, ``time.monotonic()``), reporting to ``progress``."""
    deadline = Deadline.ending_at(end, budget_s, progress)
    timed = _search(robot, spec, timing, kinds, limits, deadline, threshold, obstacles, clearance)
    # the constraints' re-evaluation holds this process's deadline: it does not travel back
    stretches = tuple(item._replace(constraints=dataclasses.replace(item.constraints, evaluate=None)) for item in timed.stretches)
    return timed._replace(stretches=stretches)


def _search(robot, spec, timing, kinds, limits, deadline, threshold, obstacles, clearance) -> Timed:
    """``timed_search``'s work under ``deadline``."""
    found = global_search(
        robot, limits, kinds, spec.start, spec.goal, timing.search, spec.revolutions, obstacles, clearance, deadline.within(0.0, 0.3)
    )
    tubes = found.result.tubes
    optimized, failures = [], []
    for index, tube in enumerate(tubes):
        remaining = deadline.remaining()
        # the rounds share what is left, three quarters of it (the rest: timing, gate, sampling)
        allowance = None if remaining is None else 0.75 * remaining / (len(tubes) - index)
        part = deadline.within(0.3 + 0.6 * index / len(tubes), 0.3 + 0.6 * (index + 1) / len(tubes))
        part.progress(0.0, f"local optimization of tube {index + 1} of {len(tubes)}")
        try:
            local = optimize_locally(robot, tube.points, limits, kinds, obstacles, clearance, part, allowance_s=allowance)
        except InfeasiblePath as error:
            failures.append(f"tube {index + 1}: {error.detail}")
            continue
        optimized.append((local.duration, index, local))
    plain = dataclasses.replace(timing, method="phase_plane", search=None, start_velocity=None, end_velocity=None)
    candidates: list[tuple[GeometricPath, int, LocalOptimum | None]] = [
        (item.path, index, item) for _, index, item in sorted(optimized, key=lambda item: item[:2])
    ]
    candidates += [(GridSplinePath(tube.points), index, None) for index, tube in enumerate(tubes)]
    for path, index, optimum in candidates:
        try:
            if obstacles:
                check_clearance(path, robot, list(obstacles), clearance, deadline)
            check_self_collision(path, robot, deadline=deadline)
            timed = timed_path(robot, path, PhasePlaneMethod(), plain, kinds, limits, deadline.within(0.9, 1.0), threshold)
        except InfeasiblePath as error:
            failures.append(f"tube {index + 1}{' (optimized)' if optimum is not None else ''}: {error.detail}")
            continue
        end = path.evaluate(np.array([1.0])).q[0]
        turns = [
            f"joint {robot.joint_names[j]!r} ends at {end[j]:.6g} rad, the goal's angle {turn:+.0f} revolution"
            for j in range(robot.dof)
            if (turn := round((end[j] - spec.goal[j]) / (2.0 * np.pi))) != 0
        ]
        notes = [*timed.notes, *turns]
        if optimum is None:
            notes.append("the local optimization found no better path: the best grid path's own curve is returned")
        elif optimum.statistics.stopped == "allowance spent":
            notes.append(
                "the local optimization stopped when its share of the time budget was spent: a job with a larger "
                "budget_s may find a faster path"
            )
        report = found.as_dict(index)
        report["local"] = [_local_report(tubes[i].time, item) for _, i, item in sorted(optimized, key=lambda item: item[1])]
        report["final_time"] = timed.timing.duration
        return timed._replace(method="search", notes=tuple(notes), search=report)
    raise InfeasiblePath("no path the search found could be followed: " + "; ".join(failures))


def _local_report(grid_time: float, local) -> dict:
    """A tube's local optimization for the answer's ``search.local`` (times in s)."""
    stats = local.statistics
    return {
        "grid_time": grid_time,
        "seed_time": stats.seed_duration if np.isfinite(stats.seed_duration) else None,
        "time": local.duration,
        "control_points": [r.control_points for r in stats.rounds],
        "round_times": [r.duration if np.isfinite(r.duration) else None for r in stats.rounds],
        "evaluations": stats.evaluations,
        "stopped": stats.stopped,
        "wall_s": stats.wall_s,
    }
