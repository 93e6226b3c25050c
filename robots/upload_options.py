"""What an upload may add to its URDF: joints locked at a value, and limits in the form of
MoveIt's ``joint_limits.yaml``.

* ``locked_joints`` {joint: value (rad or m)}: the robot is the reduced model with those joints
  fixed (``pinocchio.buildReducedModel``), as the catalog locks Panda's fingers: an uploaded
  Panda with both finger joints locked plans its 7 arm joints.
* ``allowed_collisions``: pairs of links allowed to touch, as an SRDF's ``disable_collisions``
  (its text) or a list of [link, link] pairs (``toptraj.robots.srdf``, bounded there).
* ``joint_limits``: the text of a ``joint_limits.yaml`` (or the same structure as JSON):

      joint_limits:
        shoulder_pan_joint:
          has_velocity_limits: true
          max_velocity: 3.15
          has_acceleration_limits: true
          max_acceleration: 10.0
          has_jerk_limits: false

  A ``max_*`` applies where its ``has_*_limits`` is true, as in MoveIt. Acceleration and jerk
  limits (which URDFs do not carry) are taken as given. Velocity and effort limits tighten the
  URDF's: where the file allows more than the URDF, the URDF's limit is kept and the robot's
  notes say so. Position limits stay the URDF's (noted when the file gives them), and
  MoveIt's default scaling factors are not applied (noted): requests scale limits themselves.

The text is read by ``toptraj.robots.bounded_yaml`` (at most 100,000 characters, 32 levels, 10,000
values with aliases expanded, 1,000 aliases; string keys, each once per mapping), and the same
structure given as JSON is held to the same depth and count. Every maximum lies in the accepted
range of its kind (``toptraj.robots.ranges``: the range of a request's ``timing.limits`` overrides).

Options are checked against the URDF's model before anything is stored; a wrong joint name, a
value outside the joint's range, a limit outside its accepted range or a malformed file is an
``InvalidUpload`` (422) naming the joint, the key and, for a limit, its source and range.
"""

from __future__ import annotations

import dataclasses
import json
import math
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin
import yaml

from toptraj.robots import bounded_yaml
from toptraj.robots.equipment import Payload
from toptraj.robots.errors import InvalidUpload, excerpt
from toptraj.robots.ranges import limit_problem
from toptraj.robots.srdf import allowed_pairs

#: The keys of a joint's entry in joint_limits.yaml, and the limit kind each maximum sets.
_MAXIMA = {"max_velocity": "velocity", "max_acceleration": "acceleration", "max_jerk": "jerk", "max_effort": "torque"}
_FLAGS = {"velocity": "has_velocity_limits", "acceleration": "has_acceleration_limits", "jerk": "has_jerk_limits",
          "torque": "has_effort_limits"}
_POSITION_KEYS = {"has_position_limits", "min_position", "max_position", "angle_wraparound"}
_KNOWN_KEYS = set(_MAXIMA) | set(_FLAGS.values()) | _POSITION_KEYS
_SCALING_KEYS = {"default_velocity_scaling_factor", "default_acceleration_scaling_factor"}
#: Largest joint_limits text accepted, in characters.
MAX_LIMITS_CHARS = bounded_yaml.MAX_CHARS


@dataclass(frozen=True)
class UploadOptions:
    """Checked options of an upload.

    Attributes:
        locked_joints: {joint name: value (rad, m)}, in the order given.
        joint_limits: {joint name: {kind: value}}, kinds among velocity, acceleration, jerk,
            torque (rad/s, rad/s^2, rad/s^3, N m; m/s..., N for prismatic joints).
        notes: What the file gave that is not applied (position limits, scaling factors).
        payload: The payload the robot carries unless a request gives its own
            (``toptraj.robots.equipment.Payload``), ``None``: none.
        allowed_collisions: Pairs of links allowed to touch (``toptraj.robots.srdf``), sorted.
    """

    locked_joints: dict[str, float] = field(default_factory=dict)
    joint_limits: dict[str, dict[str, float]] = field(default_factory=dict)
    notes: tuple[str, ...] = ()
    payload: Payload | None = None
    allowed_collisions: tuple[tuple[str, str], ...] = ()

    def __bool__(self) -> bool:
        return bool(self.locked_joints or self.joint_limits or self.notes or self.payload or self.allowed_collisions)

    def to_json(self) -> str:
        """Canonical JSON for the store ("" for no options, what records stored before options
        existed hold)."""
        if not self:
            return ""
        written: dict = {"locked_joints": self.locked_joints, "joint_limits": self.joint_limits, "notes": list(self.notes)}
        if self.payload is not None:
            written["payload"] = dataclasses.asdict(self.payload)
        if self.allowed_collisions:  # records without the key read as before
            written["allowed_collisions"] = [list(item) for item in self.allowed_collisions]
        return json.dumps(written, sort_keys=True, separators=(",", ":"))

    @classmethod
    def from_json(cls, text: str | None) -> UploadOptions:
        """The options ``to_json`` wrote ("" or ``None``: none)."""
        if not text:
            return cls()
        data = json.loads(text)
        held = data.get("payload")
        payload = None if held is None else Payload(
            held["mass"], tuple(held["center_of_mass"]), tuple(held["inertia"]), held.get("frame"), float(held.get("radius", 0.0))
        )
        return cls(
            dict(data.get("locked_joints", {})), dict(data.get("joint_limits", {})), tuple(data.get("notes", ())), payload,
            tuple((str(a), str(b)) for a, b in data.get("allowed_collisions", ())),
        )


def _short(name) -> str:
    """A name as a dotted path shows it, cut at 40 characters."""
    name = str(name)
    return name if len(name) <= 40 else f"{name[:40]}..."


def _number(value, where: str) -> float:
    """``value`` as a finite float; an integer too large for a float counts as not finite."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise InvalidUpload(f"{where} must be a finite number, got {excerpt(value, 40)}")
    try:
        number = float(value)
    except OverflowError:
        number = math.inf
    if not math.isfinite(number):
        raise InvalidUpload(f"{where} must be a finite number, got {excerpt(value, 40)}")
    return number


def _check_json_structure(given) -> None:
    """Hold a joint_limits given as JSON to the bounds of the YAML text (``toptraj.robots.bounded_yaml``):
    at most ``MAX_DEPTH`` levels and ``MAX_NODES`` values, walked without recursion."""
    stack, count = [(given, 1)], 0
    while stack:
        value, depth = stack.pop()
        count += 1
        if depth > bounded_yaml.MAX_DEPTH or count > bounded_yaml.MAX_NODES:
            raise InvalidUpload(
                f"joint_limits nests more than {bounded_yaml.MAX_DEPTH} levels deep or holds more than "
                f"{bounded_yaml.MAX_NODES} values; a joint_limits.yaml needs 3 levels and a few values per joint"
            )
        if isinstance(value, dict):
            stack.extend((item, depth + 1) for item in value.values())
        elif isinstance(value, list):
            stack.extend((item, depth + 1) for item in value)


def _parsed(given):
    """The structure of a joint_limits text (YAML, read within ``toptraj.robots.bounded_yaml``'s bounds)
    or of one given as JSON (held to the same bounds)."""
    if not isinstance(given, str):
        _check_json_structure(given)
        return given
    try:
        return bounded_yaml.load(given)
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        context, problem = getattr(error, "context", None), getattr(error, "problem", None) or str(error)
        problem = excerpt(f"{context}, {problem}" if context else problem, 200)[1:-1]
        if isinstance(error, bounded_yaml.BoundedYAMLError):
            raise InvalidUpload(f"joint_limits is refused{where}: {problem}") from None
        raise InvalidUpload(f"joint_limits is not valid YAML{where}: {problem}") from None


def _joint_limits(given) -> tuple[dict[str, dict[str, float]], list[str]]:
    """{joint: {kind: value}} and notes from a joint_limits.yaml text or its parsed structure."""
    given = _parsed(given)
    if not isinstance(given, dict) or not isinstance(given.get("joint_limits"), dict):
        raise InvalidUpload(
            "joint_limits must hold a 'joint_limits' mapping of joint names to their limits, as MoveIt's "
            "joint_limits.yaml does (joint_limits: {joint: {has_acceleration_limits: true, max_acceleration: 10.0}})"
        )
    notes = []
    unknown = sorted(set(given) - {"joint_limits"} - _SCALING_KEYS, key=str)
    if unknown:
        raise InvalidUpload(f"joint_limits: unknown top-level key {excerpt(unknown[0], 40)}; expected 'joint_limits'")
    scaling = sorted(set(given) & _SCALING_KEYS, key=str)
    if scaling:
        notes.append(f"joint_limits.yaml's {', '.join(scaling)} not applied: requests scale limits (a request's limit scales)")
    limits: dict[str, dict[str, float]] = {}
    positions = []
    for joint, entry in given["joint_limits"].items():
        where = f"joint_limits.{_short(joint)}"
        if not isinstance(entry, dict):
            raise InvalidUpload(f"{where} must be a mapping of limit keys (max_velocity, max_acceleration, ...)")
        unknown = sorted(set(entry) - _KNOWN_KEYS, key=str)
        if unknown:
            raise InvalidUpload(f"{where}: unknown key {excerpt(unknown[0], 40)}; known: {', '.join(sorted(_KNOWN_KEYS))}")
        values = {}
        for key, kind in _MAXIMA.items():
            flag = entry.get(_FLAGS[kind], False)
            if not isinstance(flag, bool):
                raise InvalidUpload(f"{where}.{_FLAGS[kind]} must be true or false")
            if not flag:
                continue
            if key not in entry:
                raise InvalidUpload(f"{where}: {_FLAGS[kind]} is true but {key} is missing")
            value = _number(entry[key], f"{where}.{key}")
            problem = limit_problem(kind, value, _short(joint), "joint_limits.yaml")
            if problem is not None:
                raise InvalidUpload(f"{where}.{key}: {problem}")
            values[kind] = value
        if entry.get("has_position_limits"):
            positions.append(str(joint))
        limits[str(joint)] = values
    if positions:
        notes.append(f"joint_limits.yaml's position limits of {', '.join(positions)} not applied: the URDF's are used")
    return limits, notes + _ignored_maxima(given["joint_limits"])


def _ignored_maxima(entries: dict) -> list[str]:
    """A note per ``max_*`` key given where its ``has_*_limits`` is false or absent (MoveIt
    ignores it there, and so does the upload), naming the joints and the values (at most 5)."""
    notes = []
    for key, kind in _MAXIMA.items():
        flag = _FLAGS[kind]
        ignored = [f"{_short(joint)} ({excerpt(entry[key], 20)})" for joint, entry in entries.items()
                   if key in entry and entry.get(flag, False) is False]
        if ignored:
            shown = ", ".join(ignored[:5]) + (f" and {len(ignored) - 5} more" if len(ignored) > 5 else "")
            notes.append(
                f"joint_limits.yaml's {key} of {shown} not applied: {flag} is false or absent there (as in MoveIt); "
                f"set {flag}: true to apply it"
            )
    return notes


def upload_options(locked_joints: dict | None = None, joint_limits: object = None, payload: Payload | None = None,
                   allowed_collisions: object = None) -> UploadOptions:
    """Options from an upload request, checked for form (names are checked against the model
    by ``apply_locks``, ``toptraj.robots.limits`` and ``toptraj.robots.srdf.check_links``);
    ``payload`` (checked by ``toptraj.robots.equipment.payload``) is the robot's default payload;
    ``allowed_collisions``: SRDF text or a list of [link, link] pairs (``toptraj.robots.srdf``).

    Raises:
        InvalidUpload: a non-finite locked value, or a malformed joint_limits.
        InvalidCollisionList: a malformed or oversized allowed_collisions.
    """
    locked = {}
    for joint, value in (locked_joints or {}).items():
        locked[str(joint)] = _number(value, f"locked_joints.{_short(joint)}")
    limits, notes = ({}, []) if joint_limits is None else _joint_limits(joint_limits)
    allowed = () if allowed_collisions is None else tuple(sorted(allowed_pairs(allowed_collisions)))
    return UploadOptions(locked, limits, tuple(notes), payload if payload is not None and payload.mass > 0.0 else None, allowed)


def _moving_joints(model: pin.Model) -> dict[str, int]:
    return {model.names[j]: j for j in range(1, model.njoints)}


def apply_locks(model: pin.Model, locked: dict[str, float]) -> pin.Model:
    """``model`` with the joints of ``locked`` fixed at their values (rad, m).

    Raises:
        InvalidUpload: an unknown joint, a value outside the joint's range, or every joint locked.
    """
    if not locked:
        return model
    joints = _moving_joints(model)
    reference = pin.neutral(model)
    for name, value in locked.items():
        if name not in joints:
            raise InvalidUpload(
                f"locked_joints names {excerpt(name, 40)}, which is not a moving joint of the URDF; its joints: "
                f"{excerpt(', '.join(joints), 300)}"
            )
        joint = model.joints[joints[name]]
        if joint.nq == 2:  # a continuous joint: (cos, sin)
            reference[joint.idx_q : joint.idx_q + 2] = (math.cos(value), math.sin(value))
            continue
        lower, upper = model.lowerPositionLimit[joint.idx_q], model.upperPositionLimit[joint.idx_q]
        if not lower <= value <= upper:
            raise InvalidUpload(
                f"locked_joints.{_short(name)} = {value:g} is outside the joint's range [{lower:g}, {upper:g}]"
            )
        reference[joint.idx_q] = value
    if len(locked) >= len(joints):
        raise InvalidUpload("locked_joints locks every moving joint; leave at least one free")
    return pin.buildReducedModel(model, [joints[name] for name in locked], reference)


def yaml_limit_arrays(joint_names: tuple[str, ...] | list[str], options: UploadOptions) -> dict[str, np.ndarray]:
    """The file's limits as arrays over ``joint_names`` (NaN where it gives none): {kind: (n_dof,)}.

    Raises:
        InvalidUpload: the file names a joint that is neither a joint of the robot nor locked.
    """
    index = {name: k for k, name in enumerate(joint_names)}
    arrays = {kind: np.full(len(joint_names), np.nan) for kind in _FLAGS}
    for joint, values in options.joint_limits.items():
        if joint in options.locked_joints:
            continue
        if joint not in index:
            raise InvalidUpload(
                f"joint_limits names {excerpt(joint, 40)}, which is not a moving joint of the URDF; its joints: "
                f"{excerpt(', '.join(joint_names), 300)}"
            )
        for kind, value in values.items():
            arrays[kind][index[joint]] = value
    return arrays
