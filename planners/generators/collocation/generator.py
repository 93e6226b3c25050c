"""``Collocation``, the motion generator of a free path (Jeong & Lee section 4): the path and its
timing optimized together by direct collocation, then the path re-timed exactly along itself
(phase_plane, or min_cost for beta > 0) so that every limit holds between the collocation
instants too, and, for minimum time, the bang-bang torques refined to exact switching times
(``toptraj.planners.generators.collocation.switching``)."""

from __future__ import annotations

import dataclasses

import numpy as np

from toptraj.planners.checks.gate import TimedStretch, checked, gated
from toptraj.planners.constraints.path_constraints import build_path_constraints
from toptraj.planners.errors import InfeasiblePath, NotServed, OutOfRange
from toptraj.planners.generators.collocation import collocation_path, optimize_motion
from toptraj.planners.generators.collocation.bang_bang import switching_times
from toptraj.planners.generators.collocation.motion import StatedGap
from toptraj.planners.generators.collocation.report import CollocationReport
from toptraj.planners.generators.collocation.switching import refine_collocation, switched_path
from toptraj.planners.paths.grid import path_grid
from toptraj.planners.problem.free_motion import FreeMotion
from toptraj.planners.problem.methods import Execution, MotionGenerator, Timed
from toptraj.planners.problem.path_checks import check_within_joint_limits, moving_velocity, path_boundary, timing_grid
from toptraj.planners.problem.problem import Problem
from toptraj.planners.timing.base import GAP_TARGET, TimingMethod
from toptraj.planners.timing.min_cost import MinCostMethod
from toptraj.planners.timing.phase_plane.method import PhasePlaneMethod
from toptraj.robots.notes import Note

#: Most collocation intervals a request may ask for (timing.grid_points).
MAX_INTERVALS = 100
#: Fraction of its torque limit that every joint's collocation torque must reach somewhere for
#: the motion to be refined to bang-bang torques (``_switched``).
REFINED_ABOVE = 0.9


class Collocation(MotionGenerator):
    """Direct collocation of path and timing from start to goal, minimizing T or the integral
    of (1 + beta |tau|^2) dt (``torque_weight`` beta, 1/(N m)^2)."""

    name = "collocation"
    kinds = frozenset({"velocity", "acceleration", "torque"})
    required_kinds = frozenset({"torque"})
    #: Per collocation interval and joint: 28 MB of peak RSS growth for 100 intervals on ur5
    #: (about 49 kB), rounded up.
    bytes_per_interval_joint = 50_000
    #: SLSQP and IPOPT cannot check a deadline: the optimization is the uninterruptible step.
    interruptible = False

    def __init__(self, torque_weight: float = 0.0):
        self.torque_weight = torque_weight

    @property
    def timed_by(self) -> TimingMethod:
        return PhasePlaneMethod() if self.torque_weight == 0.0 else MinCostMethod(self.torque_weight)

    def validate(self, problem: Problem) -> None:
        if not isinstance(problem.motion, FreeMotion):
            raise NotServed("method", self.name, self.name, rule="free_path_needs_collocation", alternatives=("collocation", "search"))
        if problem.grid is not None and not 4 <= problem.grid <= MAX_INTERVALS:
            raise OutOfRange("grid.intervals", problem.grid, 4, MAX_INTERVALS, rule="collocation_intervals")
        check_within_joint_limits(problem.robot, "start", problem.motion.start)
        check_within_joint_limits(problem.robot, "goal", problem.motion.goal)

    def generate(self, problem: Problem, execution: Execution) -> Timed:
        """The collocation's path, re-timed exactly along itself, its switching times refined."""
        deadline = execution.deadline
        assert isinstance(problem.motion, FreeMotion)  # validated
        robot, spec, kinds, limits, threshold = problem.robot, problem.motion, problem.kinds, problem.limits, problem.threshold
        collocation = _optimized(problem, execution.within(0.0, 0.8))
        path, collocation_timing = collocation_path(collocation)
        retimer = self.timed_by
        retiming = deadline.within(0.8, 0.9, "re-timing along the collocation's path")
        retiming.progress(0.0, "constraints")
        constraints = build_path_constraints(path, robot, limits, kinds, timing_grid(path, None, retimer, robot), deadline)
        moving = dataclasses.replace(
            problem.boundary, start_velocity=moving_velocity(spec.start_velocity), end_velocity=moving_velocity(spec.end_velocity),
        )
        notes: tuple[str, ...] = ()
        try:
            result, constraints, check = gated(
                robot, path, retimer, constraints, path_boundary(path, moving, None, retimer), None, kinds, limits, threshold,
                retiming.within(0.1, 1.0),
            )
            stretch = TimedStretch(path, result, constraints, check)
        except InfeasiblePath as error:
            # A boundary state right at a limit may be out of reach of the conservative re-timing;
            # the collocation's own timing is then returned, if it holds the limits.
            result = collocation_timing
            stretch = checked(robot, path, result, "collocation", kinds, limits, threshold, constraints)
            notes = (f"the collocation's own timing is returned (re-timing along its path failed: {error.detail})",)
        switching, winner, source, how = None, collocation, collocation, None
        if self.torque_weight == 0.0:
            deadline.progress(0.9, "refining the switching times")
            path, result, stretch, switching, notes, winner, source = _switched(
                problem, collocation, (path, result, stretch), notes, deadline
            )
            how = "refined" if switching is not None else "read off the samples"
        cost = getattr(result, "cost", None) if self.torque_weight else result.duration
        if cost is None:  # the collocation's own timing, returned: its cost is the collocation's
            cost = collocation.cost
        if source is collocation and self.torque_weight and problem.robot.has_friction:
            # The collocation's dynamics leave the joint friction out; the answer's cost holds it.
            source = StatedGap(None, FRICTION_GAP)
        elif source is collocation:  # the answer's own objective against the collocation's optimum
            source = collocation.gap_of(cost)
        solver = CollocationReport.of(winner, how, source)
        notes = (*notes, *self._gap_note(source, collocation))
        return Timed(
            path, result, (stretch,), "collocation", notes, cost, solver, switching_times=switching,
            motion_gap=(source.optimality_gap, source.gap_basis),
        )

    def _gap_note(self, source, collocation) -> tuple[str, ...]:
        """A note when the minimum time (with a torque weight, the cost) found may lie farther
        than ``GAP_TARGET`` above the optimum, with the advice that brings it closer where there
        is one."""
        if source.optimality_gap is None or source.optimality_gap <= GAP_TARGET:
            return ()
        what = "duration" if self.torque_weight == 0.0 else "cost"
        return (Note(
            f"the {what} may lie up to {100 * source.optimality_gap:.2g} % above the optimum ({source.gap_basis})",
            "collocation_gap", gap=source.optimality_gap, basis=source.gap_basis, what=what,
            most_intervals=MAX_INTERVALS if len(collocation.t) - 1 < MAX_INTERVALS else None,
        ),)


#: Why a free path with a torque weight on an arm with joint friction states no gap.
FRICTION_GAP = (
    "none: the collocation's dynamics leave the joint friction out, so its optimum is not that of the "
    "answer's cost, which holds the friction"
)


def _optimized(problem: Problem, execution: Execution):
    """The collocation's optimum on the requested intervals, under the velocity and acceleration
    limits only when they are asked for; the optimization is the uninterruptible step
    (``Execution.uninterruptible``)."""
    spec, kinds, robot, limits = problem.motion, problem.kinds, problem.robot, problem.limits
    method = problem.method
    assert isinstance(spec, FreeMotion) and isinstance(method, Collocation)
    if problem.grid is not None:
        spec = dataclasses.replace(spec, intervals=problem.grid)
    unlimited = np.full(robot.dof, np.inf)
    limits = dataclasses.replace(
        limits,
        velocity=limits.velocity if "velocity" in kinds else unlimited,
        acceleration=limits.acceleration if "acceleration" in kinds else unlimited,
    )
    return optimize_motion(robot, limits, spec, method.torque_weight, execution.deadline, uninterruptible=execution.uninterruptible)


def _switched(problem: Problem, collocation, timed, notes, deadline):
    """The time-optimal free motion with exact bang-bang torques in place of ``timed`` (path,
    timing, stretch) when it reaches the goal, is not longer and passes the limit gate; with its
    switching times (else ``None``). The collocation's rivals (``CollocationResult.rivals``) are
    refined too and the shortest refined motion wins; the collocation result it came from is
    returned, and the result whose ``optimality_gap`` the answer states (the refined motion, or
    else the collocation)."""
    robot, spec, kinds, limits, threshold = problem.robot, problem.motion, problem.kinds, problem.limits, problem.threshold
    assert isinstance(spec, FreeMotion)
    path, result, stretch = timed
    refined, winner = None, collocation
    # The rivals (other goals the fine grid found close) are compared on exact terms too: the
    # collocation's grid error can exceed their difference.
    for candidate in (collocation, *collocation.rivals):
        if np.any(np.abs(candidate.tau).max(axis=0) < REFINED_ABOVE * limits.torque):
            # A bang-bang motion holds every joint's torque at a limit throughout; one near the
            # collocation's optimum cannot have a joint whose torque stays well below its
            # limit there (velocity or acceleration limits shape such a motion).
            continue
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
