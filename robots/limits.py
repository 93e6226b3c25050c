"""Joint limits of a robot: what its URDF carries, what ``data/limits.toml`` adds, and what a
request overrides or scales.

URDFs carry position, velocity and effort limits but no acceleration or jerk limits. The data file
holds those per robot, with their source, and a default rule for every other robot.
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
from dataclasses import dataclass
from functools import cache
from importlib import resources

import numpy as np

from toptraj.robots.errors import InvalidLimits
from toptraj.robots.ranges import LIMITS, limit_problem

#: How a message names each source of a limit.
_SOURCE_NAMES = {"urdf": "the URDF", "limits.toml": "the service's limits.toml"}


def _source_name(source: str) -> str:
    """A source of ``limits_with_sources`` as a message names it."""
    if source.startswith("default: "):
        return f"the default rule ({source.removeprefix('default: ')})"
    return _SOURCE_NAMES.get(source, source)

LIMIT_KINDS = ("position_lower", "position_upper", "velocity", "acceleration", "jerk", "torque")


@dataclass(frozen=True)
class ToolSpeedLimit:
    """Bounds on the speed of one frame of a robot (``toptraj.planners.constraints.tool_speed``).

    Attributes:
        frame: The frame's name.
        frame_id: Its index in the robot's model.
        speed: Largest linear speed of the frame's origin, in m/s (``inf``: none).
        angular_speed: Largest angular speed of the frame, in rad/s (``inf``: none).
    """

    frame: str
    frame_id: int
    speed: float = math.inf
    angular_speed: float = math.inf

    @property
    def bounds(self) -> np.ndarray:
        """(speed, angular_speed), shape (2,)."""
        return np.array([self.speed, self.angular_speed])

    def tightened(self, margin: float) -> ToolSpeedLimit:
        """These bounds reduced by the fraction ``margin``."""
        factor = 1.0 - margin
        return dataclasses.replace(self, speed=self.speed * factor, angular_speed=self.angular_speed * factor)


@dataclass(frozen=True)
class LimitZone:
    """Limits of their own on part of a path (``toptraj.planners.constraints.zones``): on the
    closed s-ranges ``ranges`` of the path being timed, the robot's velocity, acceleration and
    torque limits times ``velocity``, ``acceleration`` and ``torque`` (factors in (0, 1] or
    beyond), and a largest linear speed ``tool_speed`` (m/s, ``inf``: none) of the tool frame's
    origin. ``index`` is the zone's place in the caller's list, for messages and answers."""

    index: int
    ranges: tuple[tuple[float, float], ...]
    velocity: float = 1.0
    acceleration: float = 1.0
    torque: float = 1.0
    tool_speed: float = math.inf

    def tightened(self, margin: float) -> LimitZone:
        """The zone with its tool speed reduced by the fraction ``margin`` (its factors apply to
        limits already tightened)."""
        return dataclasses.replace(self, tool_speed=self.tool_speed * (1.0 - margin))


@dataclass(frozen=True)
class JointLimits:
    """Per-joint limits, each an array of shape (n_dof,), in the Pinocchio model's joint order.

    Units: rad, rad/s, rad/s^2, rad/s^3 and N m for revolute joints (m, m/s, m/s^2, m/s^3 and N for
    prismatic ones). ``inf`` means unlimited; symmetric limits are given by their magnitude.
    ``tool``, when a request limits the speed of a frame, holds those bounds; ``zones``, the
    limits that hold on parts of the path instead (``LimitZone``).
    """

    position_lower: np.ndarray
    position_upper: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    jerk: np.ndarray
    torque: np.ndarray
    tool: ToolSpeedLimit | None = None
    zones: tuple[LimitZone, ...] = ()

    def as_lists(self) -> dict[str, list[float | None]]:
        """The limits as JSON-friendly lists, ``None`` standing for unlimited."""
        return {
            kind: [float(v) if math.isfinite(v) else None for v in getattr(self, kind)]
            for kind in LIMIT_KINDS
        }

    def with_request(
        self,
        overrides: dict[str, list[float] | None] | None = None,
        scales: dict[str, float | None] | None = None,
    ) -> JointLimits:
        """These limits with a request's per-joint ``overrides`` replacing and ``scales``
        multiplying the velocity, acceleration, jerk and torque limits.

        Raises:
            InvalidLimits: an override of the wrong length, or a non-positive value or scale.
        """
        n_dof = self.velocity.shape[0]
        values = {kind: getattr(self, kind) for kind in LIMIT_KINDS}
        for kind, given in (overrides or {}).items():
            if given is None:
                continue
            array = np.asarray(given, dtype=float)
            if array.shape != (n_dof,):
                raise InvalidLimits(f"limits.{kind}", given, rule="wrong_length", given=array.size, expected=n_dof)
            if np.any(np.isnan(array)) or np.any(array <= 0.0):
                bad = int(np.flatnonzero(np.isnan(array) | (array <= 0.0))[0])
                raise InvalidLimits(f"limits.{kind}[{bad}]", float(array[bad]), rule="limit_not_positive")
            values[kind] = array
        for kind, factor in (scales or {}).items():
            if factor is None:
                continue
            if not (math.isfinite(factor) and factor > 0.0):
                raise InvalidLimits(f"limits.{kind}_scale", factor, rule="scale_not_positive")
            values[kind] = values[kind] * factor
        return JointLimits(**values, tool=self.tool, zones=self.zones)

    def tightened(self, margin: float) -> JointLimits:
        """These limits with the velocity, acceleration, jerk and torque limits reduced by the
        fraction ``margin`` (0 <= margin < 1); position limits unchanged."""
        factor = 1.0 - margin
        return dataclasses.replace(
            self,
            velocity=self.velocity * factor,
            acceleration=self.acceleration * factor,
            jerk=self.jerk * factor,
            torque=self.torque * factor,
            tool=None if self.tool is None else self.tool.tightened(margin),
            zones=tuple(zone.tightened(margin) for zone in self.zones),
        )


@cache
def _limit_table() -> dict:
    text = resources.files("toptraj.robots").joinpath("data/limits.toml").read_text()
    return tomllib.loads(text)


def limits_for(
    robot_name: str,
    position_lower: np.ndarray,
    position_upper: np.ndarray,
    velocity: np.ndarray,
    torque: np.ndarray,
) -> JointLimits:
    """Complete a robot's URDF limits with the data file's entry for ``robot_name`` (or the
    default rule when it has none)."""
    return limits_with_sources(robot_name, position_lower, position_upper, velocity, torque)[0]


def _tightened(values: dict[str, np.ndarray], sources: dict[str, list[str]], given: dict[str, np.ndarray], names: list[str]) -> list[str]:
    """``given``'s velocity and torque limits (an upload's joint_limits.yaml; NaN where it gives
    none) taken into ``values`` and ``sources`` where they tighten them; a note for each one
    that would loosen them, which is not taken."""
    notes = []
    for kind in ("velocity", "torque"):
        if kind not in given:
            continue
        for k in np.flatnonzero(np.isfinite(given[kind])):
            if given[kind][k] <= values[kind][k]:
                values[kind] = values[kind].copy()
                values[kind][k] = given[kind][k]
                sources[kind][k] = "joint_limits.yaml"
            else:
                unit = "N m" if kind == "torque" else "rad/s"
                notes.append(
                    f"joint_limits.yaml allows joint {names[k]!r} a {kind} of {given[kind][k]:g} {unit}, above the "
                    f"URDF's {values[kind][k]:g}: the URDF's limit is kept"
                )
    return notes


def _derived(
    values: dict[str, np.ndarray], sources: dict[str, list[str]], entry: dict, given: dict[str, np.ndarray], rule: dict, n_dof: int
) -> None:
    """The acceleration and jerk limits into ``values`` and ``sources``: the default rule
    (velocity / ``seconds_to_full_speed``, acceleration / ``seconds_to_full_acceleration``),
    replaced by the data file's ``entry``, then by ``given`` joint by joint."""
    for kind, default, seconds in (
        ("acceleration", "velocity", "seconds_to_full_speed"),
        ("jerk", "acceleration", "seconds_to_full_acceleration"),
    ):
        with np.errstate(invalid="ignore"):
            values[kind] = values[default] / rule[seconds]
        sources[kind] = [f"default: {default} limit / {rule[seconds]:g} s"] * n_dof
        if kind in entry:
            values[kind] = np.asarray(entry[kind], dtype=float)
            sources[kind] = ["limits.toml"] * n_dof
        if kind in given:
            for k in np.flatnonzero(np.isfinite(given[kind])):
                values[kind] = values[kind].copy()
                values[kind][k] = given[kind][k]
                sources[kind][k] = "joint_limits.yaml"


def limits_with_sources(
    robot_name: str,
    position_lower: np.ndarray,
    position_upper: np.ndarray,
    velocity: np.ndarray,
    torque: np.ndarray,
    given: dict[str, np.ndarray] | None = None,
    joint_names: tuple[str, ...] | list[str] | None = None,
) -> tuple[JointLimits, dict[str, tuple[str, ...]], list[str]]:
    """A robot's limits, where each one comes from, and notes on what was not taken.

    In order: the URDF's position, velocity and effort limits; the data file's entry for
    ``robot_name`` (catalog robots); ``given`` (an upload's joint_limits.yaml: {kind: (n_dof,)},
    NaN where it gives none), whose velocity and torque limits only tighten the URDF's; the
    default rule for acceleration (velocity / ``seconds_to_full_speed``) and jerk
    (acceleration / ``seconds_to_full_acceleration``) where nothing gave them.

    Every velocity, acceleration, jerk and torque limit, whatever its source, lies in the
    accepted range of its kind (``toptraj.robots.ranges``) or is ``inf`` (no limit).

    Returns:
        The limits; {kind: one source per joint}, sources being "urdf", "limits.toml",
        "joint_limits.yaml" or "default: ..." (the rule); the notes.

    Raises:
        InvalidLimits: a limit outside its accepted range, naming the joint, the limit and its
            source.
    """
    table = _limit_table()
    entry = table.get(robot_name, {})
    rule = table["default"]
    n_dof = len(np.atleast_1d(velocity))
    names = list(joint_names) if joint_names is not None else [str(k) for k in range(n_dof)]
    values = {
        "position_lower": np.asarray(position_lower, dtype=float),
        "position_upper": np.asarray(position_upper, dtype=float),
        "velocity": np.asarray(velocity, dtype=float),
        "torque": np.asarray(torque, dtype=float),
    }
    sources = {kind: ["urdf"] * n_dof for kind in values}
    for kind in ("position_lower", "position_upper", "velocity", "torque"):
        if kind in entry:
            values[kind] = np.asarray(entry[kind], dtype=float)
            sources[kind] = ["limits.toml"] * n_dof
    given = given or {}
    notes = _tightened(values, sources, given, names)
    _derived(values, sources, entry, given, rule, n_dof)
    for kind in LIMITS:
        for joint, value in enumerate(values[kind]):
            problem = limit_problem(kind, float(value), names[joint], _source_name(sources[kind][joint]))
            if problem is not None:
                raise InvalidLimits(f"{kind}[{joint}]", float(value), rule="catalog_limit", detail=problem)
    limits = JointLimits(
        values["position_lower"], values["position_upper"], values["velocity"], values["acceleration"], values["jerk"],
        values["torque"],
    )
    return limits, {kind: tuple(sources[kind]) for kind in LIMIT_KINDS}, notes
