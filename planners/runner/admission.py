"""Memory admission: a problem is refused before any work when its estimated memory exceeds the
one cap (``toptraj.planners.execution.memory``), with the largest grid, or the smallest sample
period, that fits.

The estimate: the method's bytes per grid interval and joint times the grid (the one asked
for, else the largest the method thins its default grid to), plus the samples at the most the
answer may hold (``Sampling.max_samples``, at most half the cap: ``most_samples``;
``SAMPLE_ARRAYS`` eight-byte arrays per sample and joint), plus a motion generator's own
estimate (the search's graph). The cap is ``MEMORY_CAP_BYTES``, widened by a generator's own
allowance where its options carry one (the search's ``memory_bytes``): over it, ``TooLarge``
naming the largest grid that fits, or the generator's refusal naming its largest setting.

The samples' number is known only once the timing gives the duration: ``admit_samples`` then
refuses a period that gives more than that most, naming the smallest that fits (the samples'
memory was reserved at that count).
"""

from __future__ import annotations

import math

from toptraj.planners.errors import TooLarge
from toptraj.planners.execution import memory
from toptraj.planners.paths.grid import MAX_POINTS
from toptraj.planners.problem.methods import MotionGenerator
from toptraj.planners.problem.problem import Problem
from toptraj.planners.problem.ranges import DT


def admit(problem: Problem) -> None:
    """Refuse ``problem`` before any work when its estimate exceeds the cap.

    Raises:
        TooLarge: the grid asked for does not fit (``largest``: the most intervals that do,
            in the grid's own range; ``estimate`` and ``cap`` in bytes).
        OverMemory: the search's graph does not fit its allowance (the largest setting that
            does is named).
    """
    method, dof = problem.method, problem.robot.dof
    own = allowance = 0
    if isinstance(method, MotionGenerator):
        own, allowance = method.estimate(problem), method.allowance(problem)
        refusal = method.refuse(problem, allowance) if own > allowance else None
        if refusal is not None:
            raise refusal
    reserved = memory.samples_bytes(memory.most_samples(problem.sampling.max_samples, dof), dof) + own
    need = memory.grid_bytes(_intervals(problem), dof, method.bytes_per_interval_joint) + reserved
    cap = memory.MEMORY_CAP_BYTES + allowance
    if need <= cap:
        return
    largest = min(memory.largest_grid(method.bytes_per_interval_joint, dof, reserved, cap), MAX_POINTS)
    raise TooLarge(
        "grid.intervals", problem.grid, need, cap, "bytes", largest=largest if largest >= 2 else None,
        rule="grid_over_method_cap", method=method.name, dof=dof,
    )


def _intervals(problem: Problem) -> int:
    """The grid the method times on: the one asked for (a collocation's own intervals), else
    the largest its default grid is thinned to."""
    asked = problem.grid
    if asked is not None:
        return asked
    return min(problem.method.max_grid_intervals(problem.robot.dof), MAX_POINTS)


def admit_samples(problem: Problem, duration: float) -> None:
    """Refuse sampling a motion of ``duration`` seconds every ``dt`` into more samples than the
    answer may hold (``most_samples``: their memory was admitted at that count).

    Raises:
        TooLarge: with ``smallest_dt``, the smallest period that fits when it lies in ``DT``
            (else ``None``, and ``longest_s``, the longest motion the largest period serves;
            ``fields``: the tool limits given, among what makes the motion this slow).
    """
    dt, asked = problem.sampling.dt, problem.requested
    max_samples = memory.most_samples(problem.sampling.max_samples, problem.robot.dof)
    if math.ceil(duration / dt) + 1 <= max_samples:  # every dt from 0, and the final instant
        return
    needed = _round_up(duration / max(max_samples - 2, 1))
    raise TooLarge(
        "sampling.dt", dt, math.ceil(duration / dt) + 1, max_samples, "samples", rule="too_many_samples",
        duration=duration, smallest_dt=needed if needed <= DT.high else None, largest_dt=DT.high,
        longest_s=_round_down(DT.high * max(max_samples - 2, 1)),
        fields=tuple(f"limits.{name}" for name in ("tool_speed", "tool_angular_speed") if getattr(asked, name) is not None),
    )


def _round_down(value: float, digits: int = 3) -> float:
    """``value`` rounded down to ``digits`` significant digits."""
    scale = 10.0 ** (math.floor(math.log10(value)) - digits + 1)
    return math.floor(value / scale) * scale


def _round_up(value: float, digits: int = 3) -> float:
    """``value`` rounded up to ``digits`` significant digits."""
    scale = 10.0 ** (math.floor(math.log10(value)) - digits + 1)
    return math.ceil(value / scale) * scale
