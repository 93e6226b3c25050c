"""Notes on how an answer's samples render its motion: too few samples to follow it (a period
``dt`` longer than a tenth of the motion), and a motion slowed to end on a whole period (``exact_period``,
``toptraj.planners.trajectory.exact_period_scale``) by more than ``STRETCH_NOTED``."""

from __future__ import annotations

from toptraj.planners.trajectory import exact_period_scale
from toptraj.robots.notes import Note

#: Samples per motion that a period of at most duration / ``SAMPLES_ADVISED`` gives.
SAMPLES_ADVISED = 100
#: Fewest periods per motion below which the samples are noted as not following it (a period
#: longer than a tenth of the motion: a 1.55 s motion sampled every 0.9 s has 3 samples).
FEWEST_PERIODS = 10
#: Relative stretch of the motion (k - 1) beyond which it is noted.
STRETCH_NOTED = 0.01


def percent(share: float) -> str:
    """``share`` in percent, three significant figures below 1000 %, whole ones above."""
    return f"{100 * share:.3g}" if 100 * share < 1000 else f"{100 * share:.0f}"


def sampling_notes(duration: float, dt: float, exact_period: bool, count: int) -> list[Note]:
    """The notes for a motion of ``duration`` (s) sampled every ``dt`` (s) into ``count``
    samples, on whole periods with ``exact_period``."""
    notes = []
    if duration > 0 and dt > duration / FEWEST_PERIODS:
        notes.append(Note(
            f"sampling.dt = {dt:g} s is more than a tenth of the motion's duration {duration:.6g} s: its {count} samples do not "
            f"follow the motion; a period of at most {duration / SAMPLES_ADVISED:.3g} s (dt is in seconds) gives "
            f"{SAMPLES_ADVISED} samples or more",
            "too_few_samples", field="sampling.dt", value=dt, duration=duration, count=count,
            advised=duration / SAMPLES_ADVISED, samples=SAMPLES_ADVISED,
        ))
    scale = exact_period_scale(duration, dt) if exact_period else 1.0
    if scale - 1.0 > STRETCH_NOTED:
        notes.append(Note(
            f"sampling.exact_period slows the motion by {percent(scale - 1.0)} % (k = {scale:.6g}) so that it ends "
            f"on a whole period of {dt:g} s: it lasts {scale * duration:.6g} s instead of {duration:.6g} s, its "
            f"velocities are 1/k, its accelerations 1/k^2 and its jerks 1/k^3 of the planned ones; peak_utilization "
            f"is that of the planned timing, not of the slowed samples; a smaller dt (at most "
            f"{STRETCH_NOTED * duration:.3g} s keeps the slowing within {100 * STRETCH_NOTED:g} %) or sampling.exact_period "
            "false keeps the planned timing",
            "slowed_to_whole_periods", field="sampling.exact_period", dt=dt, scale=scale, duration=duration,
            stretched=scale * duration, noted=STRETCH_NOTED,
        ))
    return notes
