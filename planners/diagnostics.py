"""Words for failures: which joint cannot hold its load where along the path."""

from __future__ import annotations

import numpy as np

from toptraj.planners.constraints.path_constraints import PathConstraints


def static_load(constraints: PathConstraints, point: int) -> tuple[str, str | None, str | None]:
    """At grid point ``point``: a clause naming the joint whose torque at rest (gravity and
    friction) is the largest share of its limit, when that share exceeds 1 (else ""), that
    joint's name and the limit to blame, "torque" (both ``None`` without torque rows)."""
    torque_rows = [k for k, (kind, _) in enumerate(constraints.rows) if kind == "torque"]
    if not torque_rows:
        return "", None, None
    load = np.abs(constraints.c[point, torque_rows]) / constraints.upper[point, torque_rows]
    worst = torque_rows[int(np.argmax(load))]
    joint = constraints.joint_names[constraints.rows[worst][1]]
    if load.max() <= 1.0:
        return "", joint, "torque"
    return (
        f": holding still at s = {constraints.s[point]:.4f} needs {abs(constraints.c[point, worst]):.4g} N m "
        f"on joint {joint!r}, above its limit of {constraints.upper[point, worst]:.4g} N m",
        joint,
        "torque",
    )
