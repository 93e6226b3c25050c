"""Planning errors: each says what is wrong and where along the path."""

from __future__ import annotations

from contextlib import contextmanager

import numpy as np

from toptraj.robots.errors import ToptrajError


class InvalidRequest(ToptrajError):
    """A request that cannot be planned as given: wrong lengths, non-finite numbers, too few or
    coincident waypoints, waypoints outside the joint limits, unknown methods, absurd sizes."""

    title = "Invalid request"


class InfeasiblePath(ToptrajError):
    """No timing can follow the path within the limits.

    Attributes:
        s: Path parameter in [0, 1] where it fails.
        joint: Name of the joint whose limit cannot be met there, if one is to blame.
        limit: The kind of limit that cannot be met ("velocity", "acceleration", "torque",
            "jerk"), when one is to blame.
    """

    title = "Path cannot be followed within the limits"

    def __init__(self, detail: str, s: float | None = None, joint: str | None = None, limit: str | None = None):
        super().__init__(detail)
        self.s = s
        self.joint = joint
        self.limit = limit


class TimingFailed(ToptrajError):
    """A timing method's solver failed on a problem that is feasible at its grid points."""

    title = "Timing method failed"


class OverMemory(ToptrajError):
    """A computation needs, or took, more memory than it is allowed: its settings ask for too
    large a problem (the detail names the setting and the largest value served)."""

    title = "Computation over its memory cap"


class BudgetExceeded(ToptrajError):
    """The computation ran past its time budget."""

    status = 504
    title = "Computation over its time budget"


@contextmanager
def numerical_breakdown_is_failure(method: str):
    """Turn a numerical breakdown inside a timing method (an overflow or division by zero in
    Python floats, a singular or non-converging linear-algebra routine) into ``TimingFailed``
    naming the method, instead of an unexplained error."""
    try:
        yield
    except (ArithmeticError, np.linalg.LinAlgError) as error:
        raise TimingFailed(
            f"timing method {method!r} failed: numerical breakdown ({type(error).__name__}: {error})"
        ) from error
