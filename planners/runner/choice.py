"""The method object a ``Timing`` names, of either family: a timing method along a given path,
or the motion generator that finds the motion itself (the global search, the collocation of a
free path, via points, joints moving on their own), holding its options."""

from __future__ import annotations

from toptraj.planners.generators.joint_moves import Unsynchronized, ViaPoints
from toptraj.planners.problem.free_motion import FreeMotion
from toptraj.planners.problem.methods import MotionGenerator
from toptraj.planners.problem.problem import MotionSpec
from toptraj.planners.problem.requests import Timing, WaypointPath, timing_method
from toptraj.planners.timing.base import TimingMethod


def method_for(timing: Timing, motion: MotionSpec) -> TimingMethod | MotionGenerator:
    """The method of ``timing.method`` with its options; a time law through via points or
    joint by joint becomes the generator that shapes the motion with it. A free motion with a
    timing method stays a timing method (``build_problem`` refuses the pair)."""
    method = timing_method(timing)
    # The search and the collocation are imported where they are named: the other requests do
    # without their modules and compiled kernels.
    if timing.method == "search":
        from toptraj.planners.generators.search.generator import Search

        return Search(timing.search)
    if timing.method == "collocation":
        from toptraj.planners.generators.collocation.generator import Collocation

        return Collocation(timing.torque_weight)
    assert method is not None  # every other name is a timing method's
    if isinstance(motion, FreeMotion):
        return method
    if timing.synchronization == "none":
        return Unsynchronized(method)
    if isinstance(motion, WaypointPath) and motion.interpolation == "via":
        return ViaPoints(method)
    return method
