"""The service's words for the refusals of a cell of arms (arms that collide at their start, two
arms no timing keeps apart, three or four no order lets pass each other), in the request's
``arms[i]``, as ``toptraj.service.wordings`` words the other errors (``CELL_WORDING`` is part
of its ``WORDING``)."""

from __future__ import annotations

from collections.abc import Callable

from toptraj.planners.runner.duration import rounded_down, rounded_up


def _millimetres(value: float) -> str:
    """A position in m to its millimetres, as short as it prints (``-0.207``, ``0.96``, ``1000.123``)."""
    text = f"{round(value, 3):.3f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def _arms_collide_at_start(facts: dict) -> str:
    (a, b), (link_a, link_b), (robot_a, robot_b) = (facts["first"], facts["second"]), facts["links"], facts["robots"]
    distance, clearance = facts["distance"], facts["clearance"]
    lower = f", or lower clearance to {rounded_down(distance, 4):g} m or less" if distance > 0.0 else ""
    position = facts.get("position")
    move = (
        f"set arms[{b}].base.position to [{', '.join(_millimetres(x) for x in position)}] (those two links "
        f"{'overlap' if distance < 0.0 else 'are too close'}; there, every link of the two arms clears the other's at the start)"
        if position is not None else f"move arms[{b}].base farther from arms[{a}]'s"
    )
    return (
        f"the arms collide at their start: link {link_a!r} of arms[{a}] ({robot_a}) is {distance:.4g} m "
        f"from link {link_b!r} of arms[{b}] ({robot_b}) at s = 0 (the clearance is {clearance:g} m): "
        f"{move}, change either arm's first waypoint{lower}"
    )


def _arms_never_apart(facts: dict) -> str:
    (link_a, link_b), (s1, s2), room = facts["links"], facts["s_pair"], facts["room"]
    lower = f", or lower clearance to {rounded_down(room):g} m or less" if room > 0.0 else ""
    return (
        "no timing keeps the arms apart along these paths (neither waiting nor a coordinated curve through the "
        f"coordination diagram is free): every coordination of the two motions comes within {facts['distance']:.3g} m "
        f"(the clearance is {facts['clearance']:g} m); the one that keeps them farthest apart brings link {link_a!r} "
        f"of arms[0] at s = {s1:.3g} that close to link {link_b!r} of arms[1] at s = {s2:.3g}: move a base apart, "
        f"change a path{lower}"
    )


#: Pairs of arms a refusal of a cell lists at most (a detail is cut at 2,000 characters).
LISTED_PAIRS = 3


def _no_order_of_arms(facts: dict) -> str:
    turns = facts["turns"]
    pairs = sorted({tuple(sorted((turn.moving, turn.resting))) for turn in turns})
    text = (
        "no order of the arms lets each pass the others by waiting at its start (an arm's path crosses where another arm "
        "rests at its start or end)"
    )
    cycle = facts.get("cycle") or ()
    if not turns and cycle:
        chain = " before ".join(f"arms[{k}]" for k in cycle)
        return (
            f"{text}: each pair of arms can take turns, but only in orders that go round in a circle: {chain} (each of "
            "these can pass the next only by moving first, while the next rests at its start); move the base of one of "
            "them apart, or change its path so that it can also wait for the next one"
        )
    if not turns:
        return f"{text}: move a base apart, change a path or lower clearance"

    def said(turn) -> str:
        rests = f"link {turn.resting_link!r} of arms[{turn.resting}] resting at its {turn.rests_at}"
        near = f"overlaps {rests} by {-turn.distance:.3g} m" if turn.distance < 0.0 else f"comes within {turn.distance:.3g} m of {rests}"
        return f"with arms[{turn.first}] first, arms[{turn.moving}]'s link {turn.moving_link!r} at s = {turn.s:.3g} {near}"

    named = [f"arms[{a}] and arms[{b}]" for a, b in pairs]
    who = named[0] if len(named) == 1 else ", ".join(named[:-1]) + ", and " + named[-1] + ","
    each = "" if len(named) == 1 else "each "
    lower = " or lower clearance" if all(turn.distance > 0.0 for turn in turns) else ""
    listed = [turn for turn in turns if tuple(sorted((turn.moving, turn.resting))) in pairs[:LISTED_PAIRS]]
    more = f"; and {len(pairs) - LISTED_PAIRS} more pairs" if len(pairs) > LISTED_PAIRS else ""
    return (
        f"{text}: {who} can {each}take turns in neither order (the clearance is {facts['clearance']:g} m): move the bases of "
        f"{'that pair' if len(named) == 1 else 'each such pair'} apart or change a path so that each arm's path keeps clear of "
        f"the other arm at rest{lower} ({'; '.join(said(turn) for turn in listed)}{more})"
    )


def _arm_not_held(facts: dict) -> str:
    index, unit = facts["index"], facts["unit"]
    remedies = []
    if facts["scaled"] and facts["torque"] <= facts["own_limit"]:  # the robot's own limit holds it
        needed = rounded_up(facts["torque"] / facts["own_limit"] * 1.001, 3)
        remedies.append(f"raise arms[{index}].torque_scale to {needed:g} or more (at most 1)")
    if facts["carrying"]:
        remedies.append(f"lighten arms[{index}].payload")
    remedies.append(f"move arms[{index}].waypoints there to where the arm holds itself with less torque")
    return (
        f"arms[{index}] ({facts['robot']}): holding its path still at s = {facts['s']:.4f} needs {facts['torque']:.4g} {unit} "
        f"on joint {facts['joint']!r}, above its torque limit of {facts['torque_limit']:.4g} {unit} "
        f"(gravity{' and payload' if facts['carrying'] else ''}): no timing holds it; {', or '.join(remedies)}"
    )


CELL_WORDING: dict[str, str | Callable[[dict], str]] = {
    "arm_not_held": _arm_not_held,
    "clearance_samples": (
        "checking the arms' clearance needs {count} samples (one for every 5 mm any point of an arm moves), more than "
        "{most}: split the motion into {parts} cells or more, each arm's waypoints into as many parts (the waypoint "
        "where one part ends starting the next)"
    ),
    "arms_collide_at_start": _arms_collide_at_start,
    "arms_never_apart": _arms_never_apart,
    "no_order_of_arms": _no_order_of_arms,
}
