"""The structure of an uploaded URDF (``toptraj.robots.urdf_check``): one tree of links, each link the
child of at most one joint, a single root, no cycle, every link and joint named once, only
revolute, continuous, prismatic and fixed joints, and at most ``MAX_LINKS`` links,
``MAX_JOINTS`` joints and ``MAX_MOVING_JOINTS`` moving joints; a ``<mimic>`` names a moving joint. Each refusal is an
``InvalidURDF`` naming the joint or link. The walk is iterative: a chain of any length is
checked in linear time and constant stack.
"""

from __future__ import annotations

import xml.etree.ElementTree as ElementTree

from toptraj.robots.errors import InvalidURDF, excerpt

MOVING_JOINTS = ("revolute", "continuous", "prismatic")
MAX_MOVING_JOINTS = 64
MAX_LINKS = 1_000
MAX_JOINTS = 1_000


def _named(elements: list[ElementTree.Element], tag: str) -> dict[str, ElementTree.Element]:
    named: dict[str, ElementTree.Element] = {}
    for element in elements:
        name = element.get("name")
        if not name:
            raise InvalidURDF(f"a <{tag}> has no name")
        if name in named:
            raise InvalidURDF(f"two <{tag}> elements are named {excerpt(name)}; names must be unique")
        if any(ord(character) < 32 or ord(character) == 127 for character in name):
            # a name is a column of the answers' CSV, a line of its own: no line break, no tab
            raise InvalidURDF(f"{tag} {excerpt(name)}: its name holds a control character (a line break, a tab); rename it")
        named[name] = element
    return named


def _parent_joints(links: dict, joints: dict) -> dict[str, str]:
    """Map child link -> the one joint whose child it is; checks that the links form one tree.

    Walks iteratively, so that a chain of any length is checked in linear time and constant stack.
    """
    parent_joint: dict[str, str] = {}
    for name, joint in joints.items():
        where = f"joint {excerpt(name)}"
        parent, child = joint.find("parent"), joint.find("child")
        if parent is None or child is None:
            raise InvalidURDF(f"{where}: needs <parent link=...> and <child link=...>")
        for end in (parent, child):
            if end.get("link") not in links:
                raise InvalidURDF(f"{where}: refers to link {excerpt(end.get('link'))}, which is not defined")
        child_name = child.get("link")
        if child_name in parent_joint:
            raise InvalidURDF(
                f"{where}: link {excerpt(child_name)} is already the child of joint "
                f"{excerpt(parent_joint[child_name])}; a URDF is a tree, each link has at most one parent joint"
            )
        parent_joint[child_name] = name
    roots = [name for name in links if name not in parent_joint]
    if len(roots) > 1:
        raise InvalidURDF(
            f"links {excerpt(roots[0])} and {excerpt(roots[1])} both have no parent joint; "
            "a URDF is one tree with a single root link"
        )
    children: dict[str, list[str]] = {}
    for child_name, joint_name in parent_joint.items():
        children.setdefault(joints[joint_name].find("parent").get("link"), []).append(child_name)
    reached = set(roots)
    stack = list(roots)
    while stack:
        for child_name in children.get(stack.pop(), []):
            reached.add(child_name)
            stack.append(child_name)
    unreached = [name for name in links if name not in reached]
    if unreached:
        raise InvalidURDF(_cycle_message(unreached[0], parent_joint, joints))
    return parent_joint


def _cycle_message(start: str, parent_joint: dict[str, str], joints: dict) -> str:
    """Follow parent joints from ``start`` (a link no root reaches) until a link repeats."""
    seen: dict[str, int] = {}
    path: list[str] = []
    link = start
    while link not in seen:
        seen[link] = len(path)
        path.append(parent_joint[link])
        link = joints[parent_joint[link]].find("parent").get("link")
    cycle = path[seen[link] :]
    named = ", ".join(excerpt(name) for name in cycle[:5]) + (", ..." if len(cycle) > 5 else "")
    return f"joint {excerpt(cycle[0])}: joints {named} form a cycle; a URDF is a tree without cycles"


def check_structure(root: ElementTree.Element) -> tuple[dict, dict, dict[str, str]]:
    """The links and joints of the URDF's ``root`` element by name, and each child link's
    parent joint, once they are checked to form one tree of supported joints."""
    link_elements, joint_elements = root.findall("link"), root.findall("joint")
    if len(link_elements) > MAX_LINKS:
        raise InvalidURDF(f"the URDF has {len(link_elements)} links; at most {MAX_LINKS} are served")
    if len(joint_elements) > MAX_JOINTS:
        raise InvalidURDF(f"the URDF has {len(joint_elements)} joints; at most {MAX_JOINTS} are served")
    links, joints = _named(link_elements, "link"), _named(joint_elements, "joint")
    for name, joint in joints.items():
        if joint.get("type") not in (*MOVING_JOINTS, "fixed"):
            raise InvalidURDF(
                f"joint {excerpt(name)}: type {excerpt(joint.get('type'))} is not supported (fixed-base arms only)"
            )
    moving = [name for name, joint in joints.items() if joint.get("type") in MOVING_JOINTS]
    if not moving:
        raise InvalidURDF("the URDF has no revolute, continuous or prismatic joint")
    if len(moving) > MAX_MOVING_JOINTS:
        raise InvalidURDF(f"the URDF has {len(moving)} moving joints; at most {MAX_MOVING_JOINTS} are served")
    return links, joints, _parent_joints(links, joints)


def check_mimic(joint: ElementTree.Element, joints: dict, where: str) -> None:
    """A ``<mimic>`` names a moving joint of the URDF."""
    element = joint.find("mimic")
    if element is None:
        return
    mimicked = element.get("joint")
    if mimicked is None:
        raise InvalidURDF(f"{where}: <mimic> names no joint; give the joint it follows (joint=...), or remove the <mimic> element")
    if joints.get(mimicked) is None or joints[mimicked].get("type") not in MOVING_JOINTS:
        raise InvalidURDF(
            f"{where}: <mimic joint={excerpt(mimicked)}> names no revolute, continuous or prismatic joint of the URDF; "
            "name the joint it follows, or remove the <mimic> element"
        )


def mimic_joints(urdf: str) -> list[tuple[str, str, float, float]]:
    """(joint, the joint it mimics, multiplier, offset) of each ``<mimic>`` of a moving joint of
    ``urdf`` (already checked by ``toptraj.robots.urdf_check.check_urdf``), in the URDF's order:
    the joints of the ``<robot>`` element itself, as the checks read them (a ``<joint>`` inside
    another element, a ``<gazebo>``'s, is none of the robot's)."""
    found = []
    for joint in ElementTree.fromstring(urdf).findall("joint"):
        element = joint.find("mimic")
        if element is not None and joint.get("type") in MOVING_JOINTS:
            multiplier, offset = (float(element.get(name, default)) for name, default in (("multiplier", "1"), ("offset", "0")))
            found.append((joint.get("name", ""), element.get("joint", ""), multiplier, offset))
    return found
