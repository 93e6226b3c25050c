"""Viscous friction's tangent, moved onto the answer: the passes every timing method that
linearizes viscous friction (``PathConstraints.linearized``) makes around its reference.

A viscous term D sd = D sqrt(x) is concave in x = sd^2; a timing holds its tangent at a reference
x_ref, which bounds it from above (Verscheure et al., IEEE TAC 2009, keep the program convex the
same way). The first reference is the frictionless maximum velocity curve
(``admissible.friction_reference``). Its tangent adds D sqrt(x_ref) / 2 to a row at x = 0:
under strong damping it asks torque that no motion near rest needs, and the timing finds no
motion ("not even at rest") where slower motions exist. The reference is then lowered
(``LOWERING``, at most ``REFERENCES`` references), and each later pass takes the tangent at the
answer before: exact there, so that answer stays feasible and the duration can only fall,
until it settles (``SETTLED``). Where no reference lets the path through, the first refusal is
raised: its numbers are the first tangent's, close to the limits' own, where a tangent at low
speed understates the speeds allowed (ninefold in a test).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TypeVar

import numpy as np

from toptraj.planners.errors import BudgetExceeded, InfeasiblePath

#: Factor by which the reference is lowered after a timing that finds no motion, and the most
#: references tried.
LOWERING = 1.0 / 16.0
REFERENCES = 5
#: Most passes around each answer after a lowered reference, and the relative change of the
#: duration at which they stop.
PASSES = 6
SETTLED = 1e-6

Timed = TypeVar("Timed")


def friction_passes(
    solve: Callable[[np.ndarray], Timed], reference: np.ndarray, x_of: Callable[[Timed], np.ndarray],
    duration_of: Callable[[Timed], float], passes: int, lowered_passes: int = PASSES,
) -> Timed:
    """``solve(x_ref)`` (a timing, viscous friction linearized around x_ref (N + 1,), 1/s^2)
    around ``reference``, lowered where it finds no motion, then ``passes`` more around each
    answer (``x_of``), or up to ``lowered_passes`` after a lowered reference, stopped once its
    ``duration_of`` settles (module docstring).

    Raises:
        InfeasiblePath: the first reference's refusal, where no reference lets the path through
            (also where the budget runs out while the lower ones are tried).
    """
    first: InfeasiblePath | None = None
    for attempt in range(REFERENCES):
        try:
            timed = solve(reference)
            break
        except InfeasiblePath as error:
            first = first or error
            if attempt == REFERENCES - 1:
                raise first from None
            reference = reference * LOWERING
        except BudgetExceeded:
            if first is None:
                raise
            raise first from None  # the refusal known, rather than the budget its retries spent
    duration = np.inf
    for _ in range(passes if attempt == 0 else lowered_passes):
        timed = solve(x_of(timed))
        previous, duration = duration, duration_of(timed)
        if abs(previous - duration) <= SETTLED * duration:
            break
    return timed
