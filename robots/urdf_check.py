"""Checks an uploaded URDF before Pinocchio builds it, so that a bad upload gets an answer that
says what and where instead of a crash, a hang or a silently wrong model.

A usable arm here is one tree of links (one root, each link the child of at most one joint, no
cycle) joined by revolute, continuous and prismatic joints (fixed joints allowed), each moving
joint with effort and velocity limits, revolute and prismatic joints with lower < upper, and
inertia behind every moving joint. Every number Pinocchio reads must be a plain decimal number
inside the bounds below (SI units), wide enough for any real arm and tight enough that nothing
overflows or underflows in the dynamics:

==========================================  =========================================
origins ``xyz`` (joints, inertials, shapes)  each coordinate within +-100 m
origins ``rpy``                              each angle within +-100 rad
geometry sizes (box, cylinder, sphere)       0 to 100 m; mesh scale within +-1000
mass                                         1e-12 to 1e6 kg (0 only for a massless link)
inertia tensor entries                       within +-1e6 kg m^2
effort limit                                 1e-6 to 1e5 N m (or N)
velocity limit                               1e-6 to 1e3 rad/s (or m/s)
position limits                              within +-1e4 rad (or m), lower < upper
damping, friction                            0 to 1e6
==========================================  =========================================

The effort and velocity bounds are those of every torque and velocity limit, whatever its
source (``toptraj.robots.ranges``, the ranges of a request's ``timing.limits`` too); the lower bound of
1e-6 refuses limits such as 1e-308 that are positive in name only (no real drive is that weak;
every duration would overflow). An effort or velocity of 0 is refused as well: the URDF
specification makes both attributes required limits, not "unlimited". Every ``<inertial>``
has a positive mass, except a massless frame (mass and tensor all zero, as Panda's
``panda_link8``). An inertia tensor must be one that a body can have: positive definite, with
principal moments that satisfy the triangle inequality ``I1 + I2 >= I3`` (up to a relative 1e-3
for values printed to three digits). Two ideal limits that real URDFs use pass as well, because
the triangle inequality allows them and refusing them would refuse arms of the catalog: a point
mass (a zero tensor, TALOS's force-sensor links, SO-101's gripper frame) and a slender rod (one
zero moment, the other two equal, ``finger_edu``'s lower link). Once built, the joint-space
inertia matrix at the zero configuration must be positive definite (condition number at most
1e10): every moving joint moves some inertia about its axis, which is what the planners need.

At most 1000 links, 1000 joints and 64 moving joints (the tree's checks: ``toptraj.robots.urdf_tree``);
no ``<!DOCTYPE>`` (entities could make Pinocchio's parser read something else than this check
did).
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ElementTree
from collections.abc import Iterable

import numpy as np
import pinocchio as pin

from toptraj.robots.errors import InvalidURDF, excerpt
from toptraj.robots.ranges import TORQUE, VELOCITY
from toptraj.robots.urdf_tree import MOVING_JOINTS, check_mimic, check_structure

MAX_OFFSET = 100.0  # m, each coordinate of an origin
MAX_ANGLE = 100.0  # rad, each angle of an origin's rpy
MAX_SIZE = 100.0  # m, box sides, radii and lengths
MAX_MESH_SCALE = 1e3
MIN_MASS, MAX_MASS = 1e-12, 1e6  # kg
MAX_INERTIA = 1e6  # kg m^2, each tensor entry
EFFORT_RANGE = (TORQUE.low, TORQUE.high)  # N m (revolute) or N (prismatic)
VELOCITY_RANGE = (VELOCITY.low, VELOCITY.high)  # rad/s or m/s
MAX_POSITION = 1e4  # rad or m
MAX_DAMPING = 1e6  # N m s/rad or N s/m
MAX_FRICTION = 1e6  # N m or N
MAX_OTHER = 1e6  # safety controller, calibration and mimic values
TRIANGLE_TOLERANCE = 1e-3  # relative to the largest principal moment
ROUND_OFF = 1e-9  # relative to the largest principal moment: what counts as a zero moment
MAX_JOINT_SPACE_CONDITION = 1e10

#: Decimal numbers as C++ parsers read them (no hex, no digit separators), plus the words that
#: Python would read as non-finite values, so the answer can say "not finite".
_NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?")
_NON_FINITE = re.compile(r"[+-]?(nan|inf|infinity)", re.IGNORECASE)


def _parse(text: str, where: str, attribute: str) -> float:
    if _NUMBER.fullmatch(text):
        value = float(text)
        if math.isfinite(value):
            return value
    elif not _NON_FINITE.fullmatch(text):
        raise InvalidURDF(f"{where}: {attribute}={excerpt(text)} is not a number")
    raise InvalidURDF(f"{where}: {attribute}={excerpt(text)} is not finite")


def _scalar(element: ElementTree.Element, attribute: str, where: str) -> float | None:
    """The attribute as a finite float, ``None`` when absent."""
    text = element.get(attribute)
    return None if text is None else _parse(text.strip(), where, attribute)


def _vector(element: ElementTree.Element, attribute: str, where: str) -> np.ndarray | None:
    """The attribute as three finite floats, ``None`` when absent."""
    text = element.get(attribute)
    if text is None:
        return None
    parts = text.split()
    if len(parts) != 3:
        raise InvalidURDF(f"{where}: {attribute}={excerpt(text)} must hold three numbers")
    return np.array([_parse(part, where, attribute) for part in parts])


def _within(value: float, lower: float, upper: float, where: str, what: str, unit: str) -> None:
    if not lower <= value <= upper:
        unit = f" {unit}" if unit else ""
        raise InvalidURDF(f"{where}: {what} {value:g}{unit} is outside [{lower:g}, {upper:g}]")


def _check_origin(element: ElementTree.Element, where: str) -> None:
    origin = element.find("origin")
    if origin is None:
        return
    xyz = _vector(origin, "xyz", f"{where} <origin>")
    if xyz is not None and np.abs(xyz).max() > MAX_OFFSET:
        raise InvalidURDF(f"{where}: <origin> xyz {_numbers(xyz)} m is farther than {MAX_OFFSET:g} m along an axis")
    rpy = _vector(origin, "rpy", f"{where} <origin>")
    if rpy is not None and np.abs(rpy).max() > MAX_ANGLE:
        raise InvalidURDF(f"{where}: <origin> rpy {_numbers(rpy)} rad has an angle beyond +-{MAX_ANGLE:g} rad")


def _numbers(values: Iterable[float]) -> str:
    return ", ".join(f"{value:g}" for value in values)


_SHAPES = ("box", "cylinder", "sphere", "capsule", "mesh")


def _check_geometry(link: ElementTree.Element, where: str) -> None:
    for kind in ("visual", "collision"):
        for part in link.findall(kind):
            place = f"{where} <{kind}>"
            _check_origin(part, place)
            geometry = part.find("geometry")
            if geometry is None:
                continue
            for shape in geometry:
                if shape.tag not in _SHAPES:
                    continue  # Pinocchio reads no other shape
                shape_where = f"{place} <{shape.tag}>"
                sizes: list[float]
                if shape.tag == "box":
                    box = _vector(shape, "size", shape_where)
                    sizes = [] if box is None else list(box)
                elif shape.tag == "mesh":
                    scale = _vector(shape, "scale", shape_where)
                    if scale is not None and np.abs(scale).max() > MAX_MESH_SCALE:
                        raise InvalidURDF(f"{shape_where}: scale {_numbers(scale)} is beyond +-{MAX_MESH_SCALE:g}")
                    sizes = []
                else:
                    sizes = [
                        value
                        for value in (_scalar(shape, name, shape_where) for name in ("radius", "length"))
                        if value is not None
                    ]
                for size in sizes:
                    _within(size, 0.0, MAX_SIZE, shape_where, "size", "m")


_INERTIA_ENTRIES = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")


def _link_mass(link: ElementTree.Element, where: str) -> float:
    """Mass of ``link`` in kg (0 without ``<inertial>``), after checking its inertial."""
    inertial = link.find("inertial")
    if inertial is None:
        return 0.0
    _check_origin(inertial, f"{where} <inertial>")
    mass_element = inertial.find("mass")
    if mass_element is None:
        raise InvalidURDF(f"{where}: <inertial> has no <mass>")
    mass = _scalar(mass_element, "value", f"{where} <mass>")
    if mass is None:
        raise InvalidURDF(f"{where}: <mass> has no value")
    if mass != 0.0:
        _within(mass, MIN_MASS, MAX_MASS, where, "mass", "kg")
    inertia = inertial.find("inertia")
    if inertia is None:
        if mass > 0.0:
            raise InvalidURDF(f"{where}: <inertial> has a mass but no <inertia>")
        return mass
    entries = {}
    for name in _INERTIA_ENTRIES:
        value = _scalar(inertia, name, f"{where} <inertia>")
        if value is None:
            raise InvalidURDF(f"{where}: <inertia> needs all of {', '.join(_INERTIA_ENTRIES)}; {name} is missing")
        if abs(value) > MAX_INERTIA:
            raise InvalidURDF(f"{where}: <inertia> {name}={value:g} kg m^2 is beyond +-{MAX_INERTIA:g}")
        entries[name] = value
    if not any(entries.values()):
        return mass  # a point mass, or with zero mass a massless frame
    if mass == 0.0:
        raise InvalidURDF(f"{where}: mass must be positive where the inertia tensor is not zero")
    _check_tensor(entries, where)
    return mass


def _check_tensor(entries: dict[str, float], where: str) -> None:
    """Positive (semi-)definite, principal moments obeying the triangle inequality."""
    e = entries
    tensor = np.array(
        [[e["ixx"], e["ixy"], e["ixz"]], [e["ixy"], e["iyy"], e["iyz"]], [e["ixz"], e["iyz"], e["izz"]]]
    )
    moments = np.linalg.eigvalsh(tensor)  # ascending
    if not (moments[2] > 0.0 and moments[0] >= -ROUND_OFF * moments[2]):
        raise InvalidURDF(
            f"{where}: the inertia tensor is not positive definite (principal moments {_numbers(moments)} kg m^2)"
        )
    if moments[0] + moments[1] < moments[2] * (1.0 - TRIANGLE_TOLERANCE):
        raise InvalidURDF(
            f"{where}: the principal moments of inertia {_numbers(moments)} kg m^2 break the triangle "
            "inequality (no body has one moment larger than the sum of the other two)"
        )


def _check_limits(joint: ElementTree.Element, kind: str, where: str) -> None:
    limit = joint.find("limit")
    if limit is None:
        if kind in MOVING_JOINTS:
            raise InvalidURDF(f"{where}: has no <limit> (effort and velocity limits are required)")
        return
    place = f"{where} <limit>"
    values = {name: _scalar(limit, name, place) for name in ("effort", "velocity", "lower", "upper")}
    if kind not in MOVING_JOINTS:
        return
    for name, (lowest, highest), unit in (
        ("effort", EFFORT_RANGE, "N m (N for prismatic)"),
        ("velocity", VELOCITY_RANGE, "rad/s (m/s for prismatic)"),
    ):
        value = values[name]
        if value is None:
            raise InvalidURDF(f"{where}: <limit> has no {name}")
        if value <= 0.0:
            raise InvalidURDF(f"{where}: {name} limit must be positive, got {value:g}")
        if not lowest <= value <= highest:
            raise InvalidURDF(
                f"{where}: {name} limit {value:g} {unit} in the URDF is outside the accepted range "
                f"[{lowest:g}, {highest:g}] (the range of every {name} limit, a request's too)",
                rule="urdf_limit_out_of_range", where=where, kind=name, value=value, unit=unit, low=lowest, high=highest,
            )
    lower, upper = values["lower"], values["upper"]
    if kind == "continuous":
        return
    if lower is None or upper is None or not lower < upper:
        raise InvalidURDF(f"{where}: needs position limits lower < upper, got {lower}, {upper}")
    for name, value in (("lower", lower), ("upper", upper)):
        _within(value, -MAX_POSITION, MAX_POSITION, where, f"{name} position limit", "rad (m for prismatic)")


def _check_joint_numbers(joint: ElementTree.Element, kind: str, where: str) -> None:
    _check_origin(joint, where)
    axis_element = joint.find("axis")
    if axis_element is not None:
        axis = _vector(axis_element, "xyz", f"{where} <axis>")
        if kind in MOVING_JOINTS and axis is not None and not 1e-6 <= np.abs(axis).max() <= MAX_OTHER:
            raise InvalidURDF(f"{where}: <axis> xyz {_numbers(axis)} must be a direction (a unit vector)")
    _check_limits(joint, kind, where)
    dynamics = joint.find("dynamics")
    if dynamics is not None:
        for name, highest in (("damping", MAX_DAMPING), ("friction", MAX_FRICTION)):
            value = _scalar(dynamics, name, f"{where} <dynamics>")
            if value is not None:
                _within(value, 0.0, highest, where, name, "")
    for tag, names in (
        ("safety_controller", ("soft_lower_limit", "soft_upper_limit", "k_position", "k_velocity")),
        ("calibration", ("rising", "falling", "reference_position")),
        ("mimic", ("multiplier", "offset")),
    ):
        element = joint.find(tag)
        if element is None:
            continue
        for name in names:
            value = _scalar(element, name, f"{where} <{tag}>")
            if value is not None:
                _within(value, -MAX_OTHER, MAX_OTHER, where, f"<{tag}> {name}", "")


def _check_mass_behind_moving_joints(links: dict, joints: dict, masses: dict[str, float]) -> None:
    rigid_children: dict[str, list[str]] = {}
    for joint in joints.values():
        if joint.get("type") == "fixed":
            rigid_children.setdefault(joint.find("parent").get("link"), []).append(joint.find("child").get("link"))
    for name, joint in joints.items():
        if joint.get("type") not in MOVING_JOINTS:
            continue
        child = joint.find("child").get("link")
        stack, total = [child], 0.0
        while stack:
            link = stack.pop()
            total += masses[link]
            stack.extend(rigid_children.get(link, []))
        if total <= 0.0:
            raise InvalidURDF(
                f"joint {excerpt(name)}: link {excerpt(child)} has no <inertial> with positive mass"
            )


def _check_joint_space_inertia(model: pin.Model) -> None:
    """The mass matrix at the zero configuration is positive definite and not near singular."""
    inertia = pin.crba(model, model.createData(), pin.neutral(model))
    inertia = np.triu(inertia) + np.triu(inertia, 1).T
    values, vectors = np.linalg.eigh(inertia)
    if not values[0] > values[-1] / MAX_JOINT_SPACE_CONDITION:
        weakest = int(np.argmax(np.abs(vectors[:, 0])))
        joint = next(name for name, j in zip(model.names[1:], model.joints[1:]) if j.idx_v <= weakest < j.idx_v + j.nv)
        raise InvalidURDF(
            f"joint {excerpt(joint)}: moves (almost) no inertia about its axis (the joint-space inertia "
            f"matrix has eigenvalues from {values[0]:.3g} to {values[-1]:.3g}); give the links it moves "
            "a mass off its axis or a rotational inertia"
        )


#: Deepest nesting of elements accepted (a URDF's deepest is some five: robot > link >
#: collision > geometry > mesh; Pinocchio's parser refuses about 500 without a reason).
MAX_XML_DEPTH = 32


def _check_tree(root: ElementTree.Element) -> None:
    """Refuse, in one walk without recursion, an element in an XML namespace (the checks read a
    URDF's elements by their plain names, and would pass over a namespaced ``<joint>`` that
    Pinocchio's parser still builds) and elements nested deeper than ``MAX_XML_DEPTH``, naming
    the first."""
    stack = [(root, 1, "robot")]
    while stack:
        element, depth, path = stack.pop()
        if isinstance(element.tag, str) and element.tag.startswith("{"):
            namespace, _, tag = element.tag[1:].partition("}")
            raise InvalidURDF(
                f"the element <{tag[:40]}> is in the XML namespace {excerpt(namespace, 80)}, and a URDF's "
                "elements are in none: remove the xmlns attribute that puts it there"
            )
        if depth > MAX_XML_DEPTH:
            raise InvalidURDF(
                f"the URDF nests elements {MAX_XML_DEPTH + 1} levels deep and more ({path[:200]}); a URDF nests a few "
                "(robot > link > collision > geometry > mesh): remove the elements nested inside one another"
            )
        stack.extend((child, depth + 1, f"{path} > {str(child.tag)[:40]}" if depth < 4 else path) for child in element)


def check_urdf(urdf: str) -> pin.Model:
    """Validate ``urdf`` and return its Pinocchio model (fixed base).

    Raises:
        InvalidURDF: malformed XML, a document type declaration, links that do not form one tree
            (several parents, several roots, a cycle), too many links or joints, an unsupported
            joint type, a number that is not finite or outside the module's bounds, missing
            limits, a mass or inertia that no body has, no inertia behind a moving joint, or a
            model Pinocchio rejects. The detail names the link or joint.
    """
    if "<!DOCTYPE" in urdf:
        raise InvalidURDF("the URDF holds a <!DOCTYPE> declaration; document types and entities are not accepted")
    try:
        root = ElementTree.fromstring(urdf)
    except ElementTree.ParseError as error:
        text = urdf.strip()
        if not text:
            raise InvalidURDF("the URDF is empty: give the text of a URDF file (<robot name=...> ... </robot>)") from None
        looks_like_a_path = "/" in text or "\\" in text or text.lower().endswith((".urdf", ".xacro", ".xml"))
        if looks_like_a_path and not text.startswith("<") and "\n" not in text and len(text) < 4096:
            raise InvalidURDF(
                f"the URDF is the text {excerpt(text, 80)}, not XML: give the file's contents, not its name "
                "(jq -n --rawfile urdf FILE '{name: \"my_arm\", urdf: $urdf}' writes a body holding them, as the "
                "guide's Uploads page shows)"
            ) from None
        raise InvalidURDF(f"malformed XML: {excerpt(str(error), 200)}") from None
    _check_tree(root)
    if root.tag != "robot":
        tag = root.tag if len(root.tag) <= 40 else f"{root.tag[:40]}..."
        raise InvalidURDF(f"the root element is <{tag}>, expected <robot>")
    links, joints, _ = check_structure(root)
    masses = {}
    for name, link in links.items():
        where = f"link {excerpt(name)}"
        masses[name] = _link_mass(link, where)
        _check_geometry(link, where)
    for name, joint in joints.items():
        _check_joint_numbers(joint, joint.get("type"), f"joint {excerpt(name)}")
        check_mimic(joint, joints, f"joint {excerpt(name)}")
    _check_mass_behind_moving_joints(links, joints, masses)
    try:
        model = pin.buildModelFromXML(urdf)
    except Exception as error:  # Pinocchio's parser raises RuntimeError, ValueError and others
        raise InvalidURDF(f"Pinocchio cannot build the model: {excerpt(str(error), 300)}") from None
    _check_joint_space_inertia(model)
    return model


def mesh_count(urdf: str) -> int:
    """How many distinct mesh files the ``<visual>`` and ``<collision>`` elements of ``urdf``
    (already checked by ``check_urdf``) refer to; none of them is loaded."""
    root = ElementTree.fromstring(urdf)
    return len({mesh.get("filename", "") for mesh in root.iter("mesh")})
