"""Zones as a caller gives them, and where they lie on a given path.

A ``Zone`` is an s-range of the path or a region of the workspace (a sphere or an oriented box,
world frame, m) that the tool point (the origin of the tool frame) is inside, with its own
factors on the robot's velocity, acceleration and torque limits and its own largest tool speed.
``zone_limits`` finds where each region lies on the path: the tool point's position p(s) by
forward kinematics at ``SCAN_POINTS`` values of s, then every change between inside and outside
located by bisection to ``EDGE_TOLERANCE`` in s. The result, closed s-ranges per zone, is what
the timing holds (``toptraj.robots.LimitZone``, ``toptraj.planners.constraints.zones``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from toptraj.planners.collision.obstacles import UNIT_TOLERANCE, BoxObstacle, SphereObstacle, check_obstacles
from toptraj.planners.errors import InvalidRequest
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.planners.paths.base import GeometricPath
from toptraj.robots import LimitZone, Robot
from toptraj.robots.notes import Note

#: Most zones of one request.
MAX_ZONES = 32
#: Values of s, evenly spread, at which the tool point is tested against the regions.
SCAN_POINTS = 2001
#: Seconds the forward kinematics of one point takes, about twice the 4 to 10 us measured on
#: ur5 (a region's scan: 9 to 21 ms): what ``Deadline.expect`` is told before a scan.
FK_SECONDS = 2e-5
#: Width in s to which bisection locates a region's edge.
EDGE_TOLERANCE = 1e-9
#: Most s-ranges of all zones together (each edge becomes a grid point).
MAX_RANGES = 128
#: Timing methods that hold zones (limits that vary along the path, on the constraints' grid).
ZONE_METHODS = ("phase_plane", "toppra")


@dataclass(frozen=True)
class Zone:
    """Limits of their own on part of the path.

    Attributes:
        s_range: (s0, s1) with 0 <= s0 < s1 <= 1, the part of the path; or ``None`` with a
            ``region``.
        region: A sphere or box (world frame) the tool point is inside; or ``None``.
        velocity, acceleration, torque: Factors in (0, 1] on the robot's limits of that kind
            (after the request's overrides and scales); ``None``: 1.
        tool_speed: Largest linear speed of the tool frame's origin (m/s); ``None``: none.
    """

    s_range: tuple[float, float] | None = None
    region: SphereObstacle | BoxObstacle | None = None
    velocity: float | None = None
    acceleration: float | None = None
    torque: float | None = None
    tool_speed: float | None = None


def _refused(field: str, sentence: str, **facts) -> InvalidRequest:
    """The refusal of a zone: ``field`` in the library's names (``zones[i]...``), the library's
    ``sentence``; a ``rule`` among ``facts`` lets the service word it in its request's terms."""
    return InvalidRequest(field, facts.pop("value", None), detail=sentence, **facts)


def check_zones(zones: tuple[Zone, ...]) -> None:
    """InvalidRequest naming the zone unless there are at most ``MAX_ZONES``, each with exactly
    one of an s-range within [0, 1] (s0 < s1) and a region, at least one limit, factors in
    (0, 1] and a positive finite tool speed."""
    if len(zones) > MAX_ZONES:
        raise _refused("zones", f"{len(zones)} zones are given; at most {MAX_ZONES} are served (merge neighbouring ones)")
    for index, zone in enumerate(zones):
        if (zone.s_range is None) == (zone.region is None):
            raise _refused(f"zones[{index}]", f"zone {index} needs exactly one of an s-range and a region (sphere or box)")
        if zone.s_range is not None:
            s0, s1 = (float(value) for value in zone.s_range)
            if not (0.0 <= s0 < s1 <= 1.0):
                raise _refused(f"zones[{index}].s_range", f"zone {index} has the s-range [{s0:g}, {s1:g}]; give 0 <= s0 < s1 <= 1")
        else:
            _check_region(index, zone.region)
        factors = {"velocity": zone.velocity, "acceleration": zone.acceleration, "torque": zone.torque}
        if all(value is None for value in (*factors.values(), zone.tool_speed)):
            raise _refused(f"zones[{index}]", f"zone {index} sets no limit; give a velocity, acceleration or torque factor or a tool speed")
        for name, value in factors.items():
            if value is not None and not (0.0 < value <= 1.0):
                raise _refused(f"zones[{index}].{name}", f"zone {index} has a {name} factor of {value:g}; a zone's factors lie in (0, 1]")
        if zone.tool_speed is not None and not (0.0 < zone.tool_speed < math.inf):
            raise _refused(f"zones[{index}].tool_speed", f"zone {index} has a tool speed of {zone.tool_speed:g} m/s; give a positive finite speed")


def check_zones_held(zones: tuple[Zone, ...], kinds: tuple[str, ...]) -> None:
    """InvalidRequest naming the first zone whose factor scales a kind of limit that ``kinds``
    (the limits the timing holds) leaves out: that limit would be neither held nor its zone's."""
    for index, zone in enumerate(zones):
        for kind in ("velocity", "acceleration", "torque"):
            if getattr(zone, kind) is not None and kind not in kinds:
                raise _refused(
                    f"zones[{index}].{kind}",
                    f"zone {index} scales the {kind} limit, which is not among the limits held ({', '.join(kinds)}): "
                    f"hold {kind} too, or leave the zone's {kind} factor out",
                    rule="zone_kind_not_held", index=index, kind=kind, value=getattr(zone, kind), kinds_held=tuple(kinds),
                )


def _check_region(index: int, region) -> None:
    """InvalidRequest naming the zone unless its region is a sphere of positive radius or a
    box of positive edges with a unit orientation."""
    if isinstance(region, SphereObstacle):
        if not (0.0 < region.radius < math.inf and np.isfinite(region.center).all()):
            raise _refused(f"zones[{index}].sphere", f"zone {index}'s sphere needs a finite center and a positive radius, got {region.radius:g}")
        return
    if not (np.shape(region.size) == (3,) and np.all(np.asarray(region.size) > 0.0) and np.isfinite(region.center).all()):
        raise _refused(f"zones[{index}].box", f"zone {index}'s box needs a finite center and three positive edge lengths")
    try:
        check_obstacles([region])
    except InvalidRequest:
        norm = float(np.linalg.norm(np.asarray(region.orientation, dtype=float)))
        raise _refused(
            f"zones[{index}].box.orientation", f"zone {index}'s box orientation has norm {norm:.6g}, not a unit quaternion [qx, qy, qz, qw]",
            rule="zone_box_not_unit", index=index, norm=norm, tolerance=UNIT_TOLERANCE,
        ) from None


def contains(region: SphereObstacle | BoxObstacle, points: np.ndarray) -> np.ndarray:
    """(n,) bool: which of ``points`` (n, 3), world frame (m), lie in the closed ``region``."""
    offset = np.atleast_2d(points) - np.asarray(region.center, dtype=float)
    if isinstance(region, SphereObstacle):
        return np.einsum("ij,ij->i", offset, offset) <= region.radius**2
    local = offset @ region.rotation  # the offsets in the box's axes
    return np.all(np.abs(local) <= 0.5 * np.asarray(region.size, dtype=float), axis=1)


def distance_outside(region: SphereObstacle | BoxObstacle, points: np.ndarray) -> np.ndarray:
    """(n,) the Euclidean distance (m) of each of ``points`` (n, 3), world frame, from the closed
    ``region``; 0 inside it."""
    offset = np.atleast_2d(points) - np.asarray(region.center, dtype=float)
    if isinstance(region, SphereObstacle):
        return np.maximum(np.linalg.norm(offset, axis=1) - region.radius, 0.0)
    beyond = np.maximum(np.abs(offset @ region.rotation) - 0.5 * np.asarray(region.size, dtype=float), 0.0)
    return np.linalg.norm(beyond, axis=1)


def tool_points(robot: Robot, path: GeometricPath, frame_id: int, s: np.ndarray) -> np.ndarray:
    """(n, 3): the origin of frame ``frame_id`` in the world at the path's points ``q(s)``."""
    q = path.evaluate(np.asarray(s, dtype=float), "right").q
    model, data = robot.model, robot.data
    out = np.empty((len(q), 3))
    for row, point in enumerate(q):
        pin.framesForwardKinematics(model, data, robot.configuration(point))
        out[row] = data.oMf[frame_id].translation
    return out


def region_ranges(robot: Robot, path: GeometricPath, frame_id: int, region: SphereObstacle | BoxObstacle, deadline: Deadline = NO_DEADLINE) -> tuple[tuple[float, float], ...]:
    """The closed s-ranges over which the tool point lies in ``region``: scanned at
    ``SCAN_POINTS`` values of s, each edge located by bisection to ``EDGE_TOLERANCE``. A visit
    shorter than the scan's step (1 / 2000 of s) may be missed."""
    s = np.linspace(0.0, 1.0, SCAN_POINTS)
    deadline.check()
    deadline.expect(SCAN_POINTS * FK_SECONDS)
    flags = contains(region, tool_points(robot, path, frame_id, s))
    edges = []
    for i in np.flatnonzero(flags[1:] != flags[:-1]):
        deadline.check()
        low, high = s[i], s[i + 1]  # flags[low] != flags[high]
        while high - low > EDGE_TOLERANCE:
            middle = 0.5 * (low + high)
            if contains(region, tool_points(robot, path, frame_id, np.array([middle])))[0] == flags[i]:
                low = middle
            else:
                high = middle
        edges.append(high if not flags[i] else low)  # the edge's side inside the region
    bounds = ([0.0] if flags[0] else []) + edges + ([1.0] if flags[-1] else [])
    return tuple((float(a), float(b)) for a, b in zip(bounds[::2], bounds[1::2]))


def zone_limits(robot: Robot, path: GeometricPath, zones: tuple[Zone, ...], frame_id: int, deadline: Deadline = NO_DEADLINE) -> tuple[tuple[LimitZone, ...], tuple[Note, ...]]:
    """The zones on ``path`` as the timing holds them: s-ranges as given, regions where the
    origin of frame ``frame_id`` lies in them (``region_ranges``); a region the path never enters
    keeps no range and limits nothing, and a note says so (``missed_region``)."""
    limited: list[LimitZone] = []
    notes: list[Note] = []
    for index, zone in enumerate(zones):
        if zone.s_range is not None:
            ranges: tuple[tuple[float, float], ...] = ((float(zone.s_range[0]), float(zone.s_range[1])),)
        else:
            assert zone.region is not None  # check_zones: an s-range or a region, exactly one
            ranges = region_ranges(robot, path, frame_id, zone.region, deadline)
            if not ranges:
                notes.append(missed_region(robot, path, frame_id, index, zone.region, deadline))
        if sum(len(item.ranges) for item in limited) + len(ranges) > MAX_RANGES:
            raise _refused(
                f"zones[{index}]",
                f"the zones cover more than {MAX_RANGES} stretches of the path from zone {index} on (a region the "
                "tool point enters and leaves many times); give fewer or larger regions, or s-ranges",
                rule="zone_ranges_too_many", index=index, most=MAX_RANGES,
            )
        limited.append(LimitZone(
            index=index,
            ranges=ranges,
            velocity=1.0 if zone.velocity is None else float(zone.velocity),
            acceleration=1.0 if zone.acceleration is None else float(zone.acceleration),
            torque=1.0 if zone.torque is None else float(zone.torque),
            tool_speed=math.inf if zone.tool_speed is None else float(zone.tool_speed),
        ))
    return tuple(limited), tuple(notes)


def missed_region(robot: Robot, path: GeometricPath, frame_id: int, index: int, region: SphereObstacle | BoxObstacle,
                  deadline: Deadline = NO_DEADLINE) -> Note:
    """The note of zone ``index``, whose ``region`` the origin of frame ``frame_id`` never enters
    along ``path``: the frame, the region's kind and the closest approach, the smallest
    ``distance_outside`` (m) at ``SCAN_POINTS`` values of s and the s where it lies."""
    s = np.linspace(0.0, 1.0, SCAN_POINTS)
    deadline.check()
    deadline.expect(SCAN_POINTS * FK_SECONDS)
    distances = distance_outside(region, tool_points(robot, path, frame_id, s))
    closest = int(np.argmin(distances))
    kind = "sphere" if isinstance(region, SphereObstacle) else "box"
    frame = robot.model.frames[frame_id].name
    return Note(
        f"zone {index} limits nothing: the origin of frame {frame!r} never enters its {kind} (closest "
        f"{distances[closest]:.4g} m outside, at s = {s[closest]:.4f})",
        "missed_region", index=index, region=kind, frame=frame, distance=float(distances[closest]), at_s=float(s[closest]),
    )


def check_zones_served(method_name: str, given_path: bool) -> None:
    """InvalidRequest unless ``method_name`` holds zones on a given path (``ZONE_METHODS``)."""
    if method_name not in ZONE_METHODS or not given_path:
        raise _refused(
            "zones",
            f"zones are held by the timing methods {', '.join(ZONE_METHODS)} along a given path (waypoints "
            f"interpolated by spline, linear or blend, or a cartesian line), not by {method_name!r} here; "
            "use one of those, or leave the zones out",
            rule="zones_not_served", method=method_name, methods=ZONE_METHODS,
        )
