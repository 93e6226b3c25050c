"""Zones: limits of their own on part of a path, held in one timing of the whole path.

A zone (``toptraj.robots.LimitZone``) covers closed s-ranges of the path; there the robot's
velocity, acceleration and torque limits are multiplied by the zone's factors and the tool
frame's origin keeps below the zone's speed. Where zones overlap the tightest of each holds.
Every limit thus becomes a function of s, evaluated point by point:

    v_j(s) = f_v(s) v_j,   a_j(s) = f_a(s) a_j,   tau_j(s) = f_tau(s) tau_j,
    |v_tool| <= min(v_tool, v_zone(s)),

so that the first-order bound sd_max (Jeong & Lee eq. (3.4b): sd <= v_j / |q'_j|, linear in the
limit) is scaled by f_v(s) where joints set it, and the bounds of the second-order rows by
f_a(s) or f_tau(s) (``toptraj.planners.constraints.path_constraints``). The dense limit check
compares each state with the limits at its own s, between grid points too
(``toptraj.planners.checks.limit_check``), and a zone's edges are grid points (``with_edges``),
so that the grid resolves where its limits start and stop.
"""

from __future__ import annotations

import dataclasses
from typing import NamedTuple

import numpy as np

from toptraj.robots import JointLimits, LimitZone

#: Share of a zone's limit that its peak inside the zone must reach for the zone to bind.
BINDING_SHARE = 0.995


class ZoneFactors(NamedTuple):
    """Per-point limits of the zones at n values of s: factors on the robot's velocity,
    acceleration and torque limits (1 outside every zone) and the tool's largest linear speed
    (m/s; ``inf`` where no zone limits it), each (n,)."""

    velocity: np.ndarray
    acceleration: np.ndarray
    torque: np.ndarray
    tool_speed: np.ndarray


def inside(zone: LimitZone, s: np.ndarray) -> np.ndarray:
    """(n,) bool: which of ``s`` (n,) lie in one of the zone's closed ranges."""
    mask = np.zeros(len(s), dtype=bool)
    for start, end in zone.ranges:
        mask |= (s >= start) & (s <= end)
    return mask


def zone_factors(zones: tuple[LimitZone, ...], s: np.ndarray) -> ZoneFactors:
    """The tightest limits of ``zones`` at each of ``s`` (``ZoneFactors``)."""
    s = np.asarray(s, dtype=float)
    factors = ZoneFactors(np.ones(len(s)), np.ones(len(s)), np.ones(len(s)), np.full(len(s), np.inf))
    for zone in zones:
        mask = inside(zone, s)
        for array, value in zip(factors, (zone.velocity, zone.acceleration, zone.torque, zone.tool_speed)):
            array[mask] = np.minimum(array[mask], value)
    return factors


def has_tool_zone(limits: JointLimits) -> bool:
    """Whether a zone of ``limits`` limits the tool's speed."""
    return any(np.isfinite(zone.tool_speed) for zone in limits.zones)


def tool_speed_at(limits: JointLimits, s: np.ndarray, factors: ZoneFactors | None = None) -> np.ndarray:
    """(n,) the tool's largest linear speed (m/s) at each of ``s``: the request's, or a zone's
    where lower; ``inf`` where neither limits it."""
    factors = zone_factors(limits.zones, s) if factors is None else factors
    speed = np.inf if limits.tool is None else limits.tool.speed
    return np.minimum(speed, factors.tool_speed)


def zoned_rows(rows: tuple[tuple[str, int], ...], lower: np.ndarray, upper: np.ndarray, factors: ZoneFactors) -> tuple[np.ndarray, np.ndarray]:
    """The bounds ``lower, upper`` ((n, m), labelled by ``rows``) of the second-order rows with
    each acceleration row's multiplied by f_a(s) and each torque row's by f_tau(s)."""
    scale = np.ones_like(upper)
    for column, (kind, _) in enumerate(rows):
        scale[:, column] = factors.acceleration if kind == "acceleration" else factors.torque
    return lower * scale, upper * scale


def on_stretch(limits: JointLimits, start: float, width: float) -> JointLimits:
    """``limits`` with the zones' ranges carried into the parameter sigma = (s - start) / width
    of a stretch of the path (clipped to [0, 1]; a zone that misses the stretch is dropped)."""
    if not limits.zones:
        return limits
    zones = []
    for zone in limits.zones:
        ranges = tuple(
            (max(0.0, (a - start) / width), min(1.0, (b - start) / width))
            for a, b in zone.ranges if b >= start and a <= start + width
        )
        if ranges:
            zones.append(dataclasses.replace(zone, ranges=ranges))
    return dataclasses.replace(limits, zones=tuple(zones))


def with_edges(s: np.ndarray, zones: tuple[LimitZone, ...], knots: np.ndarray) -> np.ndarray:
    """The grid ``s`` (increasing, from 0 to 1) holding every edge of the zones' ranges: a grid
    point within a quarter of its interval of an edge moves onto it (never a knot nor an end),
    else the edge is inserted; the grid keeps its size up to the edges inserted."""
    edges = np.unique([edge for zone in zones for rng in zone.ranges for edge in rng])
    s = np.array(s, dtype=float)
    for edge in edges[(edges > 0.0) & (edges < 1.0)]:
        i = int(np.searchsorted(s, edge))
        if s[i] == edge:
            continue
        below, above = s[i - 1], s[i]
        quarter = 0.25 * (above - below)
        movable = [j for j, gap in ((i - 1, edge - below), (i, above - edge))
                   if gap < quarter and 0 < j < len(s) - 1 and not np.isin(s[j], knots) and not np.isin(s[j], edges)]
        if movable:
            s[movable[0]] = edge
        else:
            s = np.insert(s, i, edge)
    return s


def zone_peaks(zones: tuple[LimitZone, ...], s: np.ndarray, ratios: dict[str, np.ndarray]) -> dict[int, float]:
    """{zone index: the largest ratio, inside the zone, of each quantity the zone limits to the
    zone's own limit}, from ``ratios`` at the states ``s`` (n,), each (n,): per kind
    ("velocity", "acceleration", "torque") the worst joint's |value| / the robot's limit, and
    ("tool_speed") the tool's linear speed in m/s. 1.0: the zone's limit binds there."""
    peaks = {}
    for zone in zones:
        mask = inside(zone, s)
        limited = [(kind, value) for kind, value in (("velocity", zone.velocity), ("acceleration", zone.acceleration),
                                                     ("torque", zone.torque), ("tool_speed", zone.tool_speed))
                   if kind in ratios and (value != 1.0 if kind != "tool_speed" else np.isfinite(value))]
        values = [float(ratios[kind][mask].max()) / value for kind, value in limited if mask.any()]
        peaks[zone.index] = max(values, default=0.0)
    return peaks
