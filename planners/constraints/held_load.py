"""Facts for failures: which joint cannot hold its load where along the path, and every stretch
where holding still needs more torque than a limit."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from toptraj.planners.constraints.path_constraints import PathConstraints
from toptraj.planners.errors import InfeasiblePath


class HeldLoad(NamedTuple):
    """At path parameter ``s``, holding still needs ``torque`` (in ``unit``: N m, N for a
    prismatic joint) on ``joint``, above its ``limit``."""

    s: float
    torque: float
    joint: str
    limit: float
    unit: str = "N m"


def static_load(constraints: PathConstraints, point: int) -> tuple[HeldLoad | None, str | None, str | None]:
    """At grid point ``point``: the ``HeldLoad`` of the joint whose torque at rest (gravity and
    friction) is the largest share of its limit, when that share exceeds 1 (else ``None``),
    that joint's name and the limit to blame, "torque" (both ``None`` without torque rows)."""
    torque_rows = [k for k, (kind, _) in enumerate(constraints.rows) if kind == "torque"]
    if not torque_rows:
        return None, None, None
    load = np.abs(constraints.c[point, torque_rows]) / constraints.upper[point, torque_rows]
    worst = torque_rows[int(np.argmax(load))]
    joint = constraints.joint_names[constraints.rows[worst][1]]
    if load.max() <= 1.0:
        return None, joint, "torque"
    held = HeldLoad(
        float(constraints.s[point]), float(abs(constraints.c[point, worst])), joint, float(constraints.upper[point, worst]),
        constraints.force_unit(constraints.rows[worst][1]),
    )
    return held, joint, "torque"


class RestExcess(NamedTuple):
    """A stretch ``start <= s <= end`` of grid points where holding still needs more torque
    than a joint's limit, with its ``worst`` load (the largest share of its limit)."""

    start: float
    end: float
    worst: HeldLoad


def rest_loads(constraints: PathConstraints) -> tuple[np.ndarray, list[int]]:
    """(ratios, joints): at each grid point and for each joint with a torque row, the torque
    that holding still needs (gravity and Coulomb friction: the rows' ``c``, from either side
    of a kink; Jeong & Lee's constant term of eq. (3.6)) over the limit it must stay within,
    shape (N + 1, k); and those k joints' indices. Above 1: holding still is beyond the limit."""
    torque_rows = [k for k, (kind, _) in enumerate(constraints.rows) if kind == "torque"]
    joints = [constraints.rows[k][1] for k in torque_rows]
    ratios = np.zeros((len(constraints.s), len(torque_rows)))
    for c in (constraints.c, constraints.c_left):
        held = c[:, torque_rows]
        with np.errstate(divide="ignore", invalid="ignore"):
            share = np.where(held >= 0.0, held / constraints.upper[:, torque_rows], held / constraints.lower[:, torque_rows])
        ratios = np.maximum(ratios, np.nan_to_num(share, nan=0.0, posinf=np.inf))
    return ratios, joints


def rest_excesses(constraints: PathConstraints, intervals: np.ndarray) -> tuple[RestExcess, ...]:
    """The stretches of consecutive grid ``intervals`` (indices i of [s_i, s_i+1], sorted),
    each with the worst load of holding still at its grid points (``rest_loads``)."""
    ratios, joints = rest_loads(constraints)
    if not ratios.size or not len(intervals):
        return ()
    last_point = len(constraints.s) - 1
    breaks = np.flatnonzero(np.diff(intervals) > 1)
    firsts, lasts = intervals[np.concatenate(([0], breaks + 1))], intervals[np.concatenate((breaks, [len(intervals) - 1]))]
    return tuple(
        RestExcess(
            float(constraints.s[first]), float(constraints.s[min(last + 1, last_point)]),
            _load(constraints, ratios, joints, int(first), min(int(last) + 2, last_point + 1)),
        )
        for first, last in zip(firsts, lasts)
    )


def holding_excesses(constraints: PathConstraints) -> tuple[tuple[float, HeldLoad], ...]:
    """For each joint whose torque limit holding still exceeds somewhere along the path
    (``rest_loads`` above 1): (its largest share of the limit, the ``HeldLoad`` there)."""
    ratios, joints = rest_loads(constraints)
    return tuple(
        (float(ratios[:, k].max()), _load(constraints, ratios[:, [k]], [joints[k]], 0, len(ratios)))
        for k in range(len(joints)) if ratios[:, k].max() > 1.0
    )


def _load(constraints: PathConstraints, ratios: np.ndarray, joints: list[int], first: int, last: int) -> HeldLoad:
    """The ``HeldLoad`` of the largest ratio among grid points ``first`` to ``last - 1``."""
    point, k = np.unravel_index(int(np.argmax(ratios[first:last])), ratios[first:last].shape)
    point += first
    row = constraints.rows.index(("torque", joints[k]))
    torque = max(abs(constraints.c[point, row]), abs(constraints.c_left[point, row]))
    limit = constraints.upper[point, row] if constraints.c[point, row] >= 0.0 else -constraints.lower[point, row]
    return HeldLoad(float(constraints.s[point]), float(torque), constraints.joint_names[joints[k]], float(limit), constraints.force_unit(joints[k]))


def holding_facts(constraints: PathConstraints) -> dict:
    """The facts of holding still beyond the torque limits along the path, for an error to
    carry (``joints``: ``holding_excesses``; ``ratio``: their largest share), or none."""
    joints = holding_excesses(constraints)
    return {"joints": joints, "ratio": max(item[0] for item in joints)} if joints else {}


#: Stretches named one by one in an error's sentence (the rest counted).
NAMED_STRETCHES = 3


def not_even_at_rest(constraints: PathConstraints, intervals: np.ndarray) -> InfeasiblePath | None:
    """The error of a path that no motion can follow over the grid ``intervals`` (indices i of
    [s_i, s_i+1] where a timing method finds no admissible state, not even rest: every
    admissible path acceleration at sd = 0 breaks a limit), with the figures of holding still
    there: each stretch of consecutive intervals (``stretches``, in order) with the torque its
    worst joint needs at rest against that limit, and for every joint that holding still
    overloads anywhere on the path its largest share of its limit (``joints``; ``ratio``: the
    largest). ``None`` when holding still is within the limits everywhere (the method's own
    words then stand)."""
    joints = holding_excesses(constraints)
    if not joints:
        return None
    stretches = rest_excesses(constraints, np.asarray(intervals, dtype=np.intp))
    ratio = max(item[0] for item in joints)
    ends = _ends_beyond(constraints, stretches)
    first = stretches[0]
    shown = "; ".join(
        f"s = {item.start:.4f} to {item.end:.4f}, where holding still needs {item.worst.torque:.4g} {item.worst.unit} on joint "
        f"{item.worst.joint!r} (at s = {item.worst.s:.4f}) against its limit of {item.worst.limit:.4g} {item.worst.unit}"
        for item in stretches[:NAMED_STRETCHES]
    )
    more = f"; and {len(stretches) - NAMED_STRETCHES} more" if len(stretches) > NAMED_STRETCHES else ""
    also = "".join(
        f"; holding still at s = {load.s:g} needs {load.torque:.4g} {load.unit} on joint {load.joint!r} against its limit of "
        f"{load.limit:.4g} {load.unit} too" for load in ends
    )
    return InfeasiblePath(
        f"no motion along the path can meet the torque limits, not even at rest, on {len(stretches)} stretch(es): {shown}{more}{also}",
        s=first.start, joint=first.worst.joint, limit="torque", rule="not_even_at_rest", stretches=stretches,
        joints=joints, ratio=ratio, ends=ends,
    )


def _ends_beyond(constraints: PathConstraints, stretches: tuple[RestExcess, ...]) -> tuple[HeldLoad, ...]:
    """The path's ends (s = 0 and 1, where a motion from and to rest holds still) outside
    ``stretches`` where holding still needs more torque than a limit: their worst loads."""
    ratios, joints = rest_loads(constraints)
    last = len(constraints.s) - 1
    return tuple(
        _load(constraints, ratios, joints, point, point + 1)
        for point in (0, last)
        if ratios[point].max() > 1.0 and not any(item.start <= constraints.s[point] <= item.end for item in stretches)
    )


def blocked_even_at_rest(
    constraints: PathConstraints, blocking_rows: np.ndarray, empty: np.ndarray, point: int, where: str
) -> InfeasiblePath:
    """The error of a path whose grid ``empty`` (indices of intervals or points where a timing
    method finds no admissible state, not even rest) is not empty: ``not_even_at_rest``'s when
    holding still breaks the torque limits, else the limit rows that block at ``point``
    (``blocking_rows[point]``: the pair of row indices of ``admissible_set``), ``where`` naming
    the place in the method's words ("at s = 0.4000")."""
    stated = not_even_at_rest(constraints, empty)
    if stated is not None:
        return stated
    first, second = blocking_rows[point]
    what = constraints.describe_row(first)
    if second != first:
        what += f" and {constraints.describe_row(second)}"
    kind, joint = constraints.rows[first % len(constraints.rows)]
    return InfeasiblePath(
        f"no motion along the path can meet the {what} {where}, not even at rest",
        s=float(constraints.s[point]), joint=constraints.joint_names[joint], limit=kind,
    )
