"""Planning errors: each carries the facts of what is wrong and where along the path.

The classes of an input that cannot be planned as given (``InvalidRequest`` and its kinds) carry
the input's field in the library's own names (``grid.intervals``, ``sampling.dt``,
``waypoints[2][4]``, ``method.torque_weight``), the value given and the facts of the rule it
breaks; the service words them in its request's vocabulary and picks the status.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np

from toptraj.robots.errors import InvalidInput, ToptrajError


class InvalidRequest(InvalidInput):
    """A request that cannot be planned as given: wrong lengths, non-finite numbers, too few or
    coincident waypoints, waypoints outside the joint limits, unknown methods, absurd sizes."""


class OutOfRange(InvalidRequest):
    """``value`` outside [``low``, ``high``] (``unit``); ``signed``: the range bounds a magnitude,
    [-high, high]."""

    rule_of_class = "out_of_range"

    def __init__(self, field: str, value: object, low: float, high: float, unit: str = "", **facts: Any):
        super().__init__(field, value, low=low, high=high, unit=unit, **facts)


class WrongLength(InvalidRequest):
    """``given`` values where ``expected`` are needed (one per joint, most often)."""

    rule_of_class = "wrong_length"

    def __init__(self, field: str, value: object, given: int, expected: int, **facts: Any):
        super().__init__(field, value, given=given, expected=expected, **facts)


class NotOneOf(InvalidRequest):
    """A name that is none of ``allowed``."""

    rule_of_class = "not_one_of"

    def __init__(self, field: str, value: object, allowed: tuple | list, **facts: Any):
        super().__init__(field, value, allowed=list(allowed), **facts)


class NotServed(InvalidRequest):
    """An input ``method`` does not serve (``rule`` says what it needs instead; ``alternatives``
    the methods or settings that do)."""

    def __init__(self, field: str, value: object, method: str, *, rule: str, alternatives: tuple = (), **facts: Any):
        super().__init__(field, value, method=method, rule=rule, alternatives=tuple(alternatives), **facts)


class Conflicting(InvalidRequest):
    """Inputs that cannot be given together (``fields``; ``rule`` says why)."""

    def __init__(self, field: str, value: object, fields: tuple[str, ...], *, rule: str, **facts: Any):
        super().__init__(field, value, fields=tuple(fields), rule=rule, **facts)


class TooLarge(InvalidRequest):
    """A size beyond what is served: ``estimate`` above ``cap`` (``unit``); ``largest``, when
    given, is the largest value of the field that is served (it lies in the field's range)."""

    rule_of_class = "too_large"

    def __init__(self, field: str, value: object, estimate: float, cap: float, unit: str = "",
                 largest: float | None = None, **facts: Any):
        super().__init__(field, value, estimate=estimate, cap=cap, unit=unit, largest=largest, **facts)


class InfeasiblePath(ToptrajError):
    """No timing can follow the path within the limits.

    Attributes:
        s: Path parameter in [0, 1] where it fails.
        joint: Name of the joint whose limit cannot be met there, if one is to blame.
        limit: The kind of limit that cannot be met ("velocity", "acceleration", "torque",
            "jerk"), when one is to blame.
        held: A ``toptraj.planners.constraints.held_load.HeldLoad`` when holding still there already needs more
            torque than a joint's limit (gravity and friction), else ``None``.
    """

    def __init__(self, detail: str = "", s: float | None = None, joint: str | None = None, limit: str | None = None,
                 **facts: Any):
        super().__init__(detail, s=s, joint=joint, limit=limit, **facts)


class LimitExceeded(InfeasiblePath):
    """A timing that still exceeds a limit by the factor ``ratio`` (> 1) at ``s`` after the
    gate's rounds of refinement (``toptraj.planners.checks.gate``)."""


class OutsideJointRange(InfeasiblePath):
    """The interpolated path leaves the range [``lower``, ``upper``] of ``joint`` at ``s``,
    where the joint's coordinate is ``value``."""


class TimingFailed(ToptrajError):
    """A timing method's solver failed on a problem that is feasible at its grid points
    (``method``, when known; ``solver_status``: the solver's own word)."""


class WorkerStopped(TimingFailed):
    """The worker process computing the request ended without an answer (``exit_code``: -9 when
    killed, by the system for memory or by an operator): nothing in the request is known to be
    wrong, and the same request may be answered when computed again."""

    def __init__(self, exit_code: int | None):
        super().__init__(
            f"the worker process stopped without an answer (exit code {exit_code})", rule="worker_stopped", exit_code=exit_code
        )


class NonFinite(TimingFailed):
    """A method's ``quantity`` holds ``count`` NaN or infinite numbers."""


class OverMemory(ToptrajError):
    """A computation needs, or took, more memory than it is allowed: its settings ask for too
    large a problem (``field``, ``estimate`` and ``cap`` in bytes, ``largest`` served, when
    known)."""


class BudgetExceeded(ToptrajError):
    """The computation ran past its time budget (``budget_s``, ``stage`` when known)."""


class ShareSpent(BudgetExceeded):
    """A method's own share of the time budget ran out before it had an answer (the global
    search's searches): more time may find one, and the budget as a whole may have time left
    (a comparison goes on with its other methods)."""


@contextmanager
def numerical_breakdown_is_failure(method: str) -> Iterator[None]:
    """Turn a numerical breakdown inside a timing method (an overflow or division by zero in
    Python floats, a singular or non-converging linear-algebra routine) into ``TimingFailed``
    naming the method, instead of an unexplained error."""
    try:
        yield
    except (ArithmeticError, np.linalg.LinAlgError) as error:
        raise TimingFailed(
            f"timing method {method!r} failed: numerical breakdown ({type(error).__name__}: {error})",
            method=method,
        ) from error
