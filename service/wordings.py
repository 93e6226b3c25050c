"""The service's words for the library's errors: one wording per rule (``rule`` of an error;
a class's own rule by default), in the request's vocabulary.

A wording is a ``str.format`` template over the error's facts, where ``{field}`` (and each of
``fields``) is the request's field (``service.errors.REQUEST_FIELD``), ``{x!j}`` joins a sequence with ", ",
``{x!e}`` shows a value excerpted (``robots.errors.excerpt``) and ``{x!f}`` maps a library field
to the request's; or a function of the facts for what a template cannot say.
"""

from __future__ import annotations

from collections.abc import Callable

from robots.ranges import Range


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
    text = f"{facts['field']} has {facts['given']} values; "
    if "robot" in facts:
        text += f"{facts['robot']} has {facts['expected']} joints"
    else:
        text += f"the robot has {facts['expected']} joints"
    if "joint_names" in facts:
        text += f" ({', '.join(facts['joint_names'])})"
    return text


def _kind_not_served(facts: dict) -> str:
    hint = " (for jerk, use jerk_limited, a time law or ruckig)" if facts["value"] == "jerk" else ""
    return f"timing.method {facts['method']!r} cannot limit {facts['value']}; it handles {facts['handles']}{hint}"


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


def _needs_two_waypoints(facts: dict) -> str:
    given = "a cartesian path" if facts["value"] is None else f"{facts['value']} waypoints"
    return (
        f"timing.method {facts['method']!r} plans state-to-state motions: give exactly 2 waypoints, not "
        f"{given} (the offline library has no intermediate waypoints); use phase_plane or a time "
        "law through several waypoints"
    )


Wording = str | Callable[[dict], str]

#: Wording by rule.
WORDING: dict[str, Wording] = {
    "out_of_range": _out_of_range,
    "scaled_limit_out_of_range": _scaled_limit,
    "not_numbers": "{field} must be a list of numbers",
    "wrong_length": _wrong_length,
    "not_one_of": "{field} {value!r} is unknown; use one of {allowed}",
    "deviation_needs_blend": "{field} applies to interpolation 'blend', not {interpolation!r}: leave it out or use 'blend'",
    "not_joint_vectors": "{field} must be a list of joint vectors (a 2-D array)",
    "too_few_waypoints": "{field} holds {count} waypoint(s); at least 2 are needed",
    "too_many_waypoints": "{field} holds {estimate} waypoints; at most {cap} are served",
    "coordinate_out_of_range": "{field} is {value:.6g}: not a finite number within +-{high:g} ({unit})",
    "outside_joint_range": "{field} = {value:.6g} is outside the limits [{low:.6g}, {high:.6g}] of joint {joint_name!r}",
    "unknown_constraint": "{field} holds {value!r}; use any of {allowed}",
    "kind_not_served": _kind_not_served,
    "no_constraints": "{field} is empty: without limits the time-optimal motion is instantaneous",
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
    "curvature_jump": (
        "the path's curvature d2q/ds2 jumps at s = {s:.4f} (where a straight segment meets a blend), "
        "so the joint accelerations jump there and no motion that passes it has a finite jerk: use "
        "interpolation 'spline' with a jerk limit, or leave 'jerk' out of timing.constraints"
    ),
    "boundary_accelerations_not_used": "{field} accelerations are not used by timing.method {method!r}; use quintic",
    "duration_not_used": (
        "{field} is not used by timing.method {method!r}, which finds the shortest "
        "duration itself; leave it out or use a time law"
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
    "unsynchronized_joint_unlimited": (
        "{field} 'none': joint {joint_name!r} has no finite velocity, "
        "acceleration or jerk limit among timing.constraints, so its own full-speed duration is "
        "undefined; set one in timing.limits"
    ),
    "via_points_need_polynomials": "via points need {field} 'cubic' or 'quintic', not {value!r}",
    "waypoints_coincide": lambda facts: f"path.waypoints[{facts['index']}] and path.waypoints[{facts['index'] + 1}] coincide",
    "search_needs_free_path": "{field} 'search' finds the path itself: give a free path (path.kind 'free', start and goal)",
    "search_from_rest": "the search plans the fastest motion from rest to rest: leave timing.boundary and timing.duration out",
    "search_over_estimate": lambda facts: (
        f"the search needed more memory than its estimate of {facts['estimate'] / 2**30:.3g} GiB allowed ({facts['cause']}): "
        "lower timing.search.roadmap_points or neighbors (cells on a lattice)"
    ),
    "free_path_needs_collocation": (
        "a free path (start and goal only) needs timing.method 'collocation' or 'search', and collocation a free path"
    ),
    "collocation_intervals": "{field} sets the collocation intervals, {low} to {high}; got {value}",
    "all_waypoints_coincide": "path.waypoints[0] and path.waypoints[1] coincide, as do all {count} waypoints: there is nothing to move",
}
