"""A budget error names its budget as a person reads it: a batch hands each request what is
left of its own budget (1.727262320000591 s), which the message showed to the last digit."""

from __future__ import annotations

import pytest

from toptraj.planners import BudgetExceeded, Deadline


def test_the_budget_is_shown_to_three_digits():
    deadline = Deadline(1.727262320000591)
    deadline.cancel()
    with pytest.raises(BudgetExceeded, match=r"time budget of 1\.73 s$"):
        deadline.check()


def test_a_cancelled_computation_without_a_budget_says_so():
    deadline = Deadline()
    deadline.cancel()
    with pytest.raises(BudgetExceeded, match="stopped by its caller"):
        deadline.check()
