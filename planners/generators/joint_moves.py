"""Motion generators driven by a time law, joint by joint: through via points (the segments'
shapes and durations found together, ``toptraj.planners.generators.via_points``), and every
joint on its own from a start to a goal (``toptraj.planners.generators.unsynchronized``). The
law's own capabilities are theirs; the motion they return is checked on its path's constraints
by the limit gate (``toptraj.planners.checks.gate.checked``)."""

from __future__ import annotations

from toptraj.planners.checks.gate import TimedStretch, checked
from toptraj.planners.constraints.path_constraints import build_path_constraints
from toptraj.planners.errors import Conflicting, NotServed
from toptraj.planners.generators.unsynchronized import unsynchronized_trajectory
from toptraj.planners.generators.via_points import via_point_trajectory
from toptraj.planners.paths import GeometricPath
from toptraj.planners.problem.methods import Execution, MotionGenerator, Timed
from toptraj.planners.problem.path_checks import check_path_within_limits, timing_grid
from toptraj.planners.problem.problem import Problem
from toptraj.planners.problem.requests import WaypointPath
from toptraj.planners.problem.waypoints import checked_waypoints
from toptraj.planners.timing.base import PathTiming, TimingMethod
from toptraj.planners.timing.laws.method import ClassicalMethod
from toptraj.planners.timing.laws.profiles import PROFILES


class _LawMotion(MotionGenerator):
    """A generator whose motion a time law (``law``, a timing method) shapes: it has the law's
    name and capabilities, and the law states the answer's accuracy."""

    def __init__(self, law: TimingMethod):
        self.law = law
        self.name = law.name
        self.kinds = law.kinds
        self.required_kinds = law.required_kinds
        self.two_waypoints_only = law.two_waypoints_only
        self.continuous_acceleration = law.continuous_acceleration
        self.bytes_per_interval_joint = law.bytes_per_interval_joint
        self.interruptible = law.interruptible
        self.supporting_points = law.supporting_points

    @property
    def timed_by(self) -> TimingMethod:
        return self.law


def _checked_motion(problem: Problem, path: GeometricPath, result: PathTiming, deadline) -> Timed:
    """A motion found with its timing, checked on its path's constraints (jerk checked on the
    dense states, not as a constraint row) within the joint range."""
    method, robot, limits = problem.method, problem.robot, problem.limits
    assert isinstance(method, _LawMotion)
    s = timing_grid(path, problem.grid, method.law, robot)
    check_path_within_limits(robot, path, s)
    constraints = build_path_constraints(path, robot, limits, tuple(k for k in problem.kinds if k != "jerk"), s, deadline)
    stretch: TimedStretch = checked(robot, path, result, method.name, problem.kinds, limits, problem.threshold, constraints)
    return Timed(path, result, (stretch,), method.name)


class ViaPoints(_LawMotion):
    """Via points (``path.interpolation = "via"``): segments shaped and timed together by the
    limits, each by the law (cubic or quintic)."""

    def validate(self, problem: Problem) -> None:
        if problem.boundary.start_velocity is not None or problem.boundary.end_velocity is not None:
            raise Conflicting("boundary", None, ("interpolation",), rule="via_points_from_rest")
        if self.supporting_points is not None:
            raise Conflicting("law.supporting_points", self.supporting_points, ("interpolation",), rule="via_points_are_polynomials")
        if "jerk" in problem.kinds and isinstance(self.law, ClassicalMethod) and self.name in ("cubic", "quintic"):
            self.law.refuse_jerk_limit()

    def generate(self, problem: Problem, execution: Execution) -> Timed:
        execution.deadline.progress(0.0, "via points")
        assert isinstance(problem.motion, WaypointPath)  # validated
        waypoints = checked_waypoints(problem.robot, problem.motion)
        path, result = via_point_trajectory(
            problem.robot, waypoints, self.name, problem.limits, problem.kinds, problem.duration, execution.deadline
        )
        return _checked_motion(problem, path, result, execution.deadline)


class Unsynchronized(_LawMotion):
    """Every joint at its own full speed to its goal, each by the law (a time law: its
    ``ClassicalMethod``; another method is refused when the generator is made)."""

    def __init__(self, law: TimingMethod):
        if not isinstance(law, ClassicalMethod):
            raise NotServed("law.synchronization", "none", law.name, rule="unsynchronized_needs_law", alternatives=tuple(PROFILES))
        super().__init__(law)

    def validate(self, problem: Problem) -> None:
        motion, kinds = problem.motion, problem.kinds
        if not isinstance(motion, WaypointPath) or motion.interpolation == "via" or len(motion.waypoints) != 2:
            raise Conflicting("law.synchronization", "none", ("waypoints",), rule="unsynchronized_needs_two_waypoints")
        if problem.boundary.given or problem.limits.tool is not None:
            raise Conflicting("law.synchronization", "none", ("boundary", "limits.tool_speed"), rule="unsynchronized_from_rest")
        if "jerk" in kinds and isinstance(self.law, ClassicalMethod):
            self.law.refuse_jerk_limit()

    def generate(self, problem: Problem, execution: Execution) -> Timed:
        execution.deadline.progress(0.0, "joint moves")
        assert isinstance(problem.motion, WaypointPath)  # validated
        waypoints = checked_waypoints(problem.robot, problem.motion)
        assert isinstance(self.law, ClassicalMethod)  # timing.synchronization 'none' takes a time law
        path, result = unsynchronized_trajectory(
            problem.robot, waypoints[0], waypoints[1], self.law.profile, problem.limits, problem.kinds,
            problem.duration, execution.deadline,
        )
        return _checked_motion(problem, path, result, execution.deadline)
