"""The warnings of a cell's answer, as a trajectory's answer gives them: a limit kind not held
(left out of ``constraints``) that the motion exceeds, a sample period longer than a tenth of the motion,
and samples put on whole periods (``exact_period``) that slow the motion noticeably."""

from __future__ import annotations

import numpy as np

from toptraj.planners.coordination import Cell
from toptraj.planners.runner.answer import UNASKED_EXCESS
from toptraj.planners.runner.sampling_notes import FEWEST_PERIODS, SAMPLES_ADVISED, STRETCH_NOTED, percent


def cell_warnings(
    cell: Cell, unheld: list[dict[str, np.ndarray]], duration: float, sampled: float, dt: float, count: int
) -> list[str]:
    """The warnings of a cell planned in ``duration`` (s) and sampled every ``dt`` (s) into
    ``count`` samples lasting ``sampled`` (s; longer when put on whole periods), ``unheld`` each
    arm's peak utilization of the limit kinds the cell does not hold."""
    warnings = []
    for index, (arm, peaks) in enumerate(zip(cell.arms, unheld, strict=True)):
        for kind, peak in peaks.items():
            finite = np.where(np.isfinite(peak), peak, 0.0)
            if finite.max(initial=0.0) > UNASKED_EXCESS:
                joint = int(np.argmax(finite))
                warnings.append(
                    f"arms[{index}]: the {kind} of joint {arm.robot.joint_names[joint]!r} reaches {finite[joint]:.4g} times "
                    f"its limit, which was not asked for: add {kind!r} to constraints to hold it"
                )
    if duration > 0.0 and dt > duration / FEWEST_PERIODS and dt > SHORTEST_DT:  # at the shortest period: nothing to advise
        warnings.append(
            f"dt = {dt:g} s is {'longer than the motion' if dt > duration else 'more than a tenth of the motion'} "
            f"({duration:.6g} s): its {count} samples do not follow the motion. "
            + _advice(duration)
        )
    if duration > 0.0 and sampled / duration - 1.0 > STRETCH_NOTED:
        warnings.append(
            f"exact_period slows the motion by {percent(sampled / duration - 1.0)} % so that it ends on a whole period of "
            f"dt = {dt:g} s: the samples last {sampled:.6g} s instead of duration = {duration:.6g} s, and peak_utilization "
            f"is that of these samples. dt <= {STRETCH_NOTED * duration:.3g} s keeps the slowing within "
            f"{100 * STRETCH_NOTED:g} %; exact_period false keeps the planned timing"
        )
    return warnings


#: A cell's shortest sample period (s): its schema's bound on ``dt``.
SHORTEST_DT = 1e-3


def _advice(duration: float) -> str:
    """The period that gives ``SAMPLES_ADVISED`` samples of a motion of ``duration`` (s), or the
    shortest a cell takes where that is shorter, with the samples it gives."""
    advised = max(duration / SAMPLES_ADVISED, SHORTEST_DT)
    samples = min(SAMPLES_ADVISED, int(duration / advised + 1e-9) + 1)
    return f"dt is in seconds; dt <= {advised:.3g} s gives {samples} samples or more"
