"""``Client``: the toptraj HTTP API as Python calls, over one keep-alive connection (httpx):
the service, robots and trajectories here, jobs and batches from ``toptraj.client.jobs.JobCalls``."""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import numpy as np

from toptraj.client.bodies import compare_request, rows_of, trajectory_request
from toptraj.client.jobs import JobCalls
from toptraj.client.resources import Robot, RobotSummary, Skeleton
from toptraj.client.results import Comparison, CsvTrajectory, Trajectory, comparisons

#: Every operation of the service's OpenAPI, by method and path, and the ``Client`` method that
#: calls it.
ENDPOINTS: dict[tuple[str, str], str] = {
    ("GET", "/health"): "health",
    ("GET", "/v1/robots"): "robots",
    ("GET", "/v1/robots/{name}"): "robot",
    ("POST", "/v1/robots"): "upload",
    ("DELETE", "/v1/robots/{name}"): "delete_robot",
    ("POST", "/v1/robots/{name}/skeleton"): "skeleton",
    ("POST", "/v1/trajectories"): "plan",
    ("POST", "/v1/trajectories/compare"): "compare",
    ("POST", "/v1/cells"): "cell",
    ("POST", "/v1/jobs"): "submit",
    ("GET", "/v1/jobs"): "jobs",
    ("GET", "/v1/jobs/{job_id}"): "job",
    ("GET", "/v1/jobs/{job_id}/result"): "job_result",
    ("DELETE", "/v1/jobs/{job_id}"): "cancel_job",
    ("POST", "/v1/batches"): "submit_batch",
}


def _text(value: str | os.PathLike[str]) -> str:
    """A file's text for a path (``pathlib.Path``), the string itself otherwise."""
    return Path(value).read_text() if isinstance(value, os.PathLike) else value


def _json_body(value: dict | str | os.PathLike[str]) -> dict:
    """A request body from a dict, JSON text, or the path of a file holding it (a string that
    is not JSON text is taken for a path).

    Raises:
        ValueError: the text, or the file's, is not JSON (``json.JSONDecodeError``).
        OSError: a path that cannot be read.
    """
    if isinstance(value, dict):
        return value
    if isinstance(value, str) and not value.lstrip("\ufeff \t\r\n").startswith(("{", "[")):
        value = Path(value)
    return json.loads(_text(value).lstrip("\ufeff"))


def _alone(body: dict, **arguments: Any) -> None:
    """Refuse the arguments that would be lost beside a whole request ``body``."""
    given = [name for name, value in arguments.items() if value is not None]
    if given:
        raise ValueError(f"a whole request is sent as it is: put {', '.join(given)} into it instead of passing them")


class Client(JobCalls):
    """The toptraj service at ``base_url``.

    Every call goes over one ``httpx.Client`` whose connections are kept alive and reused;
    close it with ``close()`` or use the client as a context manager. An answer that is not a
    success raises ``ProblemError``; a connection that fails or a read that times out raises
    httpx's ``TransportError`` (``httpx.TimeoutException`` among them).

    Args:
        base_url: Where the service listens, e.g. ``"http://127.0.0.1:8000"``.
        timeout: Seconds to wait for an answer (reading, writing, a free connection of the
            pool); a synchronous plan may take up to the server's budget (20 s by default).
            An ``httpx.Timeout`` sets each phase.
        connect_timeout: Seconds to wait for a connection to the service.
        headers: Headers sent with every request (e.g. an ``Authorization`` of a proxy).
        http: An ``httpx.Client`` to use instead (e.g. FastAPI's ``TestClient``); it is not
            closed by ``close()``.
    """

    # --- the service -----------------------------------------------------------------------

    def health(self) -> str:
        """``GET /health``: ``"ok"`` while the service runs."""
        return str(self._call("GET", "/health")["status"])

    def openapi(self) -> dict:
        """``GET /openapi.json``: the service's OpenAPI document."""
        return self._call("GET", "/openapi.json")

    # --- robots ----------------------------------------------------------------------------

    def robots(self) -> list[RobotSummary]:
        """``GET /v1/robots``: the catalog and the uploads."""
        return [RobotSummary(r["name"], int(r["dof"]), r["source"]) for r in self._call("GET", "/v1/robots")]

    def robot(self, name: str) -> Robot:
        """``GET /v1/robots/{name}``: one robot's joints, end effector and limits.

        Raises:
            ProblemError: 404 when no robot has that name.
        """
        return Robot.from_body(self._call("GET", f"/v1/robots/{name}"))

    def upload(
        self,
        urdf: str | os.PathLike[str],
        name: str | None = None,
        *,
        locked_joints: dict[str, float] | None = None,
        joint_limits: str | os.PathLike[str] | dict | None = None,
        payload: dict | None = None,
        allowed_collisions: str | os.PathLike[str] | list | None = None,
        timeout: float | None = None,
    ) -> Robot:
        """``POST /v1/robots``: check, build and store a fixed-base arm's URDF.

        Args:
            urdf: The URDF text, or a ``pathlib.Path`` to read it from.
            name: The name to keep it under (default ``urdf-`` and a content hash).
            locked_joints: Joints to fix at a value (rad, m), e.g. a gripper's fingers
                ``{"panda_finger_joint1": 0.0, "panda_finger_joint2": 0.0}``.
            joint_limits: Limits in the form of MoveIt's ``joint_limits.yaml``: its text, a
                ``pathlib.Path`` to it, or the same structure as a dict. Acceleration and jerk
                limits are taken as given, velocity and effort limits only tighten the URDF's.
            payload: What the robot carries unless a request gives its own: ``{"mass": kg,
                "center_of_mass": [x, y, z], "inertia": [Ixx, Iyy, Izz, Ixy, Ixz, Iyz]}`` (m, kg m^2).
            allowed_collisions: Pairs of links allowed to touch, not checked for
                self-collision: an SRDF's text, a ``pathlib.Path`` to one (its
                ``disable_collisions`` are read), or a list of ``[link, link]`` pairs.
            timeout: Seconds to wait for this answer instead of the client's.

        Returns:
            The robot; ``limit_sources`` and ``notes`` say what was applied.

        Raises:
            ProblemError: 422 naming the link, joint or limit at fault; 409 a name taken.
        """
        body: dict[str, Any] = {"urdf": _text(urdf)}
        if name is not None:
            body["name"] = name
        if locked_joints is not None:
            body["locked_joints"] = dict(locked_joints)
        if joint_limits is not None:
            body["joint_limits"] = joint_limits if isinstance(joint_limits, dict) else _text(joint_limits)
        if payload is not None:
            body["payload"] = dict(payload)
        if allowed_collisions is not None:
            body["allowed_collisions"] = [list(pair) for pair in allowed_collisions] if isinstance(allowed_collisions, list) else _text(allowed_collisions)
        return Robot.from_body(self._call("POST", "/v1/robots", body, timeout=timeout))

    def delete_robot(self, name: str) -> None:
        """``DELETE /v1/robots/{name}``: remove an upload; planning for it answers 404 after.

        Raises:
            ProblemError: 404 when no upload has that name; 409 for a catalog robot.
        """
        self.request("DELETE", f"/v1/robots/{name}")

    def skeleton(self, name: str, q: Any, mounting: dict | None = None) -> Skeleton:
        """``POST /v1/robots/{name}/skeleton``: the arm as a stick figure in configurations
        ``q`` (rad, m; shape (n_configurations, n_dof), at most 1,000 rows); with ``mounting``
        (``{"position": [x, y, z], "orientation": [qx, qy, qz, qw]}``), its base placed in the world."""
        rows = rows_of(q)
        rows = [rows] if rows and not isinstance(rows[0], list) else rows  # one configuration
        request: dict[str, Any] = {"q": rows} if mounting is None else {"q": rows, "mounting": dict(mounting)}
        body = self._call("POST", f"/v1/robots/{name}/skeleton", request)
        return Skeleton(list(body["points"]), np.asarray(body["positions"], dtype=float).reshape(len(rows), -1, 3))

    # --- trajectories ----------------------------------------------------------------------

    def plan(
        self,
        robot: str | dict,
        waypoints: Any = None,
        *,
        path: dict | None = None,
        method: str | None = None,
        constraints: list[str] | None = None,
        limits: dict | None = None,
        duration: float | None = None,
        timing: dict | None = None,
        dt: float | None = None,
        format: str | None = None,
        exact_period: bool | None = None,
        payload: dict | None = None,
        mounting: dict | None = None,
        timeout: float | None = None,
    ) -> Trajectory | CsvTrajectory:
        """``POST /v1/trajectories``: time a path.

        Args:
            robot: A robot's name, or a whole request body (a dict, e.g. an example file's
                JSON), sent as it is; the other arguments then must be left out.
            waypoints: Joint configurations (rad, m), shape (n_waypoints, n_dof).
            path: A whole ``path`` object instead (cartesian, free, obstacles, ...).
            method: ``timing.method``, e.g. ``"phase_plane"`` or ``"quintic"``.
            constraints: ``timing.constraints``.
            limits: ``timing.limits`` (overrides, scale factors, tool speeds).
            duration: ``timing.duration`` (s), for the classical time laws.
            timing: Other ``timing`` fields (``boundary``, ``cost``, ``grid_points``, ...).
            dt: ``output.dt``, the sample period (s).
            format: ``output.format``: ``samples`` (default), ``joint_trajectory`` or ``csv``.
            exact_period: ``output.exact_period``: samples on whole periods of ``dt``.
            payload: ``payload``, what the robot carries (``{"mass": kg, ...}``).
            mounting: ``mounting``, the base pose and gravity (``{"position": [x, y, z], ...}``).
            timeout: Seconds to wait for this answer instead of the client's.

        Returns:
            A ``Trajectory`` for the JSON formats; a ``CsvTrajectory`` for ``csv``.

        Raises:
            ProblemError: 404 unknown robot; 422 malformed or impossible (``s``, ``joint`` and
                ``limit`` say where a limit cannot be met); 503 busy; 504 over the budget.
            ValueError: a whole body with arguments beside it, or a comparison's body.
        """
        if isinstance(robot, dict):
            if "methods" in robot:
                raise ValueError("this body names methods: it is a comparison; send it with compare(body)")
            _alone(robot, waypoints=waypoints, path=path, method=method, constraints=constraints, limits=limits,
                   duration=duration, timing=timing, dt=dt, format=format, exact_period=exact_period, payload=payload,
                   mounting=mounting)
            body = robot
        else:
            body = trajectory_request(
                robot, waypoints, path=path, method=method, constraints=constraints, limits=limits,
                duration=duration, timing=timing, dt=dt, format=format, exact_period=exact_period, payload=payload,
                mounting=mounting,
            )
        answer = self._answer(self.request("POST", "/v1/trajectories", body, timeout=timeout))
        return answer if isinstance(answer, CsvTrajectory) else Trajectory.from_body(answer)

    def compare(
        self,
        robot: str | dict,
        waypoints: Any = None,
        *,
        methods: list[str] | None = None,
        path: dict | None = None,
        constraints: list[str] | None = None,
        limits: dict | None = None,
        timing: dict | None = None,
        payload: dict | None = None,
        mounting: dict | None = None,
        timeout: float | None = None,
    ) -> list[Comparison]:
        """``POST /v1/trajectories/compare``: the same path under each of ``methods``.

        Args:
            robot: A robot's name, or a whole compare body (a dict) sent as it is.
            waypoints: Joint configurations (rad, m), shape (n_waypoints, n_dof).
            methods: Timing methods, e.g. ``["phase_plane", "toppra", "quintic"]``.
            path: A whole ``path`` object instead of ``waypoints``.
            constraints: ``timing.constraints`` shared by every method.
            limits: ``timing.limits`` shared by every method.
            timing: Other ``timing`` fields.
            payload: ``payload``, what the robot carries, for every method.
            mounting: ``mounting``, the base pose and gravity, for every method.
            timeout: Seconds to wait for this answer instead of the client's.

        Returns:
            One ``Comparison`` per method, in the order asked; a method that failed carries
            its ``error`` (not raised).
        """
        if isinstance(robot, dict):
            _alone(robot, waypoints=waypoints, methods=methods, path=path, constraints=constraints, limits=limits, timing=timing,
                   payload=payload, mounting=mounting)
            body = robot
        else:
            if not methods:
                raise ValueError("give methods, e.g. ['phase_plane', 'quintic']")
            body = compare_request(
                robot, waypoints, methods=methods, path=path, constraints=constraints, limits=limits, timing=timing,
                payload=payload, mounting=mounting,
            )
        return comparisons(self._call("POST", "/v1/trajectories/compare", body, timeout=timeout))

    def cell(self, body: dict | str | os.PathLike[str], *, timeout: float | None = None) -> dict:
        """``POST /v1/cells``: two to four arms in one workspace timed together so that their
        links keep a clearance (``examples/cell_two_ur5.json``: a dict, JSON text or a file's
        path; ``format`` ``samples`` or ``joint_trajectory``).

        Returns:
            The JSON answer as sent: ``duration``, ``sampled_duration``, ``solo_durations``,
            ``sequential_duration``, ``time_lost`` (s), ``schedule``, ``t`` (the samples' times,
            s, shared by every arm), ``arms`` (per arm: ``robot``, ``joint_names``, ``samples``
            ``{t, q, qd, qdd, tau}``, or with ``format`` ``joint_trajectory`` a
            ``joint_trajectory``, ``peak_utilization``, ``payload`` and ``base``),
            ``min_distance``, the coordination ``diagram`` of arms 0 and 1, ``diagrams``
            of every pair, and the ``warnings`` (a limit not held that the motion exceeds,
            a sampling that does not follow it).
        """
        return self._call("POST", "/v1/cells", _json_body(body), timeout=timeout)
