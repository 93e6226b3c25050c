"""The service's words for the library's errors: one wording per rule (``rule`` of an error;
a class's own rule by default), in the request's vocabulary.

A wording is a ``str.format`` template over the error's facts, where ``{field}`` (and each of
``fields``) is the request's field (``toptraj.service.problems.REQUEST_FIELD``), ``{x!j}`` joins a sequence with ", ",
``{x!e}`` shows a value excerpted (``toptraj.robots.errors.excerpt``), ``{x!f}`` maps a library field
to the request's and ``{x:~noun}`` counts (``toptraj.service.counts.counted``); or a function of the facts
for what a template cannot say.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from toptraj.robots.errors import excerpt
from toptraj.robots.ranges import Range
from toptraj.service.cell_wordings import CELL_WORDING
from toptraj.service.counts import counted
from toptraj.service.field_hints import closest
from toptraj.service.limit_wordings import LIMIT_WORDING
from toptraj.service.note_wordings import NOTE_WORDING
from toptraj.service.obstacle_wordings import OBSTACLE_WORDING
from toptraj.service.search_wordings import SEARCH_WORDING
from toptraj.service.zone_wordings import ZONE_WORDING


def _range(facts: dict) -> str:
    """``[low, high] unit`` as ``Range.describe`` shows it; a signed range as [-high, high]."""
    if facts.get("signed"):
        return f"[-{facts['high']:g}, {facts['high']:g}] {facts['unit']}".rstrip()
    return Range(facts["low"], facts["high"], facts["unit"]).describe()


def _out_of_range(facts: dict) -> str:
    return f"{facts['field']} = {facts['value']!r} is outside the accepted range {_range(facts)}"


def _scaled_limit(facts: dict) -> str:
    kind, advised = facts["kind"], facts["advised"]
    advice = (
        f"use timing.limits.{kind}_scale in [{advised[0]:g}, {advised[1]:g}]"
        if advised is not None
        else f"give timing.limits.{kind} per joint instead of a scale"
    )
    return (
        f"{facts['field']} = {facts['value']:g} makes the {kind} limit of joint {facts['joint_name'][:64]!r} "
        f"{facts['scaled']:g} {facts['unit']}, outside the accepted range {_range(facts)}; {advice}"
    )


def _wrong_length(facts: dict) -> str:
    text = f"{facts['field']} has {counted(facts['given'], 'value')}; "
    text += f"{facts.get('robot', 'the robot')} has {counted(facts['expected'], 'joint')}"
    if "joint_names" in facts:
        text += f" ({', '.join(facts['joint_names'])})"
    return text


def _kind_not_served(facts: dict) -> str:
    kind, kept = facts["value"], facts["kept"]
    hint = " (for jerk, use jerk_limited, a time law or ruckig)" if kind == "jerk" else ""
    drop = f"drop {kind!r} from timing.constraints" + (f" (e.g. {list(kept)})" if kept else "")
    other = ", or use timing.method 'jerk_limited', which holds torque and jerk" if kind == "torque" else ""
    return f"timing.method {facts['method']!r} cannot limit {kind}; it handles {facts['handles']}{hint}: {drop}{other}"


def _too_many_samples(facts: dict) -> str:
    given = (
        f"{facts['field']} = {facts['value']:g} s gives {facts['estimate']} samples over the {facts['duration']:.4g} s "
        f"motion; at most {facts['cap']} are served"
    )
    if facts["smallest_dt"] is not None:
        return f"{given}: use {facts['field']} >= {facts['smallest_dt']:g} s"
    slowing = list(facts["fields"])
    slowing += ["the velocity and acceleration limits (timing.limits and their scales)"]
    return (
        f"{given}, and even the largest {facts['field']} ({facts['largest_dt']:g} s) serves at most {facts['longest_s']:g} s "
        f"of motion: the limits make this motion too slow to serve; raise {' or '.join(slowing)}"
    )


def _curvature_jump(facts: dict) -> str:
    """A blended path under a jerk limit; jerk_limited always limits jerk, so its remedy is
    another method, not leaving 'jerk' out of the constraints."""
    remedy = (
        "use interpolation 'spline', or time the blended path with a method without a jerk limit (phase_plane, toppra)"
        if facts.get("method") == "jerk_limited"
        else "use interpolation 'spline' with a jerk limit, or leave 'jerk' out of timing.constraints"
    )
    return (
        f"the path's curvature d2q/ds2 jumps at s = {facts['s']:.4f} (where a straight segment meets a blend), "
        f"so the joint accelerations jump there and no motion that passes it has a finite jerk: {remedy}"
    )


def _needs_two_waypoints(facts: dict) -> str:
    given = "a cartesian path" if facts["value"] is None else counted(facts["value"], "waypoint")
    return (
        f"timing.method {facts['method']!r} plans state-to-state motions: give exactly 2 waypoints, not "
        f"{given} (the offline library has no intermediate waypoints); use phase_plane or a time "
        "law through several waypoints"
    )


def _where(facts: dict) -> str:
    """Where along a Cartesian line: the point's field, the next point, how far along."""
    return f"{100 * facts['fraction']:.1f} % along the line to {facts['field']} (at {facts['position']} m)"


def _law_acceleration_steps(facts: dict) -> str:
    where = ", ".join(f"{tau:.4g}" for tau in facts["steps"])
    return (
        f"the {facts['law']}'s acceleration jumps at tau = {where} (as a fraction of each stretch's "
        "duration), so its jerk is infinite there and no duration holds a jerk limit: use quintic, "
        "cycloidal, trapezoidal with blend 'cycloidal' or jerk_limited, or leave 'jerk' out of "
        "timing.constraints"
    )


def _outside_joint_range(facts: dict) -> str:
    """A joint value outside its range, with the value it would be in radians (metres) where
    it looks given in degrees (millimetres) and that lies within the range."""
    value, low, high = facts["value"], facts["low"], facts["high"]
    text = f"{facts['field']} = {value:.6g} is outside the limits [{low:.6g}, {high:.6g}] of joint {facts['joint_name']!r}"
    if abs(value) >= 10.0:
        unit, factor, given = ("m", 1e-3, "millimetres") if facts.get("prismatic") else ("rad", math.pi / 180.0, "degrees")
        if low <= value * factor <= high:
            text += f"; joint values are in {unit}: if it is in {given}, give {value * factor:.6g} {unit}"
    return text


def _unknown_frame(facts: dict) -> str:
    """A frame the robot lacks: the nearest of its frames if one is close, and all of them."""
    frames = facts["allowed"]
    shown = ", ".join(repr(item) for item in frames[:60]) + (", ..." if len(frames) > 60 else "")
    meant = closest(str(facts["value"]), frames)
    nearest = f" (did you mean {meant!r}?)" if meant else ""
    return f"{facts['field']} {facts['value'][:100]!r} is not a frame of {facts['robot']}{nearest}; its frames are {shown}"


Wording = str | Callable[[dict], str]

#: Wording by rule.
def _unknown_robot(facts: dict) -> str:
    where = f"{facts['field']}: " if isinstance(facts.get("field"), str) else ""  # a cell's arm names it
    close = closest(facts["name"], facts["known"]) if isinstance(facts["name"], str) and len(facts["name"]) <= 60 else None
    return (
        f"{where}no robot named {excerpt(facts['name'])}{f' (did you mean {close!r}?)' if close else ''}; catalog robots: "
        f"{', '.join(facts['known'])}; uploaded robots are listed by GET /v1/robots"
    )


WORDING: dict[str, Wording] = {
    "too_many_arms": lambda facts: (
        f"a cell has {facts['value']} arm{'' if facts['value'] == 1 else 's'}; from {facts['fewest']} to {facts['most']} "
        "are served (every order of the arms is tried): "
        + (
            "plan a single arm with POST /v1/trajectories (its base as mounting), or add the arms it shares the workspace with"
            if facts["value"] < facts["fewest"] else f"give between {facts['fewest']} and {facts['most']} arms, or split the cell"
        )
    ),
    "out_of_range": _out_of_range,
    "scaled_limit_out_of_range": _scaled_limit,
    "not_numbers": "{field} must be a list of numbers",
    "wrong_length": _wrong_length,
    "too_large": "{field} asks for {estimate} {unit}; at most {cap} are served",
    "not_one_of": "{field} {value!r} is unknown; use one of {allowed}",
    "deviation_needs_blend": "{field} applies to interpolation 'blend', not {interpolation!r}: leave it out or use 'blend'",
    "not_joint_vectors": "{field} must be a list of joint vectors (a 2-D array)",
    "too_few_waypoints": "{field} holds {count:~waypoint}; at least 2 are needed",
    "too_many_waypoints": "{field} holds {estimate} waypoints; at most {cap} are served",
    "coordinate_out_of_range": "{field} is {value:.6g}: not a finite number within +-{high:g} ({unit})",
    "outside_joint_range": _outside_joint_range,
    "unknown_constraint": "{field} holds {value!r}; use any of {allowed}",
    "kind_not_served": _kind_not_served,
    "no_constraints": (
        "{field} is empty: without limits the time-optimal motion is instantaneous; list the limits to hold, "
        "e.g. [\"velocity\", \"acceleration\", \"torque\"], or leave it out for the kinds the method holds"
    ),
    "trapezoid_order": "{field} needs 0 < tau1 <= tau2 < 1, got {value[0]}, {value[1]}",
    "count_out_of_range": "{field} = {value!r} is outside [{low}, {high}]",
    "law_spline_failed": "{field}: {reason}",
    "blend_needs_trapezoidal": "{field} is used by timing.method 'trapezoidal', not {method!r}",
    "needs_time_law": "{field} approximates a time law ({alternatives!j}), not timing.method {method!r}",
    "law_from_rest": (
        "{field} gives a law from rest to rest: leave timing.boundary out, or drop "
        "supporting_points to use cubic or quintic with boundary states"
    ),
    "unsynchronized_needs_law": "{field} {value!r} runs each joint with a time law ({alternatives!j}), not with timing.method {method!r}",
    "weight_needs_min_cost": "{field} is not used by timing.method {method!r}; use min_cost",
    "negative_weight": "{field} must be a non-negative number, got {value}",
    "options_need_search": "{field} sets up timing.method 'search', not {method!r}",
    "tool_speed_on_free_path": (
        "{field} and tool_angular_speed are not served by collocation on a free path; "
        "give the path (waypoints or a cartesian line) and a method such as phase_plane"
    ),
    "tool_speed_through_via": (
        "{field} and tool_angular_speed are not served with interpolation 'via' "
        "(its segments are shaped by their time laws); use 'spline' or 'linear'"
    ),
    "exact_period_with_moving_ends": (
        "{field} slows the motion uniformly, which would change the nonzero "
        "timing.boundary velocities: set {field} to false (samples every dt "
        "plus the final instant) or plan from and to rest"
    ),
    "grid_out_of_range": "{field} must lie in [{low}, {high}], got {value}",
    "grid_over_method_cap": (
        "{field} = {value} is more than {method} serves on a {dof}-joint robot (its memory grows with grid "
        "intervals times joints): use {field} <= {largest}"
    ),
    "margin_out_of_range": "{field} must lie in [{low:g}, {high}], got {value}",
    "needs_two_waypoints": _needs_two_waypoints,
    "obstacles_need_search": (
        "{field} on a free path are served by timing.method 'search' (the global search among obstacles); "
        "collocation does not see obstacles"
    ),
    "too_many_samples": _too_many_samples,
    "curvature_jump": _curvature_jump,
    "boundary_accelerations_not_used": "{field} accelerations are not used by timing.method {method!r}; use quintic",
    "duration_not_used": (
        "{field} is not used by timing.method {method!r}, which finds the shortest "
        "duration itself; leave it out or use a time law"
    ),
    "via_points_need_their_generator": (
        "{field} 'via' is shaped by a time law through the via points (cubic or quintic), not timed along "
        "a given path by {method!r}"
    ),
    "via_points_from_rest": "via-point trajectories start and end at rest: leave {field} out",
    "via_points_are_polynomials": "via-point segments are polynomials: leave {field} out, or use 'spline' or 'linear'",
    "unsynchronized_needs_two_waypoints": (
        "{field} 'none' moves every joint on its own from a start to a goal: give "
        "exactly 2 waypoints (interpolation 'spline' or 'linear'), or use 'normalized'"
    ),
    "unsynchronized_from_rest": (
        "{field} 'none' moves every joint from rest to rest on its own: leave "
        "timing.boundary and the tool-speed limits out, or use 'normalized'"
    ),
    "not_finite": "{field} is {value}, not a finite number",
    "not_tangent": "{field} is not tangent to the path at s = {at_s:g}: the path's direction there is {direction}",
    "acceleration_off_path": (
        "{field} does not fit the path at s = {at_s:g}: at path speed {path_speed:.6g} 1/s every "
        "admissible joint acceleration is {curvature_term} plus a multiple of the tangent {tangent}"
    ),
    "unsynchronized_needs_a_limit": (
        "{field} 'none' runs each joint at its own full speed, which a velocity, "
        "acceleration or jerk limit sets: add one to timing.constraints"
    ),
    "ruckig_needs_a_limit": (
        "{field} 'ruckig' needs a finite velocity, acceleration or jerk limit on the joints that "
        "move, and this robot has none among timing.constraints: set velocity and acceleration limits in "
        "timing.limits (a velocity limit alone lets the velocity jump, with unbounded accelerations and torques)"
    ),
    "unsynchronized_joint_unlimited": (
        "{field} 'none': joint {joint_name!r} has no finite velocity, "
        "acceleration or jerk limit among timing.constraints, so its own full-speed duration is "
        "undefined; set one in timing.limits"
    ),
    "via_points_need_polynomials": "via points need {field} 'cubic' or 'quintic', not {value!r}",
    "waypoints_coincide": lambda facts: (
        f"path.waypoints[{facts['index']}] and path.waypoints[{facts['index'] + 1}] coincide (no joint differs by more "
        f"than {facts['tolerance']:g} rad or m), so the path has no direction between them: remove "
        f"path.waypoints[{facts['index'] + 1}], or change one of its joint values by more than {facts['tolerance']:g}"
    ),
    "search_needs_free_path": "{field} 'search' finds the path itself: give a free path (path.kind 'free', start and goal)",
    "search_from_rest": "the search plans the fastest motion from rest to rest: leave timing.boundary and timing.duration out",
    "search_over_estimate": lambda facts: (
        f"the search needed more memory than its estimate of {facts['estimate'] / 2**30:.3g} GiB allowed ({facts['cause']}): "
        "lower timing.search.roadmap_points or neighbors (cells on a lattice)"
    ),
    "free_path_needs_collocation": lambda facts: (
        "timing.method 'collocation' finds the path itself: give a free path (path.kind 'free', start and goal)"
        if facts.get("value") == "collocation"
        else f"a free path (start and goal only) needs timing.method 'collocation' or 'search', not {facts.get('value')!r}; "
        f"for {facts.get('value')!r} give the path itself (path.kind 'waypoints' or 'cartesian')"
    ),
    "collocation_intervals": "{field} sets the collocation intervals, {low} to {high}; got {value}",
    "positions_or_poses": "a cartesian path needs exactly one of path.positions and path.poses",
    "not_cartesian_rows": lambda facts: (
        f"{facts['field']} must be a list of [{'x, y, z' if facts['width'] == 3 else 'x, y, z, qx, qy, qz, qw'}] rows"
    ),
    "not_finite_number": "{field} is not a finite number",
    "quaternion_not_unit": "{field} has a quaternion of norm {norm:.6g}, not 1",
    "only_the_start_pose": "{field} holds only the start pose: give at least one more point",
    "unknown_frame": _unknown_frame,
    "not_finite_joint_values": "{field} must hold {expected} finite joint values",
    "outside_joint_limits": "{field} = {value:.6g} is outside the limits of joint {joint_name!r}",
    "line_too_long": "the line to {field} is {length:.4g} m long: it leaves the workspace of {robot}",
    "point_out_of_reach": lambda facts: (
        f"the line leaves the workspace of {facts['robot']}: no joint solution reaches the point {_where(facts)}; bring "
        f"{facts['field']} within the arm's reach, or go around the unreachable part through a point added before it"
    ),
    "line_crosses_singularity": lambda facts: (
        f"the line crosses a singularity of {facts['robot']} near the point {_where(facts)}; move {facts['field']} so "
        "that the line passes that pose at a distance, or add a point before it so that the path goes around it"
    ),
    "joint_jump": lambda facts: (
        f"the line needs a joint jump of {facts['jump']:.3g} rad on joint {facts['joint_name']!r} near the point "
        f"{_where(facts)}; start from another configuration (path.start, another solution of the same pose) or "
        "add a point before it so that the path goes around that pose"
    ),
    "joint_path_strays": lambda facts: (
        f"the joint path strays {facts['deviation'] * 1e3:.3g} mm from the line after {facts['field']} "
        f"(tolerance {facts['tolerance'] * 1e3:g} mm): the line passes too close to a singularity"
    ),
    "goal_is_start": "path.start and {field} are the same configuration: there is no motion to search",
    "goal_is_start_turned": (
        "{field} is path.start up to whole revolutions of its continuous joints, which path.revolutions "
        "allows: there is no motion to search; to turn a joint a full revolution, give that goal with "
        "path.revolutions false"
    ),
    "search_cells_length": "{field} has {given:~value}; give one, or one per joint ({expected})",
    "search_cells_out_of_range": "{field} must lie in [{low}, {high}], got {value}",
    "lattice_too_large": lambda facts: (
        f"{facts['field']} gives a lattice of {facts['estimate']} grid points ({' x '.join(map(str, facts['shape']))}); "
        f"at most {facts['cap']} are searched: use fewer cells, or timing.search.graph 'roadmap'"
    ),
    "unknown_graph": "{field} {value!e} is unknown; use one of {allowed}",
    "max_turn_out_of_range": "{field} must lie in (0, 180) degrees, got {value}",
    "frame_without_speed": "{field} is given without timing.limits.tool_speed or tool_angular_speed",
    "unknown_tool_frame": _unknown_frame,
    "jerk_limited_needs_jerk": "timing.method 'jerk_limited' needs the jerk constraint",
    "jerk_limited_from_zero_acceleration": "timing.method 'jerk_limited' starts and ends with zero acceleration",
    "law_acceleration_steps": _law_acceleration_steps,
    "law_from_rest_only": "timing.method {method!r} starts and ends at rest; use cubic or quintic for non-zero boundary velocities",
    "law_unbounded": "no requested limit bounds the {law} law's speed: add a velocity or acceleration limit",
    "orientation_not_unit": (
        "{field} has norm {norm:.6g}; a box's orientation is a unit quaternion "
        "[qx, qy, qz, qw] (norm 1 within 1e-3), e.g. [0, 0, 0, 1] for a box along the world's axes"
    ),
    "worker_stopped": (
        "the worker process computing this request stopped without an answer (exit code {exit_code}; -9: killed, "
        "by the system for memory or by an operator); nothing in the request is known to be wrong: submit it again, "
        "and if it stops again, ask for a smaller computation (fewer timing.grid_points, fewer waypoints)"
    ),
    "jerk_program_unsolved": (
        "the jerk-limited timing's linear program ended without a solution (HiGHS: {solver_status}); "
        "try other timing.grid_points"
    ),
    "limit_not_positive": "{field} must be positive, got {value}",
    "scale_not_positive": "{field} must be positive and finite, got {value}",
    "unknown_robot": _unknown_robot,
    "name_taken": "name {name!e} already holds a different {what}; choose another name, or DELETE /v1/robots/{{name}} first",
    "store_full": (
        "the upload store holds {count} uploads and {size} bytes; its caps are {max_uploads} uploads and "
        "{max_bytes} bytes, and this upload adds {added} bytes. Free space with DELETE /v1/robots/{{name}} "
        "(GET /v1/robots lists the uploads)."
    ),
    "all_waypoints_coincide": (
        "path.waypoints[0] and path.waypoints[1] coincide, as do all {count} waypoints: there is nothing to move; give "
        "a waypoint that differs from path.waypoints[0] by more than {tolerance:g} rad or m in some joint (an arm that "
        "is to stay where it is needs no trajectory)"
    ),
    **NOTE_WORDING,
    **LIMIT_WORDING,
    **ZONE_WORDING,
    **SEARCH_WORDING,
    **CELL_WORDING,
    **OBSTACLE_WORDING,
}
