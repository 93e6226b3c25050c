"""Request bodies of ``POST /v1/trajectories`` and ``POST /v1/trajectories/compare`` from Python
values, for ``Client.plan``, ``Client.compare``, jobs and batches. The service checks them (a
malformed one is a ``ProblemError`` with status 422 naming the field)."""

from __future__ import annotations

from typing import Any

import numpy as np

OUTPUT_FORMATS = ("samples", "joint_trajectory", "csv")


def plain(value: Any, where: str = "the body") -> Any:
    """``value`` with numpy arrays and scalars (and tuples) as JSON's lists and numbers, so that
    a request may hold what the client's own results give (``Robot.limits.velocity * 0.5``).

    Raises:
        ValueError: a NaN or infinite number, named by its place (``limits.velocity[2]``):
            JSON has neither.
    """
    if isinstance(value, dict):
        return {key: plain(item, f"{key}" if where == "the body" else f"{where}.{key}") for key, item in value.items()}
    if isinstance(value, np.ndarray):
        value = value.tolist()
    elif isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, (list, tuple)):
        return [plain(item, f"{where}[{k}]") for k, item in enumerate(value)]
    if isinstance(value, float) and not np.isfinite(value):
        raise ValueError(f"{where} is {value}: JSON has no NaN or infinity; give a finite number")
    return value


def _path(path: dict | None, waypoints: Any) -> dict:
    if (path is None) == (waypoints is None):
        raise ValueError("give either waypoints (joint configurations, one row each) or path (a request's path object)")
    if path is not None:
        return dict(path)
    return {"kind": "waypoints", "waypoints": rows_of(waypoints)}


def rows_of(values: Any) -> list:
    """Rows of joint values as JSON lists; rows of different lengths are sent row by row, for
    the service to name the row."""
    try:
        return np.asarray(values, dtype=float).tolist()
    except ValueError:
        return [np.asarray(row, dtype=float).tolist() for row in values]


def _timing(timing: dict | None, fields: dict[str, Any]) -> dict:
    """``timing`` with ``fields`` (the arguments given) added; a field given both ways with two
    different values is refused, since one of them would be dropped without a word."""
    given = {key: value for key, value in fields.items() if value is not None}
    for key, value in given.items():
        if timing is not None and key in timing and timing[key] != value:
            raise ValueError(
                f"{key}={value!r} conflicts with timing={{{key!r}: {timing[key]!r}}}: give {key} once, as the argument or in timing"
            )
    return {**(timing or {}), **given}


def trajectory_request(
    robot: str,
    waypoints: Any = None,
    *,
    path: dict | None = None,
    method: str | None = None,
    constraints: list[str] | None = None,
    limits: dict | None = None,
    duration: float | None = None,
    timing: dict | None = None,
    dt: float | None = None,
    format: str | None = None,
    exact_period: bool | None = None,
    payload: dict | None = None,
    mounting: dict | None = None,
) -> dict:
    """The body of ``POST /v1/trajectories``.

    Args:
        robot: A catalog or uploaded robot's name, e.g. ``"ur5"``.
        waypoints: Joint configurations (rad, m), shape (n_waypoints, n_dof), joined by a C2
            cubic spline; or give ``path``.
        path: A whole ``path`` object instead: ``{"kind": "waypoints", ...}``,
            ``{"kind": "cartesian", ...}`` or ``{"kind": "free", "start", "goal", ...}``.
        method: ``timing.method`` (``phase_plane`` by default on the service).
        constraints: ``timing.constraints``, e.g. ``["velocity", "acceleration", "torque"]``.
        limits: ``timing.limits``: per-joint overrides, ``*_scale`` factors, tool speeds.
        duration: ``timing.duration`` (s), for the classical time laws.
        timing: Any other ``timing`` fields (``boundary``, ``cost``, ``grid_points``, ...); a
            field also given as an argument above must have the same value.
        dt: ``output.dt``, the sample period (s); 0.01 on the service.
        format: ``output.format``: ``samples``, ``joint_trajectory`` or ``csv``.
        exact_period: ``output.exact_period``: samples on whole periods of ``dt``.
        payload: What the robot carries at its tool: ``{"mass": kg, "center_of_mass": [x, y,
            z], "inertia": [...], "frame": ..., "radius": m}`` (the request's ``payload``).
        mounting: The base pose and the world's gravity: ``{"position": [x, y, z],
            "orientation": [qx, qy, qz, qw] or "rotation": 3x3, "gravity": [gx, gy, gz]}``.

    Returns:
        The request as a JSON-ready dict.

    Raises:
        ValueError: Neither or both of ``waypoints`` and ``path``, an unknown ``format``, or a
            field given both as an argument and in ``timing`` with different values.
    """
    if format is not None and format not in OUTPUT_FORMATS:
        raise ValueError(f"format {format!r} is not one of {', '.join(OUTPUT_FORMATS)}")
    body: dict[str, Any] = {
        "robot": robot,
        "path": _path(path, waypoints),
        "timing": _timing(timing, {"method": method, "constraints": constraints, "limits": limits, "duration": duration}),
    }
    output = {key: value for key, value in {"dt": dt, "format": format, "exact_period": exact_period}.items() if value is not None}
    if output:
        body["output"] = output
    return body | _equipment(payload, mounting)


def _equipment(payload: dict | None, mounting: dict | None) -> dict:
    """The request's ``payload`` and ``mounting`` fields that are given."""
    return {key: dict(value) for key, value in (("payload", payload), ("mounting", mounting)) if value is not None}


def compare_request(
    robot: str,
    waypoints: Any = None,
    *,
    methods: list[str],
    path: dict | None = None,
    constraints: list[str] | None = None,
    limits: dict | None = None,
    timing: dict | None = None,
    payload: dict | None = None,
    mounting: dict | None = None,
) -> dict:
    """The body of ``POST /v1/trajectories/compare``: one path under each of ``methods`` (e.g.
    ``["phase_plane", "quintic"]``), with the constraints and limits every method shares; the
    other arguments are those of ``trajectory_request``; a ``timing`` ``method`` must be among
    ``methods`` (``ValueError`` otherwise: the service would refuse it)."""
    if timing is not None and "method" in timing and timing["method"] not in methods:
        raise ValueError(f"timing={{'method': {timing['method']!r}}} conflicts with methods={list(methods)}: add it to methods, or leave it out of timing")
    return {
        "robot": robot,
        "path": _path(path, waypoints),
        "methods": list(methods),
        "timing": _timing(timing, {"constraints": constraints, "limits": limits}),
    } | _equipment(payload, mounting)
