"""Every 200 holds the limits it was asked to hold: a check of a trajectory answer against its
request, read from the answer alone (the fuzz tests call it on every 200)."""

from __future__ import annotations

import numpy as np

from toptraj import robots
from toptraj.planners.problem.requests import DEFAULT_KINDS
from toptraj.planners.timing import METHODS

#: Largest |value| / limit a 200 may show (the project's promise: 0.5 %).
LIMIT_SHARE = 1.005
#: Limit kinds a method applies whether asked or not.
REQUIRED_KINDS = {"jerk_limited": {"jerk"}, "ruckig": {"jerk"}, "min_cost": {"torque"}}


def asked_limits(body: dict, method: str) -> dict[str, np.ndarray]:
    """The limits a trajectory request asks ``method`` to hold, by kind: the robot's catalog
    limits, each replaced by the request's per-joint override and multiplied by its scale, for
    the asked kinds (left out: those of velocity, acceleration and torque the method holds) and
    those the method applies always."""
    catalog = robots.load(body["robot"]).limits
    timing = body.get("timing") or {}
    request = timing.get("limits") or {}
    # Left out, timing.constraints means the defaults the method holds (the answer warns of the rest).
    served = METHODS[method].kinds if method in METHODS else DEFAULT_KINDS
    asked = timing.get("constraints") or [kind for kind in DEFAULT_KINDS if kind in served]
    kinds = set(asked) | REQUIRED_KINDS.get(method, set())
    limits = {}
    for kind in kinds:
        value = np.asarray(request[kind] if request.get(kind) is not None else getattr(catalog, kind), dtype=float)
        limits[kind] = value * (request.get(f"{kind}_scale") or 1.0)
    return limits


def assert_limits_held(body: dict, answer: dict) -> None:
    """A 200 holds the limits it was asked to hold within ``LIMIT_SHARE``: the peak utilization
    it states, every returned sample (velocities, accelerations, torques), and, at sample periods
    of 10 ms and below, the differences of the returned velocities (an acceleration reached
    between two samples) and, under a jerk limit, of the returned accelerations. A comparison's
    method that failed (its ``error``) has nothing to check."""
    if answer.get("error") is not None:
        return
    limits = asked_limits(body, answer["method"])
    for kind in limits:
        peaks = [peak for peak in answer["peak_utilization"].get(kind) or () if peak is not None]
        assert max(peaks, default=0.0) <= LIMIT_SHARE, (kind, peaks, answer["method"])
    if "samples" not in answer:
        return
    t, qd, qdd, tau = (np.asarray(answer["samples"][key], dtype=float) for key in ("t", "qd", "qdd", "tau"))
    steps = np.diff(t)
    even = (steps > 0.5 * np.median(steps)) & (steps <= 0.01) if steps.size else np.zeros(0, dtype=bool)
    checks = [
        ("velocity", "velocity", qd),
        ("acceleration", "acceleration", qdd),
        ("torque", "torque", tau),
        ("acceleration", "velocity differences", np.diff(qd, axis=0)[even] / steps[even][:, None]),
        ("jerk", "acceleration differences", np.diff(qdd, axis=0)[even] / steps[even][:, None]),
    ]
    for kind, what, values in checks:
        if kind in limits and values.size:
            ratio = float(np.max(np.abs(values) / limits[kind]))
            assert ratio <= LIMIT_SHARE, (what, kind, ratio, answer["method"])
