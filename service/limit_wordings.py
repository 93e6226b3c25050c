"""The service's words for the library's refusals of a path its limits cannot follow, with the
remedy in the request's fields: a duration too short for its law (the shortest that holds the
limits) and a path that cannot be held still within the torque limits (the torque scale or
limits that hold it). Part of ``toptraj.service.wordings.WORDING``."""

from __future__ import annotations

from collections.abc import Callable

from toptraj.robots.ranges import LIMITS


def _duration_too_short(facts: dict) -> str:
    return (
        f"{facts['field']} {facts['value']:g} s is too short for the {facts.get('method', 'timing')} law under these "
        f"limits: {'the shortest is' if facts['exact'] else 'a duration of'} {facts['stated']:g} s"
        f"{'' if facts['exact'] else ' holds them'}; give at least that or leave {facts['field']} out (the "
        f"{facts['limit']} limit of joint {facts['joint']!r} is exceeded by {100 * (facts['ratio'] - 1):.2f} % at "
        f"s = {facts['s']:.4f})"
    )


def torque_remedy(facts: dict) -> str:
    """The torque scale or limits (``torque_scale``, ``torque_limits`` among ``facts``) with
    which every joint can hold the path still everywhere, as advice; an empty string without."""
    remedies = []
    zones = facts.get("zone_scales", ())
    if zones:  # every zone listed is raised together
        remedies.append(" and ".join(f"timing.zones[{index}].torque_scale {value:g}" for index, value in zones))
    if facts.get("torque_scale") is not None:
        remedies.append(f"timing.limits.torque_scale {facts['torque_scale']:g}")
    asked = facts.get("asked_scale", 1.0)
    before = f" (before timing.limits.torque_scale {asked:g})" if asked != 1.0 else ""
    if facts.get("without_scale"):
        before = " (without timing.limits.torque_scale)"
    needed = facts.get("torque_limits", ())
    if needed:
        remedies.append("timing.limits.torque of " + " and ".join(f"{value:g} {unit} on joint {joint!r}" for joint, value, unit in needed) + before)
    beyond = facts.get("beyond_range", ())
    if beyond:
        needs = " and ".join(f"{value:.4g} {unit} on joint {joint!r}" for joint, value, unit in beyond)
        return (
            f"; holding it still would need {needs}, beyond any torque limit accepted ({facts['most']:g} {beyond[0][2]}): "
            "a lighter payload, or a path where the arm holds itself with less torque, is needed"
        )
    if not remedies:
        return ""
    return (
        f"; with {', or with '.join(remedies)} (or more) every joint can hold the path still everywhere, and a slow "
        "enough motion follows it"
    )


def _not_even_at_rest(facts: dict) -> str:
    stretches = facts["stretches"]
    shown = "; ".join(
        f"s = {item.start:.4f} to {item.end:.4f}, where holding still needs {item.worst.torque:.4g} {item.worst.unit} on joint "
        f"{item.worst.joint!r} (at s = {item.worst.s:.4f}) against its limit of {item.worst.limit:.4g} {item.worst.unit}"
        for item in stretches[:3]
    )
    more = f"; and {len(stretches) - 3} more" if len(stretches) > 3 else ""
    also = "".join(
        f"; holding still at s = {load.s:g} needs {load.torque:.4g} {load.unit} on joint {load.joint!r} against its limit of "
        f"{load.limit:.4g} {load.unit} too" for load in facts.get("ends", ())
    )
    remedy = torque_remedy(facts) or "; raise the torque limits (timing.limits.torque) or lighten the load"
    return (
        f"no motion along the path can meet the torque limits, not even at rest, on {len(stretches)} stretch(es): "
        f"{shown}{more}{also}{remedy}"
    )


def _either(words) -> str:
    """"a", "a or b", "a, b or c"."""
    words = list(words)
    return " or ".join(words) if len(words) < 3 else f"{', '.join(words[:-1])} or {words[-1]}"


def _bounding_remedies(facts: dict, example_kind: str) -> str:
    """How to bound a motion that nothing bounds: the kinds the robot has finite limits of, to
    add to the constraints held; limits of the kinds held, given in the request (a trajectory)
    or in an upload of the robot (a cell, whose arms take scales only)."""
    cell = str(facts["field"]).startswith("arms[")
    constraints = "constraints" if cell else "timing.constraints"
    extra = [kind for kind in facts["available"] if kind not in facts["kinds"]]
    remedies = []
    if extra:
        remedies.append(f"add {_either(repr(kind) for kind in extra)} to {constraints} ({facts['robot']} has finite limits of {'those kinds' if len(extra) > 1 else 'that kind'})")
    unit = LIMITS[example_kind].unit if example_kind in LIMITS else ""
    if cell and not extra:  # a cell's arms take scales only
        remedies.append("upload the robot with its limits (POST /v1/robots with joint_limits) and plan the cell with it")
    elif not cell:
        remedies.append(f'give the limits in timing.limits, e.g. "{example_kind}": one value per joint in {unit}')
    return "; or ".join(remedies)


def _no_limit_bounds_speed(facts: dict) -> str:
    kinds = facts["kinds"]
    where = f"{facts['field']}: " if str(facts["field"]).startswith("arms[") else ""
    first = next((kind for kind in kinds if kind != "torque"), "velocity")
    return (
        f"{where}nothing bounds the motion of {facts['robot']}: it has no finite {_either(kinds) or 'requested'} limit, "
        f"so the shortest time would be zero; {_bounding_remedies(facts, first)}"
    )


def _stretch_unbounded(facts: dict) -> str:
    joints = facts["joints"]
    moving = f"{'joint ' if len(joints) == 1 else 'joints '}{', '.join(repr(j) for j in joints)}" if joints else "no joint"
    cell = str(facts["field"]).startswith("arms[")
    where = f"{facts['field']}: " if cell else ""
    tool = "" if cell else " (or a tool-speed limit that holds there)"  # a cell has none
    return (
        f"{where}from s = {facts['s_from']:.4f} to {facts['s_to']:.4f} nothing bounds the motion: {moving} "
        f"{'moves' if len(joints) == 1 else 'move'} there without a finite {_either(facts['kinds'])} limit{tool}, "
        f"so the shortest time would be zero; {_bounding_remedies(facts, next((k for k in facts['kinds'] if k != 'torque'), 'velocity'))}"
    )


LIMIT_WORDING: dict[str, str | Callable[[dict], str]] = {
    "duration_too_short": _duration_too_short,
    "no_limit_bounds_speed": _no_limit_bounds_speed,
    "stretch_unbounded": _stretch_unbounded,
    "not_even_at_rest": _not_even_at_rest,
}
