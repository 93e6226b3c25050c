"""Facts for failures: which joint cannot hold its load where along the path."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from toptraj.planners.constraints.path_constraints import PathConstraints


class HeldLoad(NamedTuple):
    """At path parameter ``s``, holding still needs ``torque`` (N m, N for a prismatic joint)
    on ``joint``, above its ``limit``."""

    s: float
    torque: float
    joint: str
    limit: float


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
    held = HeldLoad(float(constraints.s[point]), float(abs(constraints.c[point, worst])), joint, float(constraints.upper[point, worst]))
    return held, joint, "torque"
