"""Arms timed along their given paths so that they keep their clearance, as early as
possible on one clock (path-velocity decomposition: Kant & Zucker 1986; O'Donnell &
Lozano-Pérez 1989).

Candidates, each checked against the coordination diagram, the quickest kept:

* both arms on their own time-optimal motions at once: when the arms never come near each
  other this is optimal (neither can finish before its own optimum);
* one arm started late by the least delay that keeps them apart (the late start by the other
  arm's whole duration is moving one arm after the other);
* the quickest monotone curve through the free diagram (``curve``), smoothed, both arms timed
  along it by one time-optimal solve (``timing.pair_timing``).

Three or more arms: prioritized planning over every order of the arms (``prioritized``, its
optimality loss stated there).

The one kept is verified at fine samples (``verify.schedule_clearance``) and slowed uniformly
where a dense resampling finds a limit (velocity, acceleration, torque) exceeded between the
solver's grid points (``limits.within_limits``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from toptraj.planners.collision.self_collision import SelfCollision, check_self_collision
from toptraj.planners.coordination.cell import MAX_ARMS, Cell, pair_distances
from toptraj.planners.coordination.curve import SmoothCurve, resampled, shortcut, shortest_curve, widened
from toptraj.planners.coordination.diagram import (
    FINE_STEP,
    Diagram,
    Measured,
    arm_capsules,
    check_ends,
    coordination_diagram,
    measure,
    widest_coordination,
)
from toptraj.planners.coordination.limits import cannot_hold_still, within_limits
from toptraj.planners.coordination.prioritized import pair_diagrams, prioritized
from toptraj.planners.coordination.timing import CurveMotion, Schedule, SoloMotion, pair_timing, solo_timing
from toptraj.planners.coordination.verify import PairClearance, schedule_clearance
from toptraj.planners.errors import InfeasiblePath, InvalidRequest
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.planners.timing.base import TimeScaling

#: Late starts tried per arm, evenly over the other arm's duration.
DELAYS = 64
#: Samples in time at which a candidate is checked against the diagram.
DIAGRAM_SAMPLES = 2_000
#: Widenings (grid nodes) of the collision region in which the quickest curve is sought.
WIDENINGS = (1, 2, 3)
#: Spacings (in s) of the control points of the smoothed curves tried.
SPACINGS = (0.2, 0.1, 0.05, 0.02, 0.01)
#: Margins (m) above the clearance of the diagram's free cells, tried in turn for two arms: the
#: schedules of the first stay clear between the diagram's samples in time; where none of
#: them passes the strict check, the diagram without a margin, its schedules held by that
#: check alone.
MARGINS = (FINE_STEP, 0.0)


@dataclass(frozen=True)
class Coordination:
    """The timed arms: their ``schedule``, each arm's own optimum ``solo`` (s), the
    coordination ``diagrams`` of every pair (a, b), a < b (``diagram``: that of arms 0 and 1),
    the (s_1, ..., s_N) the schedule passes through (``curve``, (n, N)), and its ``clearance``."""

    schedule: Schedule
    solo: tuple[float, ...]
    diagrams: dict[tuple[int, int], Diagram]
    curve: np.ndarray
    clearance: PairClearance

    @property
    def diagram(self) -> Diagram:
        """The coordination diagram of arms 0 and 1."""
        return self.diagrams[(0, 1)]

    @property
    def time_lost(self) -> float:
        """Seconds beyond the slowest arm's own optimum, spent keeping the arms apart."""
        return self.schedule.duration - max(self.solo)


def _free(diagram: Diagram, schedule: Schedule) -> bool:
    s = schedule.path_parameters(np.linspace(0.0, schedule.duration, DIAGRAM_SAMPLES + 1))
    return bool(diagram.free_at(s[:, 0], s[:, 1]).all())


def _delayed(diagram: Diagram, solo: list[TimeScaling], late: int) -> Schedule | None:
    """The schedule with arm ``late`` started after the least delay that keeps it free."""
    for delay in np.linspace(0.0, solo[1 - late].duration, DELAYS + 1):
        motions = [SoloMotion(solo[0]), SoloMotion(solo[1])]
        motions[late] = SoloMotion(solo[late], float(delay))
        schedule = Schedule(tuple(motions), "simultaneous" if delay == 0.0 else f"arms[{late}] waits")
        if _free(diagram, schedule):
            return schedule
    return None


def _smoothed(cell: Cell, diagram: Diagram, points: np.ndarray, deadline: Deadline) -> Schedule | None:
    """The quickest free schedule along B-splines of ``points`` resampled at each of
    ``SPACINGS`` (wider rounding of the corners, faster where it stays free), or None."""
    best: Schedule | None = None
    for spacing in SPACINGS:
        deadline.check()
        curve = SmoothCurve(resampled(points, spacing))
        s = curve.evaluate(np.linspace(0.0, 1.0, DIAGRAM_SAMPLES + 1))[0]
        if not diagram.free_at(s[:, 0], s[:, 1]).all():
            continue
        try:
            scaling = pair_timing(cell, curve, deadline=deadline)
        except InfeasiblePath:  # a curve along which the pair cannot be timed: the other candidates stand
            continue
        schedule = within_limits(cell, Schedule((CurveMotion(scaling, curve, 0), CurveMotion(scaling, curve, 1)), "coordinated"))
        if (best is None or schedule.duration < best.duration) and _free(diagram, schedule):
            best = schedule
    return best


def curve_schedule(cell: Cell, diagram: Diagram, solo: list[TimeScaling], deadline: Deadline) -> Schedule | None:
    """Both arms along the quickest smoothed curve of the diagram, or None when none is free:
    the curve is sought in the collision region widened by ``WIDENINGS`` nodes in turn, its
    staircase straightened (``curve.shortcut``) and smoothed (``_smoothed``)."""
    dt1, dt2 = (np.diff(np.interp(diagram.s, scaling.s, scaling.t)) for scaling in solo)
    found = []
    for cells in WIDENINGS:
        try:
            nodes = shortest_curve(widened(diagram, cells), dt1, dt2)
        except InfeasiblePath:
            continue
        schedule = _smoothed(cell, diagram, shortcut(widened(diagram, max(cells - 2, 0)), nodes), deadline)
        if schedule is not None:
            found.append(schedule)
    return min(found, key=lambda schedule: schedule.duration, default=None)


def _check_cell(cell: Cell) -> None:
    if not 2 <= len(cell.arms) <= MAX_ARMS:
        raise InvalidRequest(
            "arms", len(cell.arms), rule="too_many_arms", fewest=2, most=MAX_ARMS,
            detail=f"a cell of {len(cell.arms)} arm{'' if len(cell.arms) == 1 else 's'}; from 2 to {MAX_ARMS} are served",
        )


def _candidates(
    cell: Cell, solo: list[TimeScaling], deadline: Deadline, margin: float, measured: Measured | None
) -> tuple[dict, list[Schedule]]:
    """The pairwise diagrams and the schedules to try: for two arms a late start of either and
    the coordinated curve on the diagram of free cells ``margin`` (m) above the clearance, from
    the distances ``measured`` once for every margin; for more, the prioritized schedule
    (``prioritized``)."""
    if len(cell.arms) > 2:
        diagrams = pair_diagrams(cell, deadline)
        return diagrams, [prioritized(cell, solo, diagrams, deadline)]
    diagram = coordination_diagram(cell, deadline=deadline, margin=margin, measured=measured)
    candidates = [_delayed(diagram, solo, 1), _delayed(diagram, solo, 0), curve_schedule(cell, diagram, solo, deadline)]
    return {(0, 1): diagram}, [candidate for candidate in candidates if candidate is not None]


def _arms_alone(cell: Cell, deadline: Deadline) -> list[TimeScaling]:
    """Each arm's own path checked for self-collision, then timed alone; an arm's failure
    raised again naming the arm (``arms[i]``)."""
    solo = []
    for index, arm in enumerate(cell.arms):
        where = f"arms[{index}] ({arm.robot.name})"
        try:
            check_self_collision(arm.path, arm.robot, deadline=deadline)
            solo.append(solo_timing(arm, cell.kinds, deadline=deadline, field=f"arms[{index}]"))
        except SelfCollision as error:
            s = float(getattr(error, "s", 0.0))
            raise SelfCollision(f"{where}: {error.detail}", s, error.link_a, error.link_b, error.distance) from error
        except InfeasiblePath as error:
            held = getattr(error, "held", None)  # a load that no timing holds: what holds it instead
            loads = getattr(error, "joints", None)  # or the worst of the loads held still beyond a limit
            if held is None and loads:
                held = max(loads, key=lambda item: item[0])[1]
            if held is not None:
                joint = arm.robot.joint_names.index(held.joint)
                raise cannot_hold_still(index, arm, held.s, held.torque, joint) from error
            facts = {key: getattr(error, key, None) for key in ("s", "joint", "limit")}
            raise InfeasiblePath(f"{where} cannot follow its own path alone: {error.detail}", **facts) from error
    return solo


def _verified(cell: Cell, candidates: list[Schedule], deadline: Deadline) -> tuple[Schedule, PairClearance] | None:
    """The quickest of ``candidates`` (held to the limits) whose strict check keeps the
    clearance, with that check; None when none does."""
    for schedule in sorted((within_limits(cell, c) for c in candidates), key=lambda c: c.duration):
        clearance = schedule_clearance(cell, schedule, deadline)
        if clearance.bound >= cell.clearance:
            return schedule, clearance
    return None


def coordinate(cell: Cell, deadline: Deadline = NO_DEADLINE) -> Coordination:
    """Time the cell's arms along their paths, kept ``cell.clearance`` apart, all done as early
    as possible (module docstring; three or more arms: ``prioritized``).

    Raises:
        InvalidRequest: fewer than 2 or more than ``MAX_ARMS`` arms, or arms that collide at
            their start.
        SelfCollision: an arm's own path makes two of its links touch (naming the arm, the
            links and s).
        InfeasiblePath: an arm cannot follow its path within its limits (naming the arm, the
            joint, the limit and s), or no timing keeps the arms apart along these paths.
    """
    _check_cell(cell)
    check_ends(cell)
    solo = _arms_alone(cell, deadline)
    measured = measure(cell, deadline=deadline) if len(cell.arms) == 2 else None
    for margin in MARGINS[: 1 if len(cell.arms) > 2 else None]:
        diagrams, candidates = _candidates(cell, solo, deadline, margin, measured)
        kept = _verified(cell, candidates, deadline)
        if kept is not None:
            schedule, clearance = kept
            t = np.linspace(0.0, schedule.duration, DIAGRAM_SAMPLES + 1)
            return Coordination(
                schedule, tuple(motion.duration for motion in solo), diagrams, schedule.path_parameters(t), clearance
            )
    text = (
        "no timing keeps the arms apart along these paths (neither waiting nor a coordinated curve through the "
        "coordination diagram is free)"
    )
    if len(cell.arms) == 2:
        raise _widest_refusal(cell, diagrams[(0, 1)], text)
    raise InfeasiblePath(f"{text}: move a base apart, change a path or lower clearance")


def _widest_refusal(cell: Cell, diagram: Diagram, text: str) -> InfeasiblePath:
    """The refusal naming where the coordination that keeps the two arms farthest apart comes
    closest, and ``room``: the clearance below which the diagram has room for it (its margin
    ``FINE_STEP`` below that distance)."""
    widest, i, j = widest_coordination(diagram)
    s1, s2 = float(diagram.s[i]), float(diagram.s[j])
    first, second = cell.arms
    _, k1, k2 = pair_distances(arm_capsules(first, np.array([s1])), arm_capsules(second, np.array([s2])))
    link_a, link_b = first.link_names()[int(k1[0])], second.link_names()[int(k2[0])]
    return InfeasiblePath(
        f"{text}: every coordination of the two motions comes within {widest:.3g} m (the clearance is {cell.clearance:g} m); "
        f"the one that keeps them farthest apart brings link {link_a!r} of arm 0 at s = {s1:.3g} that close to link "
        f"{link_b!r} of arm 1 at s = {s2:.3g}",
        s=s1, rule="arms_never_apart", arms=(0, 1), links=(link_a, link_b), s_pair=(s1, s2), distance=widest,
        clearance=cell.clearance, room=widest - FINE_STEP,
    )
