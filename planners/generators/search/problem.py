"""A search problem, built once before the branch and bound: the graph (lattice or roadmap), its
pieces of curve with the configuration-space obstacles removed, every piece's bounds, and the
cost-to-go from each node of the direction-augmented graph under t1 and t2."""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass

import numpy as np

from toptraj.planners.collision import Obstacle
from toptraj.planners.collision.clearance import clearance_along
from toptraj.planners.collision.self_collision import SelfCollision, self_distances, self_pairs
from toptraj.planners.errors import InfeasiblePath, NotOneOf, OutOfRange
from toptraj.planners.execution.deadline import NO_DEADLINE, Deadline
from toptraj.planners.generators.search.bounds import PieceBounds, piece_bounds
from toptraj.planners.generators.search.free_space import clear_pieces, clear_spans, free_distances, point_distances
from toptraj.planners.generators.search.graph import (
    DEFAULT_MAX_TURN,
    DEFAULT_OPTIONS,
    LATTICE_MAX_JOINTS,
    SearchGraph,
    SearchOptions,
    lattice_graph,
    roadmap_graph,
)
from toptraj.planners.generators.search.pieces import Pieces, build_pieces
from toptraj.planners.generators.search.states import search_states
from toptraj.planners.problem.path_checks import check_within_joint_limits
from toptraj.robots import JointLimits, Robot
from toptraj.robots.collision import robot_capsules

GRAPH_KINDS = ("auto", "lattice", "roadmap")


@dataclass(frozen=True)
class SearchProblem:
    """Everything the branch and bound reads.

    The search's states are the nodes of the direction-augmented graph seen through the
    curve: a partial path is known by its last two moves (a turn of the graph, whose B-spline
    span is not yet fixed), or, after one move, by that move alone (``start_states``).

    Attributes:
        graph: The grid points and moves.
        turn_in, turn_out: The turns of the augmented graph (pairs of moves), shape (T,).
        pieces: Every span (``toptraj.planners.generators.search.pieces``).
        bounds: Every span's bounds (``toptraj.planners.generators.search.bounds``).
        usable: Per span, whether it keeps the clearance and some motion can follow it.
        start_moves: Per move from the start: (edge, state, direct span): the state it leads to
            (-1 when it ends at a goal) and its usable direct span (-1 where none).
        successors: Per state, its usable moves on: (next state, span, last span) with the last
            span (-1 where none) when the next state's move ends at a goal.
        state_point: The grid point each state's last move ends at, shape (S,).
        h1, h2: Per state, lower bounds on the time from the fixed part of its curve to a goal:
            the straight distance over V_max, and the least t2 over the graph's completions
            (``inf`` where no goal can be reached).
        robot, limits, kinds: What the spans were bounded for (t4 uses them too).
        removed: Spans removed by the obstacles; ``points_blocked``: grid points closer than
            the clearance.
        prepare_s: Seconds spent building the problem.
        checked: Per span, whether its clearance has been checked (all of them unless the
            problem is lazy: ``build_problem``); an unchecked span counts as usable.
        point_distance: ``free_distances`` at every grid point, shape (P,).
        obstacles, clearance: What the spans keep their clearance (m) from.
    """

    graph: SearchGraph
    turn_in: np.ndarray
    turn_out: np.ndarray
    pieces: Pieces
    bounds: PieceBounds
    usable: np.ndarray
    start_moves: list[tuple[int, int, int]]
    successors: list[list[tuple[int, int, int]]]
    state_point: np.ndarray
    h1: np.ndarray
    h2: np.ndarray
    robot: Robot
    limits: JointLimits
    kinds: tuple[str, ...]
    removed: int
    points_blocked: int
    prepare_s: float
    checked: np.ndarray
    point_distance: np.ndarray
    obstacles: tuple[Obstacle, ...]
    clearance: float


def _graph(robot, start, goal, options: SearchOptions, revolutions, obstacles, clearance, deadline: Deadline) -> SearchGraph:
    kind = options.graph
    if kind not in GRAPH_KINDS:
        raise NotOneOf("search.graph", kind, GRAPH_KINDS)
    if kind == "auto":
        kind = "lattice" if robot.dof <= LATTICE_MAX_JOINTS else "roadmap"
    if kind == "lattice":
        return lattice_graph(robot, start, goal, options, revolutions)

    def free(q):
        return free_distances(robot, q, obstacles, clearance, deadline=deadline) >= clearance

    return roadmap_graph(robot, start, goal, options, revolutions, free, deadline)


def _check_apart(robot: Robot, name: str, q: np.ndarray) -> None:
    """Raise ``SelfCollision`` when two checked links touch at the configuration ``q``."""
    distance, which = self_distances(robot, q[None, :])
    if distance[0] < 0.0:
        link_a, link_b = self_pairs(robot).links[int(which[0])]
        s = 0.0 if name == "start" else 1.0
        raise SelfCollision(
            f"at path.{name}, links {link_a!r} and {link_b!r} touch (their capsules overlap by {-distance[0]:.4g} m): "
            "move it so that the arm does not fold onto itself",
            s=s, link_a=link_a, link_b=link_b, distance=float(distance[0]),
        )


def check_end(robot: Robot, name: str, q: np.ndarray, obstacles: list[Obstacle], clearance: float) -> None:
    """Raise where the start or goal ``q`` lies outside the joint limits, within the clearance
    of an obstacle, or with two links touching (what the search's generator checks before any
    work, and ``build_problem`` again for a caller of the search alone)."""
    check_within_joint_limits(robot, name, q)
    if obstacles:
        nearest = float(point_distances(robot, q[None, :], obstacles)[0])
        if nearest < clearance:
            _, capsule, obstacle = clearance_along(robot, q[None, :], obstacles)
            touching = robot_capsules(robot)[int(capsule[0])]
            link = touching.link
            how = f"is inside obstacle {int(obstacle[0])} (by {-nearest:.4g} m)" if nearest < 0 else (
                f"comes within {nearest:.4g} m of obstacle {int(obstacle[0])}"
            )
            raise InfeasiblePath(
                f"at the {name}, link {link!r} {how} (the clearance is {clearance:g} m)",
                rule="end_too_close", field=name, distance=nearest, clearance=clearance, link=link, obstacle=int(obstacle[0]),
                fixed=touching.joint == 0,
            )
    _check_apart(robot, name, q)


def build_problem(
    robot: Robot,
    limits: JointLimits,
    kinds: tuple[str, ...],
    start: np.ndarray,
    goal: np.ndarray,
    options: SearchOptions | None = None,
    revolutions: bool = True,
    obstacles: tuple[Obstacle, ...] = (),
    clearance: float = 0.01,
    deadline: Deadline = NO_DEADLINE,
) -> SearchProblem:
    """The graph between ``start`` and ``goal`` (n_dof,), its pieces kept clear of
    ``obstacles`` by ``clearance`` (m), their bounds and the costs to go.

    A lazy problem (``options.lazy``; ``global_search``'s default on a roadmap) leaves the
    spans unchecked, as in Lazy PRM (Bohlin & Kavraki, ICRA 2000), until ``with_spans_checked``.

    Raises:
        InvalidRequest: start or goal outside the joint limits, an unknown graph kind, a grid
            too large.
        InfeasiblePath: start or goal closer to an obstacle than the clearance.
    """
    began = time.perf_counter()
    options = options or DEFAULT_OPTIONS
    obstacle_list = list(obstacles)
    for name, q in (("start", start), ("goal", goal)):
        check_end(robot, name, q, obstacle_list, clearance)
    deadline.progress(0.0, "search: graph")
    graph = _graph(robot, start, goal, options, revolutions, obstacle_list, clearance, deadline)
    max_turn = options.max_turn if options.max_turn is not None else DEFAULT_MAX_TURN[graph.kind]
    if not 0.0 < max_turn < 180.0:
        raise OutOfRange("search.max_turn", max_turn, 0.0, 180.0, "degrees", rule="max_turn_out_of_range")
    turn_in, turn_out = graph.transitions(max_turn, deadline)
    pieces = build_pieces(graph.points, graph.edge_from, graph.edge_to, graph.start, graph.goals, turn_in, turn_out)
    deadline.check()
    deadline.progress(0.1, "search: obstacles and self-collision")
    if options.lazy:
        distance = free_distances(robot, graph.points, obstacle_list, clearance, deadline=deadline)
        usable, checked = np.ones(len(pieces), dtype=bool), np.zeros(len(pieces), dtype=bool)
    else:
        usable, distance = clear_pieces(pieces, graph.points, robot, obstacle_list, clearance, deadline)
        checked = np.ones(len(pieces), dtype=bool)
    points_blocked = int((distance < clearance).sum())
    removed = int((~usable).sum())
    deadline.progress(0.2, "search: bounds")
    bounds = piece_bounds(pieces, robot, limits, kinds, deadline)
    usable &= bounds.feasible
    problem = SearchProblem(
        graph=graph, turn_in=turn_in, turn_out=turn_out, pieces=pieces, bounds=bounds, usable=usable,
        start_moves=[], successors=[], state_point=np.empty(0, dtype=int), h1=np.empty(0), h2=np.empty(0),
        robot=robot, limits=limits, kinds=tuple(kinds), removed=removed, points_blocked=points_blocked,
        prepare_s=0.0, checked=checked, point_distance=distance, obstacles=tuple(obstacle_list), clearance=clearance,
    )
    return dataclasses.replace(_with_states(problem, graph, deadline), prepare_s=time.perf_counter() - began)


def with_spans_checked(
    problem: SearchProblem, spans: np.ndarray, deadline: Deadline = NO_DEADLINE, states: bool = True,
) -> tuple[SearchProblem, int]:
    """``problem`` with the clearance of the unchecked ones among ``spans`` (indices) checked
    (``clear_spans``), the blocked ones no longer usable and, with ``states``, the states and
    costs to go redone where any is (without, they are left as they were: ``toward_goal``
    redoes them for each goal): the problem and how many were found blocked."""
    spans = np.unique(np.asarray(spans, dtype=int))
    spans = spans[~problem.checked[spans]]
    if not spans.size:
        return problem, 0
    clear = clear_spans(
        problem.pieces, spans, problem.point_distance, problem.robot, list(problem.obstacles), problem.clearance, deadline
    )
    checked, usable = problem.checked.copy(), problem.usable.copy()
    checked[spans] = True
    usable[spans[~clear]] = False
    blocked = int((~clear).sum())
    problem = dataclasses.replace(problem, checked=checked, usable=usable, removed=problem.removed + blocked)
    return (_with_states(problem, problem.graph, deadline) if blocked and states else problem), blocked


def toward_goal(problem: SearchProblem, goal: int, deadline: Deadline = NO_DEADLINE) -> SearchProblem:
    """The same problem with one goal point only (``goal``, an index into the graph's goals):
    the grid paths ending at one revolution variant of the goal, a homotopy class of their
    own, searched with their own upper bound."""
    graph = dataclasses.replace(problem.graph, goals=problem.graph.goals[goal : goal + 1])
    return _with_states(problem, graph, deadline)


def _with_states(problem: SearchProblem, graph: SearchGraph, deadline: Deadline = NO_DEADLINE) -> SearchProblem:
    """``problem`` with the states, moves and costs to go toward ``graph.goals``."""
    bounds = problem.bounds
    successors, start_moves, state_point, h2, cut = search_states(
        graph, problem.turn_in, problem.turn_out, problem.pieces, bounds, problem.usable, deadline
    )
    goal_points = graph.points[graph.goals]
    straight = np.min(np.linalg.norm(cut[:, None, :] - goal_points[None, :, :], axis=2), axis=1)
    h1 = np.where(np.isfinite(h2), straight / bounds.v_max, np.inf)
    return dataclasses.replace(
        problem, graph=graph, start_moves=start_moves, successors=successors, state_point=state_point, h1=h1, h2=h2
    )
