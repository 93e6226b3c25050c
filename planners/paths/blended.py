"""Straight joint segments joined by circular blends (Kunz & Stilman, "Time-Optimal Trajectory
Generation for Path Following with Bounded Acceleration and Velocity", RSS 2012, section IV),
the path MoveIt's time-optimal trajectory generation (TOTG) follows.

At an interior waypoint q_i, with unit directions y_i = (q_i - q_i-1) / |q_i - q_i-1| and
y_i+1 of the segments that meet there and the angle alpha_i = arccos(y_i . y_i+1) between them,
a circle tangent to both segments replaces the corner. It touches each segment at the distance

    l_i = min(|q_i - q_i-1| / 2, |q_i+1 - q_i| / 2, delta sin(alpha_i / 2) / (1 - cos(alpha_i / 2)))

from the waypoint (eq. (3); the last term keeps the circle within ``delta`` of the waypoint:
the deviation of the circle is l_i (1 - cos(alpha_i / 2)) / sin(alpha_i / 2)), has the radius
r_i = l_i / tan(alpha_i / 2) (eq. (4)) and the center
c_i = q_i + (y_i+1 - y_i) / |y_i+1 - y_i| r_i / cos(alpha_i / 2) (eq. (5)). Half a segment at
most goes to each of its two blends, so the blends never overlap.

The path is parameterized by arc length sigma (|dq/dsigma| = 1), and s = sigma / L for the total
length L. On a circle of radius r, with x and y the unit vectors from its center to its start
and along its start tangent and theta = sigma_local / r,

    q = c + r (x cos theta + y sin theta),          dq/dsigma = -x sin theta + y cos theta,
    d2q/dsigma2 = -(x cos theta + y sin theta) / r,  d3q/dsigma3 = (x sin theta - y cos theta) / r^2,

so dq/ds is continuous everywhere and d2q/ds2 jumps where a line meets a circle (``breaks``: the
motion does not stop there, but the limits seen from either side differ). A corner that turns
back on itself (alpha = pi) cannot be blended and is a corner where the motion stops
(``kinks``), as is one whose blend's radius would be below ``MIN_BLEND`` of the path
(``tight_corners`` names those, for a note in the answer).
"""

from __future__ import annotations

import numpy as np

from toptraj.planners.paths.base import GeometricPath, PathPoints

#: 1 - cos(alpha) below this: the segments continue straight on (no blend needed, the direction
#: changes by less than 1.5e-6 rad).
STRAIGHT = 1e-12
#: A blend whose radius is below this fraction of the path is a corner where the motion stops:
#: its curvature, L / radius in s, outruns what the timing grids resolve (max_deviation 1e-9 rad
#: on a UR5 path exceeded the acceleration limit by 23 %, and min_cost's solver failed up to
#: 1e-6 of the path), and the speed it allows, sqrt(acceleration limit x radius), is nearly a
#: stop. The radius, not the blend's length, decides: a corner between two short segments that
#: turns by little (a dense recording of a smooth curve) has a short blend of a large radius,
#: which the motion follows at speed.
MIN_BLEND = 1e-5
#: Distance (relative to the path's length) below which two points are one: a rounding.
SAME_POINT = 1e-12
#: Shortest line a blend leaves before it (relative to the path's length): a blend that would
#: leave a shorter one shrinks, by at most half and keeping its radius above ``MIN_BLEND``
#: (toppra's grid failed on a line of 7.6e-8 of the path between two blends of a dense
#: recording). A line may still come out shorter where the blend cannot shrink so far.
MIN_LINE = 1e-5


class BlendedPath(GeometricPath):
    """Straight segments between the waypoints, each corner replaced by a circular arc that
    stays within ``max_deviation`` of it (joint-space norm, joint units).

    Args:
        waypoints: Shape (n_waypoints, n_dof), no two consecutive ones equal, in joint units.
        max_deviation: Largest distance of a blend from its waypoint (delta), > 0.

    Attributes:
        length: Total arc length L in joint space (joint units).
        deviations: Distance of each interior waypoint from its blend, shape (n_waypoints - 2,)
            (0 where the path passes the waypoint: a straight continuation or a stop).
        tight_by_deviation: Those of ``tight_corners`` whose blend ``max_deviation`` limits
            (the others are limited by half of a segment beside them).
        tight_corners: Indices of the waypoints whose blend's radius would be below
            ``MIN_BLEND`` of the path: corners where the motion stops.
    """

    def __init__(self, waypoints: np.ndarray, max_deviation: float):
        waypoints = np.asarray(waypoints, dtype=float)
        self.waypoints = waypoints
        self.dof = waypoints.shape[1]
        self.max_deviation = float(max_deviation)
        pieces, corners, deviations, tight, by_deviation = _pieces(waypoints, self.max_deviation)
        self._pieces = pieces
        piece_lengths = np.array([piece[-1] for piece in pieces])
        self.length = float(piece_lengths.sum())
        self.knots = np.concatenate(([0.0], np.cumsum(piece_lengths) / self.length))
        self.knots[-1] = 1.0
        # corners[k]: whether the junction after piece k is a stop.
        junctions = self.knots[1:-1]
        stop = np.array(corners[: len(junctions)], dtype=bool)
        self.kinks = junctions[stop]
        self.breaks = junctions[~stop]
        self.deviations = np.array(deviations)
        self.tight_corners = tuple(tight)
        self.tight_by_deviation = tuple(by_deviation)
        self._is_arc = np.array([piece[0] == "arc" for piece in pieces])
        n_pieces = len(pieces)
        # Per piece: origin and direction (lines) or center, x, y (arcs), and the radius.
        self._a = np.zeros((n_pieces, self.dof))
        self._b = np.zeros((n_pieces, self.dof))
        self._c = np.zeros((n_pieces, self.dof))
        self._radius = np.ones(n_pieces)
        for k, piece in enumerate(pieces):
            if piece[0] == "line":
                self._a[k], self._b[k] = piece[1], piece[2]
            else:
                self._a[k], self._b[k], self._c[k], self._radius[k] = piece[1], piece[2], piece[3], piece[4]

    def _locate(self, s, side):
        s = np.clip(np.atleast_1d(np.asarray(s, dtype=float)), 0.0, 1.0)
        piece = np.searchsorted(self.knots, s, side="left" if side == "left" else "right") - 1
        piece = np.clip(piece, 0, len(self._pieces) - 1)
        local = np.clip((s - self.knots[piece]) * self.length, 0.0, (self.knots[piece + 1] - self.knots[piece]) * self.length)
        return piece, local

    def _derivatives(self, s, side, orders):
        """q and its sigma-derivatives up to ``orders`` - 1 (arc-length parameter), each (n, n_dof)."""
        piece, local = self._locate(s, side)
        arc = self._is_arc[piece][:, None]
        radius = self._radius[piece][:, None]
        theta = local[:, None] / radius
        cos, sin = np.cos(theta), np.sin(theta)
        a, b, c = self._a[piece], self._b[piece], self._c[piece]
        # Lines: q = a + b sigma. Arcs: a = center, b = x, c = y.
        radial = b * cos + c * sin
        tangent = -b * sin + c * cos
        values = [
            np.where(arc, a + radius * radial, a + b * local[:, None]),
            np.where(arc, tangent, b),
            np.where(arc, -radial / radius, 0.0),
            np.where(arc, -tangent / radius**2, 0.0),
        ]
        return values[:orders]

    def evaluate(self, s: np.ndarray, side: str = "right") -> PathPoints:
        q, dq, ddq = self._derivatives(s, side, 3)
        return PathPoints(q, dq * self.length, ddq * self.length**2)

    def third_derivative(self, s: np.ndarray, side: str = "right") -> np.ndarray:
        return self._derivatives(s, side, 4)[3] * self.length**3


def _pieces(waypoints: np.ndarray, max_deviation: float) -> tuple[list, list, list, list, list]:
    """The path's pieces through ``waypoints`` (n, n_dof), each (kind, start point, direction or
    x, y, center, radius, length) with kind "line" or "arc"; whether the junction after each is
    a stop; each interior waypoint's distance from its blend; the corners left unblended, and
    those of them ``max_deviation`` limits."""
    segments = np.diff(waypoints, axis=0)
    lengths = np.linalg.norm(segments, axis=1)
    directions = segments / lengths[:, None]
    scale = lengths.sum()
    pieces, corners, deviations, tight, by_deviation = [], [], [], [], []
    position = waypoints[0]
    for i in range(1, len(waypoints) - 1):
        blend = _blend(waypoints[i], directions[i - 1], directions[i], lengths[i - 1], lengths[i], max_deviation)
        tight_here = blend is not None and blend[3] <= MIN_BLEND * scale
        if tight_here:
            tight.append(i)
            # A larger deviation rounds it: the blend that takes half the shorter segment is wide enough.
            if 0.5 * min(lengths[i - 1], lengths[i]) / np.tan(0.5 * blend[4]) > MIN_BLEND * scale:
                by_deviation.append(i)
        if blend is None or tight_here:
            # Straight on (the segments are one line), or a corner that cannot be blended.
            reverse = directions[i - 1] @ directions[i] < 1.0 - STRAIGHT
            pieces.append(_line(position, waypoints[i]))
            corners.append(reverse)
            position = waypoints[i]
            deviations.append(0.0)
            continue
        center, x, y, radius, angle, distance = blend
        start = waypoints[i] - distance * directions[i - 1]
        gap = float(np.linalg.norm(start - position))
        if SAME_POINT * scale < gap < MIN_LINE * scale and distance - (MIN_LINE * scale - gap) > 0.5 * distance:
            # A sliver of line before this blend: it shrinks (by at most half, its radius staying
            # above MIN_BLEND) to leave a line of MIN_LINE.
            smaller = _blend(waypoints[i], directions[i - 1], directions[i], lengths[i - 1], lengths[i], max_deviation,
                             most=distance - (MIN_LINE * scale - gap))
            if smaller is not None and smaller[3] > MIN_BLEND * scale:
                center, x, y, radius, angle, distance = smaller
                start = waypoints[i] - distance * directions[i - 1]
        # The straight piece up to the blend, however short (a short first segment: the path
        # must leave the first waypoint); only a gap of a rounding is closed by the arc itself.
        if np.linalg.norm(start - position) > SAME_POINT * scale:
            pieces.append(_line(position, start))
            corners.append(False)
        pieces.append(("arc", center, x, y, radius, angle * radius))
        corners.append(False)
        position = center + radius * (x * np.cos(angle) + y * np.sin(angle))
        deviations.append(float(np.linalg.norm(center - waypoints[i]) - radius))
    pieces.append(_line(position, waypoints[-1]))
    return pieces, corners, deviations, tight, by_deviation


def _line(start: np.ndarray, end: np.ndarray):
    span = end - start
    length = float(np.linalg.norm(span))
    return ("line", start, span / length if length > 0 else np.zeros_like(span), length)


def _blend(corner, incoming, outgoing, before, after, max_deviation, most=np.inf):
    """(center, x, y, radius, angle, distance) of the circle that replaces the corner at
    ``corner`` between unit directions ``incoming`` and ``outgoing`` (segments of lengths
    ``before`` and ``after``), or ``None`` when the segments continue straight on or turn back."""
    cosine = float(np.clip(incoming @ outgoing, -1.0, 1.0))
    if cosine > 1.0 - STRAIGHT or cosine < -1.0 + STRAIGHT:
        return None
    angle = np.arccos(cosine)
    half = 0.5 * angle
    distance = min(0.5 * before, 0.5 * after, max_deviation * np.sin(half) / (2.0 * np.sin(0.5 * half) ** 2), most)
    radius = distance / np.tan(half)
    bisector = outgoing - incoming
    center = corner + bisector / np.linalg.norm(bisector) * radius / np.cos(half)
    start = corner - distance * incoming
    x = (start - center) / np.linalg.norm(start - center)
    return center, x, incoming, radius, angle, distance
