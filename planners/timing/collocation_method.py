"""``collocation``: the name under which a free motion is optimized (path and timing together,
``toptraj.planners.generators.collocation``). It does not time a given path, so ``solve`` refuses one."""

from __future__ import annotations

from toptraj.planners.constraints.path_constraints import PathConstraints
from toptraj.planners.errors import NotServed
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.planners.timing.base import AT_REST, Boundary, PathTiming, TimingMethod


class CollocationMethod(TimingMethod):
    """Direct collocation of path and timing from start to goal (see ``toptraj.planners.generators.collocation``)."""

    name = "collocation"
    kinds = frozenset({"velocity", "acceleration", "torque"})
    required_kinds = frozenset({"torque"})

    def solve(
        self,
        constraints: PathConstraints,
        boundary: Boundary = AT_REST,
        duration: float | None = None,
        deadline: Deadline = NO_DEADLINE,
    ) -> PathTiming:
        raise NotServed("method", "collocation", "collocation", rule="collocation_needs_free_path",
                        detail="collocation optimizes the path itself: give a free path (start and goal)")
