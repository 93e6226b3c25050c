"""Configuration-space obstacles on the search graph (Jeong & Lee eq. 2.4, CO(b) = {y | R(y)
meets b}): the pieces of curve whose configurations come closer to an obstacle than the
clearance, or where two links of the arm touch, are removed from the graph.

The distance of the arm from an obstacle changes by at most sum_j R_j |dq_j| between
configurations dq apart (R_j bounds the distance from joint j to any point of the arm beyond
it); pieces are checked where this bound cannot prove them clear, at samples refined where the
bound between them comes within the clearance (``clear_pieces``). A piece is kept only when the
bound proves it clear. Distances are computed for all configurations at once by the compiled
``distance_kernels`` (the link capsules' ends, then a box's golden section or a pair of links'
segment distance only where a cheaper bound says it may lower a configuration's least), at
samples along the spans given by the compiled ``span_kernels``; ``joint_placements`` is the
same kinematics in numpy, for the arms the kernels do not serve.
"""

from __future__ import annotations

import numpy as np

from toptraj.planners.collision import Obstacle, clearance_along
from toptraj.planners.collision.self_collision import self_distances, self_pairs
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.planners.generators.search.curve import BASIS
from toptraj.planners.generators.search.distance_kernels import capsule_ends, lower_distances, obstacle_row, pair_minimum
from toptraj.planners.generators.search.pieces import Pieces
from toptraj.planners.generators.search.span_kernels import span_points
from toptraj.robots import Robot
from toptraj.robots.collision import robot_capsules

#: Largest arm motion (m) between the samples of a piece near an obstacle.
COARSE_STEP = 0.02
#: The same where the coarse samples leave the piece undecided.
FINE_STEP = 0.002
#: Configurations whose distances are computed at once (between two deadline checks).
BATCH = 4_000
#: Intervals refined at once by ``clear_pieces`` (each takes three new distances).
REFINED = 20_000


_AXES = {"X": np.array([1.0, 0.0, 0.0]), "Y": np.array([0.0, 1.0, 0.0]), "Z": np.array([0.0, 0.0, 1.0])}


def _joint_motion(joint) -> tuple[str, np.ndarray] | None:
    """("revolute" or "prismatic", unit axis) of a one-degree-of-freedom joint, or None for a
    kind the batched kinematics does not handle."""
    name = joint.shortname()
    for prefix, kind in (("JointModelRUB", "revolute"), ("JointModelR", "revolute"), ("JointModelP", "prismatic")):
        if name.startswith(prefix) and name[len(prefix):] in _AXES:
            return kind, _AXES[name[len(prefix):]]
    if name in ("JointModelRevoluteUnaligned", "JointModelPrismaticUnaligned"):
        axis = np.asarray(joint.extract().axis, dtype=float)
        return ("revolute" if "Revolute" in name else "prismatic"), axis / np.linalg.norm(axis)
    return None


def joint_placements(robot: Robot, q: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """World rotations (k, J, 3, 3) and translations (k, J, 3) of every joint frame at the
    configurations q (k, n_dof), computed for all configurations at once; None when a joint is
    of a kind this does not handle (``_joint_motion``)."""
    model = robot.model
    k = len(q)
    rotation = np.zeros((k, model.njoints, 3, 3))
    rotation[:, 0] = np.eye(3)
    translation = np.zeros((k, model.njoints, 3))
    for j in range(1, model.njoints):
        motion = _joint_motion(model.joints[j])
        if motion is None:
            return None
        kind, axis = motion
        placement = model.jointPlacements[j]
        parent = model.parents[j]
        base_rotation = rotation[:, parent] @ placement.rotation
        base_translation = translation[:, parent] + np.einsum("kij,j->ki", rotation[:, parent], placement.translation)
        value = q[:, model.joints[j].idx_v]
        if kind == "revolute":
            cross = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
            turn = np.eye(3) + np.sin(value)[:, None, None] * cross + (1.0 - np.cos(value))[:, None, None] * (cross @ cross)
            rotation[:, j] = base_rotation @ turn
            translation[:, j] = base_translation
        else:
            rotation[:, j] = base_rotation
            translation[:, j] = base_translation + value[:, None] * np.einsum("kij,j->ki", base_rotation, axis)
    return rotation, translation


def chain_tables(robot: Robot) -> tuple | None:
    """The kinematic chain as arrays for ``distance_kernels.capsule_ends`` (parents, placements,
    prismatic flags, axes, q indices) and the capsules (joints, local ends, radii); None when a
    joint is of a kind the batched kinematics does not handle (``_joint_motion``)."""
    cached = _TABLES.get(id(robot))
    if cached is not None and cached[0] is robot:
        return cached[1]
    model = robot.model
    count = model.njoints
    parent, index = np.zeros(count, dtype=np.int64), np.zeros(count, dtype=np.int64)
    rotation, translation = np.zeros((count, 3, 3)), np.zeros((count, 3))
    prismatic, axis = np.zeros(count, dtype=np.bool_), np.zeros((count, 3))
    tables = None
    motions = [_joint_motion(model.joints[j]) for j in range(1, count)]
    if all(motion is not None for motion in motions):
        for j, motion in enumerate(motions, start=1):
            assert motion is not None
            placement = model.jointPlacements[j]
            parent[j], index[j] = model.parents[j], model.joints[j].idx_v
            rotation[j], translation[j] = placement.rotation, placement.translation
            prismatic[j], axis[j] = motion[0] == "prismatic", motion[1]
        capsules = robot_capsules(robot)
        tables = (
            (parent, rotation, translation, prismatic, axis, index,
             np.array([c.joint for c in capsules], dtype=np.int64),
             np.array([c.a for c in capsules], dtype=float).reshape(-1, 3),
             np.array([c.b for c in capsules], dtype=float).reshape(-1, 3)),
            np.array([c.radius for c in capsules], dtype=float),
        )
    _TABLES[id(robot)] = (robot, tables)
    while len(_TABLES) > MAX_TABLES:  # a robot per payload and mounting: keep the most recent
        del _TABLES[next(iter(_TABLES))]
    return tables


#: Robots whose tables are kept (each table holds its robot, whose id is the key).
MAX_TABLES = 64
_TABLES: dict[int, tuple] = {}


def point_distances(
    robot: Robot, q: np.ndarray, obstacles: list[Obstacle], exact_below: float = np.inf, deadline: Deadline = NO_DEADLINE,
    self_offset: float | None = None,
) -> np.ndarray:
    """Smallest signed distance (m) of the arm's link capsules (``toptraj.robots.collision``) to any
    obstacle at each configuration (k, n_dof); distances above ``exact_below`` may be lower
    bounds (``toptraj.planners.collision.distance.capsule_distance``), computed by the compiled
    ``distance_kernels``. With ``self_offset``, each is at most ``self_offset`` plus the
    smallest distance between two checked links (``toptraj.planners.collision.self_collision``).
    ``deadline`` is checked before each obstacle of each ``BATCH`` of configurations."""
    out = np.empty(len(q))
    tables = chain_tables(robot)
    rows_of = [obstacle_row(obstacle) for obstacle in obstacles]
    pairs = self_pairs(robot) if self_offset is not None else None
    q = np.ascontiguousarray(q, dtype=float)
    for begin in range(0, len(q), BATCH):
        deadline.check()
        rows = q[begin : begin + BATCH]
        if tables is None:
            nearest = clearance_along(robot, rows, obstacles, exact_below)[0] if obstacles else np.full(len(rows), np.inf)
            if pairs is not None and self_offset is not None:
                nearest = np.minimum(nearest, self_offset + self_distances(robot, rows, pairs)[0])
            out[begin : begin + BATCH] = nearest
            continue
        a, b = capsule_ends(rows, *tables[0])
        nearest = np.full(len(rows), np.inf)
        for kind, row in rows_of:
            deadline.check()
            lower_distances(a, b, tables[1], kind, row, float(exact_below), nearest)
        if pairs is not None and self_offset is not None and len(pairs.first):
            touching = np.empty(len(rows))
            pair_minimum(a, b, pairs.first, pairs.second, pairs.radius, touching)
            nearest = np.minimum(nearest, self_offset + touching)
        out[begin : begin + BATCH] = nearest
    return out


def free_distances(
    robot: Robot, q: np.ndarray, obstacles: list[Obstacle], clearance: float, exact_below: float = np.inf,
    deadline: Deadline = NO_DEADLINE,
) -> np.ndarray:
    """What the search keeps at or above ``clearance`` (m) at each configuration (k, n_dof):
    the smaller of the distance to the obstacles and ``clearance`` plus the smallest distance
    between two checked links (``point_distances`` with ``self_offset``). It falls below the
    clearance exactly where an obstacle comes nearer or two links touch, and changes no faster
    than a distance to an obstacle: a pair's distance changes only by the motion of one link
    relative to the other, each joint between them moving it by at most R_j |dq_j|
    (``joint_reaches``), so the bounds of ``clear_pieces`` hold for it."""
    return point_distances(robot, q, obstacles, exact_below, deadline, self_offset=clearance)


def joint_reaches(robot: Robot) -> np.ndarray:
    """Per joint (n_dof,), a bound (m, or 1 for a prismatic joint) on how far any point of the
    arm moves per unit of that joint's motion, whatever the configuration: the distance from
    the joint to any capsule point beyond it (link lengths along the chain plus the capsule's
    extent from its own joint)."""
    model = robot.model
    out = np.zeros(robot.dof)
    capsules = robot_capsules(robot)
    for j in range(1, model.njoints):
        motion = _joint_motion(model.joints[j])
        farthest = 0.0
        for capsule in capsules:
            k, along = int(capsule.joint), 0.0
            while k > j:  # walk from the capsule's joint up to j
                along += float(np.linalg.norm(model.jointPlacements[k].translation))
                k = model.parents[k]
            if k != j:
                continue
            extent = max(float(np.linalg.norm(capsule.a)), float(np.linalg.norm(capsule.b))) + capsule.radius
            farthest = max(farthest, along + extent)
        out[model.joints[j].idx_v] = 1.0 if motion is not None and motion[0] == "prismatic" else farthest
    return out


def clear_pieces(pieces: Pieces, points: np.ndarray, robot: Robot, obstacles: list[Obstacle], clearance: float,
                 deadline: Deadline) -> tuple[np.ndarray, np.ndarray]:
    """Which pieces keep ``clearance`` (m) from ``obstacles`` and the links apart along all of
    them, shape (K,), and the distance of every grid point (``free_distances``), shape (P,):
    ``clear_spans`` of every piece."""
    distance = free_distances(robot, points, obstacles, clearance, deadline=deadline)
    return clear_spans(pieces, np.arange(len(pieces)), distance, robot, obstacles, clearance, deadline), distance


def clear_spans(pieces: Pieces, spans: np.ndarray, distance: np.ndarray, robot: Robot, obstacles: list[Obstacle],
                clearance: float, deadline: Deadline) -> np.ndarray:
    """Which of the pieces ``spans`` (indices, shape (m,)) keep ``clearance`` (m) from
    ``obstacles`` and the links apart along all of them, shape (m,); ``distance`` (P,) is
    ``free_distances`` at every grid point.

    The arm's points move at most sum_j R_j |dq_j| (``joint_reaches``); along a span, |dq_j/dt|
    is at most the largest difference of its control points in joint j, so over a parameter
    interval of width h the arm moves at most h S, S = sum_j R_j max_k |dP_kj|, and between two
    samples with distances d_a, d_b the distance stays above (d_a + d_b - h S) / 2. A span is
    clear when its corner point's distance exceeds the clearance by R times the hull of its
    control points; else its interval samples are checked, and intervals whose bound falls
    below the clearance are split in four until the arm moves less than ``FINE_STEP`` across
    one: a sample closer than the clearance, or an interval still undecided then, removes the
    span.
    """
    spans = np.asarray(spans, dtype=int)
    weights = joint_reaches(robot)
    control = pieces.control
    hull = (np.abs(control[spans] - control[spans, 1:2]) * weights).sum(axis=2).max(axis=1)
    keep = distance[pieces.corner[spans]] - hull >= clearance
    undecided = spans[~keep]
    if not undecided.size:
        return keep
    speed = np.zeros(len(pieces))
    speed[undecided] = (np.abs(np.diff(control[undecided], axis=1)).max(axis=1) * weights).sum(axis=1)  # S per span
    blocked = np.zeros(len(pieces), dtype=bool)
    count = pieces.first[1] - pieces.first[0]
    # the undecided spans a group at a time, each group refined to the end before the next:
    # the work between two deadline checks and the memory held stay bounded whatever the count
    group = max(1, REFINED // (count + 1))
    for begin in range(0, len(undecided), group):
        _refine(undecided[begin : begin + group], count, control, speed, blocked, robot, obstacles, clearance, deadline)
    keep[~keep] = ~blocked[undecided]
    return keep


def _refine(spans: np.ndarray, count: int, control: np.ndarray, speed: np.ndarray, blocked: np.ndarray, robot: Robot,
            obstacles: list[Obstacle], clearance: float, deadline: Deadline) -> None:
    """``clear_pieces``' samples and refinement of ``spans`` (indices, shape (m,)): sets
    ``blocked`` (K,) of those that come within ``clearance`` or stay undecided at
    ``FINE_STEP``. The intervals still unsure wait on a stack and are split ``REFINED`` at a
    time, the newest first (depth first), so that the stack holds at most about
    4 ``REFINED`` intervals per level of splitting."""
    t = np.linspace(0.0, 1.0, count + 1)
    owner = np.repeat(spans, count + 1)
    q = span_points(control, owner, np.tile(t, len(spans)), BASIS)
    d = free_distances(robot, q, obstacles, clearance, clearance + COARSE_STEP, deadline)
    blocked[owner[d < clearance]] = True
    d_rows = d.reshape(len(spans), count + 1)
    stack = [(np.repeat(spans, count), np.tile(t[:-1], len(spans)), np.full(len(spans) * count, 1.0 / count),
              d_rows[:, :-1].ravel(), d_rows[:, 1:].ravel())]
    while stack:
        deadline.check()
        piece, t_a, width, d_a, d_b = stack.pop()
        if len(piece) > REFINED:  # the rest waits its turn
            stack.append((piece[:-REFINED], t_a[:-REFINED], width[:-REFINED], d_a[:-REFINED], d_b[:-REFINED]))
            piece, t_a, width, d_a, d_b = piece[-REFINED:], t_a[-REFINED:], width[-REFINED:], d_a[-REFINED:], d_b[-REFINED:]
        unsure = ~blocked[piece] & ((d_a + d_b - width * speed[piece]) / 2.0 < clearance)
        piece, t_a, width, d_a, d_b = piece[unsure], t_a[unsure], width[unsure], d_a[unsure], d_b[unsure]
        fine = width * speed[piece] <= FINE_STEP
        blocked[piece[fine]] = True
        piece, t_a, width, d_a, d_b = piece[~fine], t_a[~fine], width[~fine], d_a[~fine], d_b[~fine]
        if not piece.size:
            continue
        width = width / 4.0
        inner = t_a[:, None] + width[:, None] * np.arange(1, 4)[None, :]  # (m, 3)
        q = span_points(control, np.repeat(piece, 3), inner.ravel(), BASIS)
        new = free_distances(robot, q, obstacles, clearance, clearance + COARSE_STEP, deadline).reshape(-1, 3)
        blocked[piece[(new < clearance).any(axis=1)]] = True
        ends = np.column_stack([d_a, new, d_b])  # (m, 5)
        stack.append((
            np.repeat(piece, 4),
            (t_a[:, None] + width[:, None] * np.arange(4)[None, :]).ravel(),
            np.repeat(width, 4),
            ends[:, :-1].ravel(),
            ends[:, 1:].ravel(),
        ))
