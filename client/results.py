"""Typed answers of ``POST /v1/trajectories`` and ``POST /v1/trajectories/compare``: frozen
dataclasses with numpy arrays, one row per sample, one column per joint, SI units (rad, m, s,
N m, N); ``body`` keeps the answer as the service sent it."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from toptraj.client.errors import ProblemError


def _floats(values: Any) -> np.ndarray:
    """``values`` as a float array; ``None`` (JSON null) becomes ``nan``."""
    if isinstance(values, list) and any(v is None for v in values):
        values = [np.nan if v is None else v for v in values]
    return np.asarray(values, dtype=float)


def _rows(values: Any, columns: int) -> np.ndarray:
    """A list of rows as an ``(n, columns)`` float array, ``(0, columns)`` when empty."""
    return np.asarray(values, dtype=float).reshape(-1, columns)


def _optional(kind: Any, value: dict | None) -> Any:
    return None if value is None else kind.from_body(value)


@dataclass(frozen=True, eq=False)
class Utilization:
    """Peak |value| / limit per joint on a dense resampling of the answer (1.0: the limit binds;
    the service holds every limit within 0.5 %); ``nan`` for a joint without a finite limit of
    that kind (the answer's null).

    Attributes:
        velocity: Peak |qd| / velocity limit, shape (n_dof,).
        acceleration: Peak |qdd| / acceleration limit, shape (n_dof,).
        torque: Peak |tau| / torque limit, shape (n_dof,).
        jerk: Peak |qddd| / jerk limit, shape (n_dof,), for timings with a finite jerk; else None.
        tool_speed: Peak tool speed / ``timing.limits.tool_speed`` when that limit is set.
        tool_angular_speed: Peak angular tool speed / its limit when set.
    """

    velocity: np.ndarray
    acceleration: np.ndarray
    torque: np.ndarray
    jerk: np.ndarray | None = None
    tool_speed: float | None = None
    tool_angular_speed: float | None = None

    @classmethod
    def from_body(cls, body: dict) -> Utilization:
        """From the answer's ``peak_utilization`` object."""
        jerk = body.get("jerk")
        return cls(
            velocity=_floats(body["velocity"]),
            acceleration=_floats(body["acceleration"]),
            torque=_floats(body["torque"]),
            jerk=None if jerk is None else _floats(jerk),
            tool_speed=body.get("tool_speed"),
            tool_angular_speed=body.get("tool_angular_speed"),
        )


@dataclass(frozen=True)
class SwitchPoint:
    """Where the path acceleration switches: ``s`` in [0, 1] and the kind of switch
    (acceleration, deceleration, tangent, singular, discontinuity)."""

    s: float
    kind: str


@dataclass(frozen=True, eq=False)
class PhasePlane:
    """The timing in the phase plane.

    Attributes:
        s: Path parameter of each point, shape (m,), from 0 to 1.
        sd: Path speed ds/dt at each point (1/s), shape (m,).
        sd_max: Maximum velocity curve (1/s), shape (m,); ``nan`` where unbounded.
        switch_points: Where the path acceleration switches, in order.
    """

    s: np.ndarray
    sd: np.ndarray
    sd_max: np.ndarray
    switch_points: list[SwitchPoint]

    @classmethod
    def from_body(cls, body: dict) -> PhasePlane:
        """From the answer's ``phase_plane`` object."""
        switches = [SwitchPoint(float(p["s"]), str(p["kind"])) for p in body.get("switch_points", [])]
        return cls(_floats(body["s"]), _floats(body["sd"]), _floats(body["sd_max"]), switches)


@dataclass(frozen=True)
class Accuracy:
    """Estimated relative distance of the answer from its method's converged optimum
    (``relative_gap``, None when there is no estimate) and how it was obtained (``basis``)."""

    relative_gap: float | None
    basis: str

    @classmethod
    def from_body(cls, body: dict) -> Accuracy:
        """From the answer's ``accuracy`` object."""
        return cls(body.get("relative_gap"), str(body.get("basis", "")))


@dataclass(frozen=True)
class Conditioning:
    """Frobenius condition number of the end effector's Jacobian along the trajectory (1:
    isotropic; None: singular somewhere), translations over ``characteristic_length`` (m)."""

    kappa_min: float | None
    kappa_max: float | None
    characteristic_length: float

    @classmethod
    def from_body(cls, body: dict) -> Conditioning:
        """From the answer's ``conditioning`` object."""
        return cls(body.get("kappa_min"), body.get("kappa_max"), float(body["characteristic_length"]))


@dataclass(frozen=True)
class Binding:
    """The limit that set a time law's minimal duration: its ``kind``, ``joint`` (None for a
    limit of the whole path) and where along the path, ``s`` in [0, 1]."""

    kind: str
    joint: str | None
    s: float

    @classmethod
    def from_body(cls, body: dict) -> Binding:
        """From the answer's ``binding`` object."""
        return cls(str(body["kind"]), body.get("joint"), float(body["s"]))


@dataclass(frozen=True)
class Clearance:
    """The closest approach of the robot to the obstacles: ``distance`` (m) between ``link``
    and obstacle number ``obstacle`` (index into ``path.obstacles``), at path parameter ``s``."""

    distance: float
    link: str
    obstacle: int
    s: float

    @classmethod
    def from_body(cls, body: dict) -> Clearance:
        """From the answer's ``min_clearance`` object."""
        return cls(float(body["distance"]), str(body["link"]), int(body["obstacle"]), float(body["s"]))


def joint_trajectory_arrays(message: dict) -> dict[str, np.ndarray]:
    """The samples of a ``trajectory_msgs/JointTrajectory`` message (as JSON) as arrays: ``t``
    (s, shape (n,), from ``time_from_start`` to the nanosecond) and ``q``, ``qd``, ``qdd``,
    ``tau``, shape (n, n_dof), from the points' positions, velocities, accelerations, effort."""
    points = message["points"]
    n_dof = len(message["joint_names"])
    stamps = np.array([[p["time_from_start"]["sec"], p["time_from_start"]["nanosec"]] for p in points], dtype=np.int64)
    t = stamps[:, 0] + stamps[:, 1] * 1e-9 if len(points) else np.zeros(0)
    fields = {"q": "positions", "qd": "velocities", "qdd": "accelerations", "tau": "effort"}
    return {"t": t, **{name: _rows([p[key] for p in points], n_dof) for name, key in fields.items()}}


@dataclass(frozen=True, eq=False)
class Trajectory:
    """A planned trajectory (a JSON answer: ``output.format`` ``samples`` or
    ``joint_trajectory``).

    Attributes:
        robot: The robot planned for.
        method: The timing method used.
        joint_names: Joint names, the order of every per-joint column.
        duration: Planned duration (s).
        sampled_duration: Time of the last sample (s): ``duration``, or the whole periods it was
            stretched to with ``output.exact_period``.
        format: ``samples`` or ``joint_trajectory``: the shape the service sent.
        t: Sample times (s), shape (n,).
        q: Joint positions (rad, m), shape (n, n_dof).
        qd: Joint velocities (rad/s, m/s), shape (n, n_dof).
        qdd: Joint accelerations (rad/s^2, m/s^2), shape (n, n_dof).
        tau: Joint torques (N m) or forces (N) by inverse dynamics, shape (n, n_dof).
        phase_plane: Path speed and maximum velocity curve over s.
        peak_utilization: Peak |value| / limit per joint.
        accuracy: Estimated distance from the method's converged optimum.
        conditioning: Condition number of the end effector's Jacobian along the motion.
        warnings: What the answer should be read with (singularities, dropped waypoints, ...).
        solve_ms: Planning time in the library (ms).
        binding: The limit that set a time law's minimal duration, else None.
        min_clearance: With obstacles: the closest approach, else None.
        cost: ``min_cost`` and ``collocation``: the integral of (1 + beta |tau|^2) dt (s).
        solver: ``collocation``: the solver's status, iterations and winning initial guess.
        switching_times: ``collocation`` with bang-bang torques: per joint, the times (s) at
            which its saturated torque changes sides.
        search: ``search``: what the global search did (the service's ``SearchPublic``).
        zones: With ``timing.zones``: where each lies on the path and whether it bound the timing.
        payload: The payload the torques include (mass (kg), centre of mass (m), ...), else None.
        mounting: With ``mounting``: the base pose (m) and the world's gravity (m/s^2) applied.
        joint_trajectory: With ``format = "joint_trajectory"``: the ROS message as JSON
            (``joint_names``, ``points``), ready for a ``FollowJointTrajectory`` goal.
        body: The whole answer as the service sent it.
    """

    robot: str
    method: str
    joint_names: list[str]
    duration: float
    sampled_duration: float
    format: str
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    tau: np.ndarray
    phase_plane: PhasePlane
    peak_utilization: Utilization
    accuracy: Accuracy
    conditioning: Conditioning
    warnings: list[str]
    solve_ms: float
    binding: Binding | None = None
    min_clearance: Clearance | None = None
    cost: float | None = None
    solver: dict | None = None
    switching_times: dict[str, list[float]] | None = None
    search: dict | None = None
    zones: list[dict] | None = None
    payload: dict | None = None
    mounting: dict | None = None
    joint_trajectory: dict | None = field(default=None, repr=False)
    body: dict = field(default_factory=dict, repr=False)

    def __repr__(self) -> str:
        """One line: what was planned, how long it lasts, how many samples and warnings (the
        arrays are the attributes)."""
        return (
            f"Trajectory(robot={self.robot!r}, method={self.method!r}, duration={self.duration!r}, samples={len(self.t)}, "
            f"joints={len(self.joint_names)}, warnings={len(self.warnings)})"
        )

    @classmethod
    def from_body(cls, body: dict) -> Trajectory:
        """From a ``TrajectoryResponse`` body, in either JSON format."""
        n_dof = len(body["joint_names"])
        message = body.get("joint_trajectory")
        if message is not None:
            arrays, format_ = joint_trajectory_arrays(message), "joint_trajectory"
        else:
            samples = body["samples"]
            arrays = {"t": _floats(samples["t"]), **{k: _rows(samples[k], n_dof) for k in ("q", "qd", "qdd", "tau")}}
            format_ = "samples"
        return cls(
            robot=body["robot"],
            method=body["method"],
            joint_names=list(body["joint_names"]),
            duration=float(body["duration"]),
            sampled_duration=float(body.get("sampled_duration", body["duration"])),
            format=format_,
            phase_plane=PhasePlane.from_body(body["phase_plane"]),
            peak_utilization=Utilization.from_body(body["peak_utilization"]),
            accuracy=Accuracy.from_body(body["accuracy"]),
            conditioning=Conditioning.from_body(body["conditioning"]),
            warnings=list(body.get("warnings", [])),
            solve_ms=float(body["solve_ms"]),
            binding=_optional(Binding, body.get("binding")),
            min_clearance=_optional(Clearance, body.get("min_clearance")),
            cost=body.get("cost"),
            solver=body.get("solver"),
            switching_times=body.get("switching_times"),
            search=body.get("search"),
            zones=body.get("zones"), payload=body.get("payload"), mounting=body.get("mounting"),
            joint_trajectory=message,
            body=body,
            **arrays,
        )


@dataclass(frozen=True, eq=False)
class CsvTrajectory:
    """A trajectory served as CSV (``output.format = "csv"``): the columns as arrays.

    Attributes:
        joint_names: Joint names, from the header's ``q.<joint>`` columns.
        t: Sample times (s), shape (n,).
        q: Joint positions (rad, m), shape (n, n_dof).
        qd: Joint velocities (rad/s, m/s), shape (n, n_dof).
        qdd: Joint accelerations (rad/s^2, m/s^2), shape (n, n_dof).
        tau: Joint torques (N m) or forces (N), shape (n, n_dof).
        comments: The text of the lines starting with ``#`` (without the ``#``), in order.
        metadata: The comment lines of the form ``name: value`` (or ``name = value``), by name
            (a name given twice, as ``warning``, keeps its last value: ``warnings`` has them all).
        headers: The response's HTTP headers (lower-case names).
        text: The CSV as the service sent it.
    """

    joint_names: list[str]
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    tau: np.ndarray
    comments: list[str]
    metadata: dict[str, str]
    headers: dict[str, str] = field(repr=False)
    text: str = field(repr=False)

    def __repr__(self) -> str:
        return f"CsvTrajectory(duration={self.duration!r}, samples={len(self.t)}, joints={len(self.joint_names)}, warnings={len(self.warnings)})"

    @property
    def duration(self) -> float | None:
        """The planned duration (s) of the ``# duration:`` line, None without one."""
        value = self.metadata.get("duration", "").removesuffix(" s").strip()
        try:
            return float(value)
        except ValueError:
            return None

    @property
    def warnings(self) -> list[str]:
        """Every ``# warning:`` line's text, in order."""
        return [comment.partition(":")[2].strip() for comment in self.comments if comment.startswith("warning:")]

    @classmethod
    def from_text(cls, text: str, headers: dict[str, str] | None = None) -> CsvTrajectory:
        """Parse the CSV of the service: comment lines (``#``), a header ``t,q.<joint>,...,
        qd.<joint>,...,qdd.<joint>,...,tau.<joint>,...``, then one row per sample."""
        lines = [line for line in text.splitlines() if line.strip()]
        comments = [line[1:].strip() for line in lines if line.startswith("#")]
        table = [line for line in lines if not line.startswith("#")]
        header = table[0].split(",")
        rows = np.array([[float(v) for v in line.split(",")] for line in table[1:]], dtype=float).reshape(-1, len(header))
        columns = {name: rows[:, k] for k, name in enumerate(header)}
        joints = [name[2:] for name in header if name.startswith("q.")]
        arrays = {
            quantity: np.column_stack([columns[f"{quantity}.{joint}"] for joint in joints]) if joints else np.zeros((len(rows), 0))
            for quantity in ("q", "qd", "qdd", "tau")
        }
        metadata = {}
        for comment in comments:
            for separator in (":", "="):
                name, found, value = comment.partition(separator)
                if found and name.strip() and "," not in name:
                    metadata[name.strip()] = value.strip()
                    break
        return cls(joints, columns["t"], comments=comments, metadata=metadata, headers=dict(headers or {}), text=text, **arrays)


@dataclass(frozen=True)
class Comparison:
    """One method's result of a comparison: its duration, or its error.

    Attributes:
        method: The timing method.
        duration: Duration (s); None when the method failed.
        solve_ms: Planning time (ms); None when the method failed.
        peak_utilization: Peak |value| / limit per joint; None when the method failed.
        binding: The limit that set a time law's minimal duration, else None.
        accuracy: Estimated distance from the method's converged optimum; None on failure.
        warnings: What the answer should be read with; empty on failure.
        error: The method's problem when it failed (not raised: the other methods stand).
        body: This result as the service sent it.
    """

    method: str
    duration: float | None
    solve_ms: float | None
    peak_utilization: Utilization | None = None
    binding: Binding | None = None
    accuracy: Accuracy | None = None
    warnings: list[str] = field(default_factory=list)
    error: ProblemError | None = None
    body: dict = field(default_factory=dict, repr=False)

    @classmethod
    def from_body(cls, body: dict) -> Comparison:
        """From one item of a ``CompareResponse``'s ``results``."""
        return cls(
            method=body["method"],
            duration=body.get("duration"),
            solve_ms=body.get("solve_ms"),
            peak_utilization=_optional(Utilization, body.get("peak_utilization")),
            binding=_optional(Binding, body.get("binding")),
            accuracy=_optional(Accuracy, body.get("accuracy")),
            warnings=list(body.get("warnings") or []),
            error=None if body.get("error") is None else ProblemError(body["error"]),
            body=body,
        )


def comparisons(body: dict) -> list[Comparison]:
    """The results of a ``CompareResponse``, in the order of the methods asked."""
    return [Comparison.from_body(result) for result in body["results"]]
