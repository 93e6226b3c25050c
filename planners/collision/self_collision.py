"""Self-collision: the arm's links against each other along a path, on the link capsules of
``toptraj.robots.collision`` (each contains its link's collision mesh, so a path the capsules
keep apart keeps the meshes apart).

Pairs checked: every two capsules of different links, except links moved by the same joint
(rigid together), by a joint and its parent joint (adjacent: they touch at the joint) and the
allowed pairs: the robot's own list (an upload's SRDF ``disable_collisions``), the SRDF
example-robot-data ships for a catalog arm, and the pairs whose capsules touch at the zero
pose (the capsules are larger than the meshes; such a pair would refuse every path). An
allowed pair covers the links fixed to either of its links (moved by the same joint): ur5's
SRDF allows wrist_1_link against wrist_3_link, and so against ee_link, fixed to wrist_3_link.

The distance of a pair changes only by the motion of one link relative to the other: each
joint between them (on the chain from one link to the other) turns the farther link about its
axis, moving its points by at most R |dq_j| (R: the reach bound of
``toptraj.planners.collision.clearance``), each joint once. Between samples at distances d_a,
d_b with L = R sum_j |dq_j|, the distance stays above (d_a + d_b - L) / 2. Intervals where that bound falls below zero are split in
four until it holds or the motion across one is below ``RESOLUTION``; a sample in contact is
reported at its s, the first along the path. A path never certified within
``MAX_CONFIGURATIONS`` samples is refused at the first uncertain interval.

Conservative: each capsule contains its link's collision mesh, so a path the check accepts
keeps the meshes apart (no touching path is accepted), but a path is refused as soon as the
capsules touch, while the meshes may still be apart by up to the capsules' padding. Measured by
coal on the collision meshes (the smallest mesh distance of two links whose capsules touch, over
sampled configurations): ur5 up to 0.097 m (its elbow fold is refused 0.078 m early, shoulder_link
against forearm_link), panda up to 0.13 m (the base's capsule, 0.121 m in radius).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from toptraj.planners.collision.clearance import COARSE, COARSE_STEP, _reach
from toptraj.planners.collision.distance import segment_distance
from toptraj.planners.errors import InfeasiblePath
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.robots import Robot
from toptraj.robots.collision import LinkCapsule, robot_capsules, world_capsules
from toptraj.robots.srdf import pair, shipped_pairs

if TYPE_CHECKING:
    from toptraj.planners.paths.base import GeometricPath

#: Largest motion (m) of any point of the arm across an interval still uncertain.
RESOLUTION = 1e-3
#: Most configurations checked along one path (first pass and refinement together).
MAX_CONFIGURATIONS = 20_000
#: Largest padding (m) of the capsules over the meshes of a catalog arm, as measured (module
#: docstring), said in a refusal: the meshes may still be this far apart where capsules touch.
PADDING = 0.13
#: Configurations whose pair distances are computed at once.
BATCH = 1_000


class SelfCollision(InfeasiblePath):
    """Two links of the arm touch along the path: ``link_a``, ``link_b``, the ``s`` where and
    their capsules' signed ``distance`` (m, negative: overlapping) there."""

    title = "Path makes the arm collide with itself"

    def __init__(self, detail: str, s: float, link_a: str, link_b: str, distance: float):
        super().__init__(detail, s=s)
        self.link_a, self.link_b, self.distance = link_a, link_b, distance


@dataclass(frozen=True)
class SelfPairs:
    """The capsule pairs checked: indices ``first``, ``second`` (m,) into ``capsules``, their
    ``radius`` sums (m,) (m) and the ``links`` of each pair."""

    capsules: tuple[LinkCapsule, ...]
    first: np.ndarray
    second: np.ndarray
    radius: np.ndarray
    links: tuple[tuple[str, str], ...]


@dataclass(frozen=True)
class SelfClearance:
    """The smallest signed distance (m) between two links along a path, the links and ``s``
    where it occurs, and how many configurations were checked."""

    distance: float
    link_a: str
    link_b: str
    s: float
    checked: int


def _link(capsule: LinkCapsule) -> str:
    return capsule.link or capsule.name


def _joints(first: int, second: int) -> tuple[int, int]:
    return (first, second) if first <= second else (second, first)


def _adjacent(model, first: int, second: int) -> bool:
    return first == second or model.parents[first] == second or model.parents[second] == first


def candidate_pairs(robot: Robot, allowed: frozenset[tuple[str, str]] = frozenset()) -> SelfPairs:
    """The capsule pairs of different, non-adjacent links of ``robot`` not in ``allowed``."""
    capsules = tuple(robot_capsules(robot))
    # an allowed pair covers the links fixed to either of its links (moved by the same joint)
    joint_of = {_link(c): c.joint for c in capsules}
    allowed_joints = {_joints(joint_of[x], joint_of[y]) for x, y in allowed if x in joint_of and y in joint_of}
    first, second, links = [], [], []
    for i, a in enumerate(capsules):
        for j in range(i + 1, len(capsules)):
            b = capsules[j]
            if _link(a) == _link(b) or _adjacent(robot.model, a.joint, b.joint) or _joints(a.joint, b.joint) in allowed_joints:
                continue
            first.append(i)
            second.append(j)
            links.append((_link(a), _link(b)))
    radius = np.array([capsules[i].radius + capsules[j].radius for i, j in zip(first, second, strict=True)])
    return SelfPairs(capsules, np.array(first, dtype=int), np.array(second, dtype=int), radius, tuple(links))


def pair_distances(robot: Robot, pairs: SelfPairs, q: np.ndarray) -> np.ndarray:
    """Signed distances (m) of every pair at each configuration of ``q`` (n, n_dof): (n, m)."""
    a, b = world_capsules(robot.model, robot.data, list(pairs.capsules), robot.configuration(np.atleast_2d(q)))
    i, j = pairs.first, pairs.second
    return segment_distance(a[:, i], b[:, i], a[:, j], b[:, j]) - pairs.radius


def touching_at_zero(robot: Robot) -> frozenset[tuple[str, str]]:
    """The link pairs whose capsules overlap at the zero configuration (the arm's own
    geometry, which its joints keep in contact), the payload's sphere left out: a payload
    overlapping a link there is checked like anywhere else."""
    pairs = candidate_pairs(robot)
    if not len(pairs.first):
        return frozenset()
    distances = pair_distances(robot, pairs, np.zeros((1, robot.dof)))[0]
    touching = (pair(*pairs.links[k]) for k in np.flatnonzero(distances <= 0.0))
    return frozenset(item for item in touching if "payload" not in item)


def default_allowed(robot: Robot) -> frozenset[tuple[str, str]]:
    """The pairs allowed to touch when a request gives none: the robot's own list
    (``Robot.allowed_collisions``), the SRDF example-robot-data ships for a catalog arm, and
    the pairs touching at the zero pose."""
    from toptraj.robots.catalog import EXAMPLE_ARMS

    allowed = set(getattr(robot, "allowed_collisions", frozenset()))
    if robot.source == "example-robot-data" and robot.name in EXAMPLE_ARMS:
        allowed |= shipped_pairs(EXAMPLE_ARMS[robot.name].loader) or frozenset()
    return frozenset(allowed | touching_at_zero(robot))


_PAIRS: dict[tuple[int, frozenset | None], tuple[Robot, SelfPairs]] = {}


def self_pairs(robot: Robot, allowed: frozenset[tuple[str, str]] | None = None) -> SelfPairs:
    """The pairs checked for ``robot`` with ``allowed`` added to its default list
    (``default_allowed``), built once per robot and list."""
    key = (id(robot), allowed)
    cached = _PAIRS.get(key)
    if cached is not None and cached[0] is robot:
        return cached[1]
    pairs = candidate_pairs(robot, default_allowed(robot) | (allowed or frozenset()))
    if len(_PAIRS) > 256:
        _PAIRS.clear()
    _PAIRS[key] = (robot, pairs)
    return pairs


def self_distances(robot: Robot, q: np.ndarray, pairs: SelfPairs | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Per configuration of ``q`` (n, n_dof): the smallest signed distance (m) between two
    checked links (inf without pairs) and the index of the pair; shapes (n,)."""
    pairs = self_pairs(robot) if pairs is None else pairs
    nearest, which = np.full(len(q), np.inf), np.zeros(len(q), dtype=int)
    if not len(pairs.first):
        return nearest, which
    for begin in range(0, len(q), BATCH):  # temporaries of BATCH x pairs x 3 floats at most
        distances = pair_distances(robot, pairs, q[begin : begin + BATCH])
        which[begin : begin + BATCH] = distances.argmin(axis=1)
        nearest[begin : begin + BATCH] = distances[np.arange(len(distances)), which[begin : begin + BATCH]]
    return nearest, which


def _refuse(s: float, pairs: SelfPairs, which: int, distance: float, certain: bool, upload: bool) -> SelfCollision:
    """The refusal of the pair ``which`` at ``s`` (``distance``: the capsules' signed distance,
    m; ``certain``: they touch there, else the check could not tell), with what may be done: the
    capsules' padding where they wrap meshes, allowing the pair in an upload (``upload``)."""
    link_a, link_b = pairs.links[which]
    capsules = [pairs.capsules[pairs.first[which]], pairs.capsules[pairs.second[which]]]
    links = [capsule for capsule in capsules if capsule.link != "payload"]  # the payload's sphere is its own collision shape
    if certain and all(capsule.mesh for capsule in links):
        shape = (
            f"the capsules contain the links' collision meshes with a padding of up to about {PADDING:g} m "
            "on the catalog arms, so the meshes may still be apart"
        )
    elif certain:
        radius = max(capsule.radius for capsule in links if not capsule.mesh)
        shape = f"a link without a collision mesh is a capsule of radius {radius:g} m along it, so its real shape may differ"
    if certain:
        how = f"touch at s = {s:.4g} (their capsules overlap by {-distance:.4g} m; {shape})"
    else:
        how = f"may touch after s = {s:.4g} (the check could not tell within {MAX_CONFIGURATIONS} configurations)"
    if "payload" in (link_a, link_b):  # the payload's sphere (``toptraj.robots.collision``) is no link to allow
        advice = "move the waypoints there so that the payload stays clear of the arm, or give the payload a smaller collision radius"
    else:
        advice = "move the waypoints there so that the arm does not fold onto itself"
        if upload:
            advice += ", or, if the links may touch, allow the pair among the robot's allowed collisions when uploading it"
    return SelfCollision(
        f"links {link_a!r} and {link_b!r} {how}: {advice}",
        s=s, link_a=link_a, link_b=link_b, distance=distance,
    )


def _split(s: np.ndarray, unsure: np.ndarray) -> np.ndarray:
    """Three new parameters inside each unsure interval (s[i], s[i + 1]) (quarters)."""
    lo, width = s[:-1][unsure], np.diff(s)[unsure]
    return (lo[:, None] + width[:, None] * np.array([0.25, 0.5, 0.75])[None, :]).ravel()


def check_self_collision(
    path: GeometricPath, robot: Robot, allowed: frozenset[tuple[str, str]] | None = None, deadline: Deadline = NO_DEADLINE
) -> SelfClearance:
    """The links' smallest distance to each other along ``path`` (a ``GeometricPath``):
    configurations at most ``COARSE_STEP`` of pair motion apart, the intervals whose bound falls
    below zero split until certified or ``RESOLUTION`` (module docstring); ``deadline``
    checked at each round.

    Raises:
        SelfCollision: two checked links touch (the first s along the path), or the path
            cannot be certified within ``MAX_CONFIGURATIONS`` configurations.
    """
    pairs = self_pairs(robot, allowed)
    upload = robot.source == "upload"
    reach = _reach(robot)
    coarse = path.evaluate(np.linspace(0.0, 1.0, COARSE + 1)).q
    motion = reach * float(np.abs(np.diff(coarse, axis=0)).sum())
    s = np.linspace(0.0, 1.0, min(MAX_CONFIGURATIONS // 4, max(COARSE, math.ceil(motion / COARSE_STEP))) + 1)
    q = path.evaluate(s).q
    d, which = self_distances(robot, q, pairs)
    while True:
        deadline.check()
        contact = np.flatnonzero(d < 0.0)
        before = s[contact[0]] if contact.size else np.inf
        step = reach * np.abs(np.diff(q, axis=0)).sum(axis=1)
        unsure = ((d[:-1] + d[1:] - step) / 2.0 < 0.0) & (s[:-1] < before) & (step > RESOLUTION)
        if not unsure.any():
            break
        if len(s) + 3 * int(unsure.sum()) > MAX_CONFIGURATIONS:
            first = int(np.flatnonzero(unsure)[0])
            raise _refuse(float(s[first]), pairs, int(which[first]), float((d[first] + d[first + 1] - step[first]) / 2.0), False, upload)
        new_s = _split(s, unsure)
        new_q = path.evaluate(new_s).q
        new_d, new_which = self_distances(robot, new_q, pairs)
        order = np.argsort(np.concatenate([s, new_s]), kind="stable")
        s, q = np.concatenate([s, new_s])[order], np.concatenate([q, new_q])[order]
        d, which = np.concatenate([d, new_d])[order], np.concatenate([which, new_which])[order]
    if contact.size:
        first = int(contact[0])
        raise _refuse(float(s[first]), pairs, int(which[first]), float(d[first]), True, upload)
    worst = int(np.argmin(d))
    link_a, link_b = pairs.links[int(which[worst])] if len(pairs.links) else ("", "")
    return SelfClearance(float(d[worst]), link_a, link_b, float(s[worst]), len(s))
