"""Checks an uploaded URDF before Pinocchio builds it, so that a bad upload gets an answer that
says what and where instead of a crash or a silently wrong model.

A usable arm here is a tree of revolute, continuous and prismatic joints (fixed joints allowed),
each with positive effort and velocity limits, revolute and prismatic joints with lower < upper,
and positive mass behind every moving joint.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ElementTree

import pinocchio as pin

from robots.errors import InvalidURDF

MOVING_JOINTS = ("revolute", "continuous", "prismatic")
MAX_JOINTS = 64


def _number(element: ElementTree.Element, attribute: str, where: str) -> float | None:
    text = element.get(attribute)
    if text is None:
        return None
    try:
        value = float(text)
    except ValueError:
        raise InvalidURDF(f"{where}: {attribute}={text!r} is not a number") from None
    if not math.isfinite(value):
        raise InvalidURDF(f"{where}: {attribute}={text!r} is not finite")
    return value


def _link_mass(link: ElementTree.Element) -> float:
    inertial = link.find("inertial")
    if inertial is None:
        return 0.0
    mass = inertial.find("mass")
    if mass is None:
        raise InvalidURDF(f"link {link.get('name')!r}: <inertial> has no <mass>")
    value = _number(mass, "value", f"link {link.get('name')!r} <mass>")
    if value is None or value < 0.0:
        raise InvalidURDF(f"link {link.get('name')!r}: mass must be a non-negative number")
    inertia = inertial.find("inertia")
    if inertia is None and value > 0.0:
        raise InvalidURDF(f"link {link.get('name')!r}: <inertial> has a mass but no <inertia>")
    return value


def check_urdf(urdf: str) -> pin.Model:
    """Validate ``urdf`` and return its Pinocchio model (fixed base).

    Raises:
        InvalidURDF: malformed XML, no joints, an unsupported joint type, missing or non-positive
            limits, a link without inertia behind a moving joint, or a model Pinocchio rejects.
    """
    try:
        root = ElementTree.fromstring(urdf)
    except ElementTree.ParseError as error:
        raise InvalidURDF(f"malformed XML: {error}") from None
    if root.tag != "robot":
        raise InvalidURDF(f"the root element is <{root.tag}>, expected <robot>")
    links = {link.get("name"): link for link in root.findall("link")}
    joints = root.findall("joint")
    for joint in joints:
        if joint.get("type") not in (*MOVING_JOINTS, "fixed"):
            raise InvalidURDF(
                f"joint {joint.get('name')!r}: type {joint.get('type')!r} is not supported (fixed-base arms only)"
            )
    moving = [joint for joint in joints if joint.get("type") in MOVING_JOINTS]
    if not moving:
        raise InvalidURDF("the URDF has no revolute, continuous or prismatic joint")
    if len(moving) > MAX_JOINTS:
        raise InvalidURDF(f"the URDF has {len(moving)} moving joints; at most {MAX_JOINTS} are served")
    children: dict[str, list[ElementTree.Element]] = {}
    for joint in joints:
        where = f"joint {joint.get('name')!r}"
        kind = joint.get("type")
        parent, child = joint.find("parent"), joint.find("child")
        if parent is None or child is None:
            raise InvalidURDF(f"{where}: needs <parent link=...> and <child link=...>")
        for end in (parent, child):
            if end.get("link") not in links:
                raise InvalidURDF(f"{where}: refers to link {end.get('link')!r}, which is not defined")
        children.setdefault(parent.get("link"), []).append(joint)
        if kind == "fixed":
            continue
        limit = joint.find("limit")
        if limit is None:
            raise InvalidURDF(f"{where}: has no <limit> (effort and velocity limits are required)")
        for attribute in ("effort", "velocity"):
            value = _number(limit, attribute, f"{where} <limit>")
            if value is None:
                raise InvalidURDF(f"{where}: <limit> has no {attribute}")
            if value <= 0.0:
                raise InvalidURDF(f"{where}: {attribute} limit must be positive, got {value}")
        if kind != "continuous":
            lower = _number(limit, "lower", f"{where} <limit>")
            upper = _number(limit, "upper", f"{where} <limit>")
            if lower is None or upper is None or not lower < upper:
                raise InvalidURDF(f"{where}: needs position limits lower < upper, got {lower}, {upper}")

    def subtree_mass(link_name: str) -> float:
        """Mass of a link and of everything rigidly fixed to it."""
        total = _link_mass(links[link_name])
        for joint in children.get(link_name, []):
            if joint.get("type") == "fixed":
                total += subtree_mass(joint.find("child").get("link"))
        return total

    for joint in moving:
        child = joint.find("child").get("link")
        if subtree_mass(child) <= 0.0:
            raise InvalidURDF(
                f"joint {joint.get('name')!r}: link {child!r} has no <inertial> with positive mass"
            )
    try:
        model = pin.buildModelFromXML(urdf)
    except (RuntimeError, ValueError) as error:
        raise InvalidURDF(f"Pinocchio cannot build the model: {error}") from None
    return model
