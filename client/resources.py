"""Typed answers of the robot and job resources (``/v1/robots``, ``/v1/jobs``, ``/v1/batches``):
frozen dataclasses, per-joint values as numpy arrays in SI units; ``body`` keeps the answer as
the service sent it."""

from __future__ import annotations

from dataclasses import dataclass, field
from datetime import datetime
from typing import Any, cast

import numpy as np

from toptraj.client.errors import ProblemError
from toptraj.client.results import Comparison, CsvTrajectory, Trajectory, comparisons

#: Job statuses after which nothing changes any more.
ENDED = frozenset({"done", "failed", "cancelled", "interrupted"})


@dataclass(frozen=True)
class RobotSummary:
    """One line of the robot list: its ``name``, degrees of freedom ``dof`` and ``source``
    (``bundled``, ``example-robot-data`` or ``upload``)."""

    name: str
    dof: int
    source: str


def _limit(values: list, unlimited: float) -> np.ndarray:
    return np.array([unlimited if v is None else v for v in values], dtype=float)


@dataclass(frozen=True, eq=False)
class Limits:
    """A robot's per-joint limits, shape (n_dof,) each, SI units; ``inf`` where a joint has no
    such limit (``-inf`` for a missing lower position limit, e.g. a continuous joint).

    Attributes:
        position_lower: Lower position limits (rad, m).
        position_upper: Upper position limits (rad, m).
        velocity: Velocity limits (rad/s, m/s).
        acceleration: Acceleration limits (rad/s^2, m/s^2).
        jerk: Jerk limits (rad/s^3, m/s^3).
        torque: Torque (N m) or force (N) limits.
    """

    position_lower: np.ndarray
    position_upper: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    jerk: np.ndarray
    torque: np.ndarray

    @classmethod
    def from_body(cls, body: dict) -> Limits:
        """From a robot's ``limits`` object (null: unlimited)."""
        return cls(
            position_lower=_limit(body["position_lower"], -np.inf),
            **{kind: _limit(body[kind], np.inf) for kind in ("position_upper", "velocity", "acceleration", "jerk", "torque")},
        )


@dataclass(frozen=True)
class Robot:
    """A robot as the service sees it.

    Attributes:
        name: The name requests give.
        dof: Degrees of freedom (actuated joints).
        source: ``bundled``, ``example-robot-data`` or ``upload``.
        joint_names: Joint names, the order of every per-joint value.
        end_effector: The frame Cartesian paths and tool speeds refer to by default.
        limits: Per-joint limits.
        limit_sources: Where each limit comes from, per kind and joint (``urdf``,
            ``limits.toml``, ``joint_limits.yaml`` or ``default: ...``).
        locked_joints: Joints of the URDF fixed at a value (rad, m) and left out.
        notes: What was not used or was changed (mesh files, limits not applied).
        body: The description as the service sent it.
    """

    name: str
    dof: int
    source: str
    joint_names: list[str]
    end_effector: str
    limits: Limits
    limit_sources: dict[str, list[str]]
    locked_joints: dict[str, float]
    notes: list[str]
    body: dict = field(default_factory=dict, repr=False)

    @classmethod
    def from_body(cls, body: dict) -> Robot:
        """From a ``RobotPublic`` body."""
        return cls(
            name=body["name"],
            dof=int(body["dof"]),
            source=body["source"],
            joint_names=list(body["joint_names"]),
            end_effector=body["end_effector"],
            limits=Limits.from_body(body["limits"]),
            limit_sources={kind: list(sources) for kind, sources in body.get("limit_sources", {}).items()},
            locked_joints=dict(body.get("locked_joints") or {}),
            notes=list(body.get("notes", [])),
            body=body,
        )


@dataclass(frozen=True, eq=False)
class Skeleton:
    """The arm as a stick figure: ``positions[k, i]`` is the world position (m) of point
    ``points[i]`` (the joints' origins, then the end effector) in configuration k; shape
    (n_configurations, n_points, 3)."""

    points: list[str]
    positions: np.ndarray


@dataclass(frozen=True)
class BatchItem:
    """One request's answer in a batch.

    Attributes:
        line: The request's position in the batch, from 1.
        status: The HTTP status its own endpoint would have answered.
        result: Its answer (a ``Trajectory``, a ``CsvTrajectory`` for a request asking
            ``output.format`` ``csv``, or a list of ``Comparison`` for a comparison); None when
            it failed.
        error: Its problem when it failed, else None.
        body: Its answer or problem as the service sent it (a CSV answer: its text).
    """

    line: int
    status: int
    result: Trajectory | CsvTrajectory | list[Comparison] | None
    error: ProblemError | None
    body: dict | str = field(repr=False)

    @classmethod
    def from_body(cls, body: dict) -> BatchItem:
        """From one item of a batch's ``results``."""
        status, answer = int(body["status"]), body["body"]
        if status >= 400:
            return cls(int(body["line"]), status, None, ProblemError(answer), answer)
        if isinstance(answer, str):  # a request asking CSV: the text its endpoint would send
            return cls(int(body["line"]), status, CsvTrajectory.from_text(answer, {}), None, answer)
        result = cast("Trajectory | list[Comparison]", answer_of(answer))  # a batch holds no batch
        return cls(int(body["line"]), status, result, None, answer)


def answer_of(body: dict) -> Trajectory | list[Comparison] | list[BatchItem]:
    """A job's answer, typed by its shape: a comparison (``results`` with ``method``), a batch
    (``results`` with ``line``) or a trajectory."""
    results = body.get("results")
    if results is None:
        return Trajectory.from_body(body)
    if results and "line" in results[0]:
        return [BatchItem.from_body(item) for item in results]
    return comparisons(body)


def _time(value: str | None) -> datetime | None:
    return None if value is None else datetime.fromisoformat(value)


@dataclass(frozen=True)
class Job:
    """A background job (a trajectory, a comparison or a batch) and, once done, its answer.

    Attributes:
        id: 32 hex digits.
        kind: ``trajectory``, ``compare`` or ``batch``.
        status: ``queued``, ``running``, ``done``, ``failed``, ``cancelled`` or ``interrupted``
            (the server stopped while it ran; submit it again).
        fraction: Progress in [0, 1] (1 when done); it never goes back.
        stage: What is under way, e.g. ``collocation: guess 3 of 15``.
        budget_s: Computing time allowed once running (s).
        created_at: When it was submitted (UTC).
        started_at: When it started running (UTC), else None.
        finished_at: When it ended (UTC), else None.
        error: Once failed or interrupted: its problem (not raised), else None.
        result: Once done and read with ``Client.job``: its answer (a ``Trajectory``, a list of
            ``Comparison``, or a list of ``BatchItem``), else None.
        body: The job as the service sent it.
    """

    id: str
    kind: str
    status: str
    fraction: float
    stage: str
    budget_s: float
    created_at: datetime | None
    started_at: datetime | None
    finished_at: datetime | None
    error: ProblemError | None
    result: Trajectory | list[Comparison] | list[BatchItem] | None = field(default=None, repr=False)
    body: dict[str, Any] = field(default_factory=dict, repr=False)

    @property
    def ended(self) -> bool:
        """Whether the job has ended (done, failed, cancelled or interrupted)."""
        return self.status in ENDED

    @classmethod
    def from_body(cls, body: dict) -> Job:
        """From a ``JobPublic`` or ``JobSummary`` body."""
        progress = body.get("progress") or {}
        result = body.get("result")
        return cls(
            id=body["id"],
            kind=body["kind"],
            status=body["status"],
            fraction=float(progress.get("fraction", 0.0)),
            stage=str(progress.get("stage", "")),
            budget_s=float(body["budget_s"]),
            created_at=_time(body.get("created_at")),
            started_at=_time(body.get("started_at")),
            finished_at=_time(body.get("finished_at")),
            error=None if body.get("error") is None else ProblemError(body["error"]),
            result=None if result is None else answer_of(result),
            body=body,
        )


@dataclass(frozen=True)
class JobPage:
    """A page of ``GET /v1/jobs``: ``jobs`` newest first (without their answers) and the
    ``next_cursor`` of the next, older page (None on the last page)."""

    jobs: list[Job]
    next_cursor: str | None
