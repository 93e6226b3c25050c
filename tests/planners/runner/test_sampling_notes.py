"""The library's notes on sampling: a period longer than the motion, and a motion slowed by
more than 1 % to end on a whole period, with their facts."""

from __future__ import annotations

import pytest

from toptraj.planners.runner.sampling_notes import sampling_notes


def test_a_period_longer_than_the_motion_and_its_slowing_are_noted():
    few, slowed = sampling_notes(0.63, 10.0, True, 2)
    assert few.rule == "too_few_samples" and few.facts["count"] == 2 and few.facts["advised"] == pytest.approx(0.0063)
    assert slowed.rule == "slowed_to_whole_periods" and slowed.facts["scale"] == pytest.approx(10.0 / 0.63)
    assert "1487 %" in slowed and "peak_utilization is that of the planned timing" in slowed


def test_a_slowing_of_one_percent_or_less_is_not_noted():
    assert sampling_notes(1.0, 0.01005, True, 101) == []  # 100 periods of 0.01005 s: 0.5 % longer
    assert [note.rule for note in sampling_notes(1.0, 0.1, True, 11)] == []  # ten periods: followed
    assert [note.rule for note in sampling_notes(1.0, 0.09, True, 13)] == ["slowed_to_whole_periods"]  # 1.08 s


def test_a_period_longer_than_a_tenth_of_the_motion_is_noted():
    """A 1.55 s motion sampled every 0.9 s had 3 samples and no word."""
    (few,) = sampling_notes(1.55, 0.9, False, 3)
    assert few.rule == "too_few_samples" and "is more than a tenth of the motion's duration 1.55 s: its 3 samples" in few
    assert sampling_notes(1.55, 0.155, False, 11) == []
