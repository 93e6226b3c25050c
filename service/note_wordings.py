"""The service's words for the notes of an answer (``toptraj.robots.notes.Note``: dropped
waypoints, turns of continuous joints, corners not blended, an accuracy above its target),
as ``toptraj.service.wordings`` words the errors (``NOTE_WORDING`` is part of its ``WORDING``), and
for a URDF limit outside the range of every limit of its kind."""

from __future__ import annotations

from collections.abc import Callable

from toptraj.planners.problem.raised_limits import RAISED_FACTOR
from toptraj.planners.runner.sampling_notes import percent


def _gap_above_target(facts: dict) -> str:
    gap, intervals, method = facts["gap"], facts["intervals"], facts["method"]
    figure = f"the duration is within about {100 * gap:.2g} % of the time-optimal one on this grid"
    within = f"timing.grid_points {facts['wanted']} would bring it within {100 * facts['target']:g} %"
    phase_plane = "timing.method phase_plane refines its grid where the error lies"
    if facts["remedy"] == "grid.intervals":
        if facts["grid_given"]:
            return f"{figure} (the grid given by timing.grid_points, {intervals} intervals); {within}"
        return f"{figure} ({intervals} intervals); {within}"
    if facts["remedy"] == "method" and facts["grid_given"]:
        return f"{figure} (the grid given by timing.grid_points, {intervals} intervals; {method} serves at most {facts['cap']} on this robot): {phase_plane}"
    if facts["remedy"] == "method":
        return f"{figure} (the default grid, {intervals} intervals, refined as far as the limits, the grid cap and the time budget allowed): {phase_plane}"
    return f"{figure} ({intervals} intervals, refined as far as {method}'s grid cap and the time budget allowed)"


def _waypoints_dropped(facts: dict) -> str:
    repeats, field = facts["indices"], facts["field"]
    shown = ", ".join(map(str, repeats[:10])) + (", ..." if len(repeats) > 10 else "")
    if facts.get("coincident", True):
        if len(repeats) == 1:
            return f"{field}[{repeats[0]}] repeats the waypoint before it and was dropped"
        return f"{field} [{shown}] repeat the waypoint before each of them and were dropped ({len(repeats)} in all)"
    near = f"{facts['nearest']:.2g} rad or m"
    rule = (
        f"(the rule: a waypoint within {facts['share']:g} of the path's joint-space length, {facts['length']:.4g}, of "
        "the one kept before it, or of the last, goes)"
    )
    why = "a path through waypoints so near would turn sharply and the arm nearly stop there"
    if len(repeats) == 1:
        advice = "; path.min_spacing = 0 keeps it" if facts.get("settable") else ""
        return (
            f"{field}[{repeats[0]}] was dropped as a near repeat {rule}; it lies {near} from a waypoint kept: "
            f"{why}{advice}"
        )
    advice = "; path.min_spacing = 0 keeps them" if facts.get("settable") else ""
    return (
        f"{field} [{shown}] ({len(repeats)} in all) were dropped as near repeats {rule}; none lies farther than "
        f"{near} from a waypoint kept: {why}{advice}"
    )


def _sharp_near_pairs(facts: dict) -> str:
    pairs, field = facts["pairs"], facts["field"]
    named = "; ".join(
        f"{field}[{a}] and [{b}], {distance:.2g} rad or m apart ({distance / facts['length']:.2g} of the path's joint-space "
        f"length), the path turning by {turn:.0f} degrees"
        for a, b, distance, turn in pairs[: facts["shown"]]
    )
    more = f" (and {len(pairs) - facts['shown']} more pairs)" if len(pairs) > facts["shown"] else ""
    advice = (
        f"; path.min_spacing = {facts['spacing']:g} drops one of each pair (and any waypoint as near the one kept "
        "before it)" if facts.get("settable") else ""
    )
    return f"the arm nearly stops between waypoints so near where the path turns sharply: {named}{more}{advice}"


def _points_dropped(facts: dict) -> str:
    repeats, field = facts["indices"], facts["field"]
    if len(repeats) == 1:
        return f"{field}[{repeats[0]}] repeats the point before it and was dropped (the line stops at each point)"
    shown = ", ".join(map(str, repeats[:10])) + (", ..." if len(repeats) > 10 else "")
    return f"{field} [{shown}] repeat the point before each of them and were dropped ({len(repeats)} in all; the line stops at each point)"


def _collocation_gap(facts: dict) -> str:
    advice = (
        f": more timing.grid_points (collocation intervals, up to {facts['most_intervals']}) bring it closer"
        if facts["most_intervals"] is not None else ""
    )
    what = "duration" if facts.get("what", "duration") == "duration" else "cost, the integral of (1 + beta |tau|^2) dt,"
    return f"the {what} may lie up to {100 * facts['gap']:.2g} % above the optimum ({facts['basis']}){advice}"


def _limit_far_above_own(facts: dict) -> str:
    """A limit asked far above the robot's own, with the slips that give one: degrees for
    radians, percent for a factor (the one of override and scale that alone goes beyond)."""
    kind, unit, override, scale = facts["kind"], facts["unit"], facts["override"], facts["scale"]
    scale_field = f"timing.limits.{kind}_scale"
    given = " and ".join(
        ([f"timing.limits.{kind}[{facts['index']}] = {override:g}"] if override is not None else [])
        + ([f"{scale_field} = {scale:g}"] if scale is not None else [])
    )
    if scale is not None and (override is None or scale > RAISED_FACTOR):
        slip = f"a scale is a factor ({scale_field} = 0.8 for 80 %)"
    elif kind == "torque" or facts["prismatic"]:
        slip = f"limits are in SI units ({unit}), one per joint in the robot's joint order"
    else:
        slip = f"limits are in SI units ({unit}; radians, not degrees: 180 deg/s is 3.14 rad/s)"
    planned = "the motion is planned under it, and " if facts["held"] else ""
    return (
        f"{given} put{'s' if ' and ' not in given else ''} the {kind} limit of joint {facts['joint_name'][:64]!r} at "
        f"{facts['value']:.4g} {unit}, {facts['ratio']:.3g} times its own limit of {facts['own']:.4g} {unit}: "
        f"{planned}peak_utilization is measured against it. If that is not meant, {slip}; leave the field out to use "
        "the robot's own limits"
    )


def _missed_region(facts: dict) -> str:
    zone, distance = f"timing.zones[{facts['index']}]", facts["distance"]
    grow = (
        f"{zone}.sphere.radius by more than {distance:.4g} m" if facts["region"] == "sphere"
        else f"each edge of {zone}.box.size by more than {2 * distance:.4g} m"
    )
    return (
        f"{zone} limits nothing: the tool point (origin of frame {facts['frame']!r}) never enters its {facts['region']} "
        f"along the path; it passes {distance:.4g} m outside at its closest (s = {facts['at_s']:.4f}). To limit the "
        f"motion there, grow {grow} or move {zone}.{facts['region']}.center towards the path (world frame, m); "
        "timing.limits.tool_frame chooses the tool point"
    )


def _too_few_samples(facts: dict) -> str:
    return (
        f"output.dt = {facts['value']:g} s is {'longer than the motion' if facts['value'] > facts['duration'] else 'more than a tenth of the motion'} "
        f"({facts['duration']:.6g} s): its {facts['count']} samples do not follow the motion. output.dt is in seconds; "
        f"output.dt <= {facts['advised']:.3g} s gives {facts['samples']} samples or more"
    )


def _slowed_to_whole_periods(facts: dict) -> str:
    scale, duration = facts["scale"], facts["duration"]
    return (
        f"output.exact_period (the default of formats csv and joint_trajectory) slows the motion by "
        f"{percent(scale - 1.0)} % so that it ends on a whole period of output.dt = {facts['dt']:g} s: the samples "
        f"last {facts['stretched']:.6g} s instead of duration = {duration:.6g} s, with velocities {1 / scale:.3g}, "
        f"accelerations {scale ** -2:.3g} and jerks {scale ** -3:.3g} times the planned ones. peak_utilization is that "
        f"of the planned timing (duration), not of these samples. output.dt <= {facts['noted'] * duration:.3g} s keeps "
        f"the slowing within {100 * facts['noted']:g} %; output.exact_period false keeps the planned timing"
    )


def _obstacles_far(facts: dict) -> str:
    return (
        f"the obstacles of path.obstacles stay at least {facts['distance']:.4g} m from the arm, {facts['distance'] / facts['reach']:.0f} "
        f"times its reach ({facts['reach']:.3g} m): they constrain nothing. Obstacles are in metres, in the world frame "
        "(the robot's base frame without a mounting); a position in millimetres is a thousand times too far"
    )


def _gravity_unusual(facts: dict) -> str:
    gravity = ", ".join(f"{value:g}" for value in facts["gravity"])
    if facts["up"]:
        return (
            f"mounting.gravity [{gravity}] points up (+z in the world), and the torques follow it; the Earth's is "
            "[0, 0, -9.81] in a world whose z is up, and a ceiling-mounted arm is given by mounting.orientation "
            "([1, 0, 0, 0]) with that gravity"
        )
    return (
        f"mounting.gravity [{gravity}] has a magnitude of {facts['magnitude']:.4g} m/s^2, and the torques follow it; "
        "the Earth's is 9.81 m/s^2 (gravity is in m/s^2, not in g)"
    )


def _default_kind_not_held(facts: dict) -> str:
    kind, method = facts["kind"], facts["method"]
    peak = (
        f"; the {kind} peaks at {facts['peak']:.4g} times the limit of joint {facts['joint']!r} (peak_utilization.{kind})"
        if facts["peak"] is not None else ""
    )
    remedy = ": to hold torque limits too, use timing.method 'jerk_limited'" if kind == "torque" else ""
    return (
        f"{kind} limits are not held: timing.constraints was left out, and of its default (velocity, acceleration, "
        f"torque) timing.method {method!r} holds only {', '.join(facts['kinds'])}{peak}{remedy}"
    )


NOTE_WORDING: dict[str, str | Callable[[dict], str]] = {
    "default_kind_not_held": _default_kind_not_held,
    "gap_above_target": _gap_above_target,
    "duration_given": "not estimated: timing.duration sets the duration, which is no optimum",
    "not_estimated": "not estimated for timing.method {method}",
    "waypoints_dropped": _waypoints_dropped,
    "points_dropped": _points_dropped,
    "sharp_near_pairs": _sharp_near_pairs,
    "turned_the_short_way": lambda facts: (
        f"{facts['field']} 'shortest': continuous joint(s) {', '.join(map(repr, facts['joints']))} turn the short "
        "way; their waypoints after the first are reached as equivalent angles (whole turns apart)"
    ),
    "turns_the_long_way": lambda facts: (
        f"continuous joint {facts['joint_name']!r} turns {facts['turn']:+.4g} rad from "
        f"{facts['field']} to [{facts['index'] + 1}], more than pi: the other way round is shorter; "
        "path.continuous = 'shortest' takes it"
    ),
    "corners_not_blended": lambda facts: (
        f"{facts['field']} = {facts['value']:g} is too small to blend the corners at waypoints "
        f"{', '.join(map(str, facts['corners']))} (a blend of radius below {facts['min_blend']:g} of the path): the "
        "motion stops there"
    ),
    "corners_between_short_segments": lambda facts: (
        f"the corners at {facts['field']} {', '.join(map(str, facts['corners']))} turn too sharply for the segments "
        f"beside them (a blend within half of each has a radius below {facts['min_blend']:g} of the path): the motion "
        "stops there; path.interpolation 'spline' passes them without stopping"
    ),
    "collocation_gap": _collocation_gap,
    "limit_far_above_own": _limit_far_above_own,
    "missed_region": _missed_region,
    "too_few_samples": _too_few_samples,
    "gravity_unusual": _gravity_unusual,
    "obstacles_far": _obstacles_far,
    "slowed_to_whole_periods": _slowed_to_whole_periods,
    "urdf_limit_out_of_range": (
        "{where}: {kind} limit {value:g} {unit} in the URDF is outside the accepted range "
        "[{low:g}, {high:g}] (the range of every {kind} limit, a request's timing.limits too)"
    ),
}
