"""``Client``: the toptraj HTTP API as Python calls (see the package docstring)."""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import httpx
import numpy as np


class ProblemError(Exception):
    """An answer that is not a success: the problem+json's ``status``, ``title`` and ``detail``
    (and, for a path that cannot be followed, ``s``, ``joint`` and ``limit`` in ``problem``)."""

    def __init__(self, problem: dict):
        self.problem = problem
        self.status = int(problem.get("status", 0))
        self.title = str(problem.get("title", ""))
        self.detail = str(problem.get("detail", ""))
        super().__init__(f"{self.status} {self.title}: {self.detail}")


@dataclass(frozen=True)
class Trajectory:
    """A planned trajectory: ``duration`` (s), samples ``t`` (n,) and ``q``, ``qd``, ``qdd``,
    ``tau`` (n, n_dof) in SI units, the peak utilization of each limit per joint, the warnings,
    and the whole answer as the service sent it (``body``)."""

    robot: str
    method: str
    joint_names: list[str]
    duration: float
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    tau: np.ndarray
    peak_utilization: dict[str, Any]
    warnings: list[str]
    body: dict = field(repr=False)

    @classmethod
    def from_body(cls, body: dict) -> Trajectory:
        samples = body["samples"]
        return cls(
            robot=body["robot"],
            method=body["method"],
            joint_names=list(body["joint_names"]),
            duration=float(body["duration"]),
            t=np.asarray(samples["t"], dtype=float),
            q=np.asarray(samples["q"], dtype=float),
            qd=np.asarray(samples["qd"], dtype=float),
            qdd=np.asarray(samples["qdd"], dtype=float),
            tau=np.asarray(samples["tau"], dtype=float),
            peak_utilization=body["peak_utilization"],
            warnings=list(body["warnings"]),
            body=body,
        )


@dataclass(frozen=True)
class Comparison:
    """One method's result of a compare: its duration (s) and solve time (ms), or its error."""

    method: str
    duration: float | None
    solve_ms: float | None
    error: dict | None


class Client:
    """The toptraj API at ``base_url`` (or through a given ``httpx.Client``, e.g. a test client)."""

    def __init__(self, base_url: str = "http://127.0.0.1:8000", timeout: float = 60.0, http: httpx.Client | None = None):
        self._http = http or httpx.Client(base_url=base_url, timeout=timeout)
        self._owned = http is None

    def __enter__(self) -> Client:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        if self._owned:
            self._http.close()

    def _call(self, method: str, path: str, body: dict | None = None) -> Any:
        response = self._http.request(method, path, json=body)
        if response.status_code >= 400:
            try:
                problem = response.json()
            except ValueError:
                problem = {"status": response.status_code, "title": response.reason_phrase, "detail": response.text[:500]}
            raise ProblemError(problem)
        return response.json() if response.content else None

    def robots(self) -> list[dict]:
        """The catalog and the uploads: ``{name, dof, source}`` each."""
        return self._call("GET", "/v1/robots")

    def robot(self, name: str) -> dict:
        """One robot's joints, end effector and limits."""
        return self._call("GET", f"/v1/robots/{name}")

    def upload(self, urdf: str, name: str | None = None) -> dict:
        """Upload a URDF; returns the robot's description (its ``name`` among it)."""
        return self._call("POST", "/v1/robots", {"urdf": urdf, **({"name": name} if name else {})})

    @staticmethod
    def _request(robot: str, path: dict | None, waypoints, timing: dict | None, **timing_fields) -> dict:
        if (path is None) == (waypoints is None):
            raise ValueError("give either path (a request's path object) or waypoints")
        if path is None:
            path = {"kind": "waypoints", "waypoints": np.asarray(waypoints, dtype=float).tolist()}
        timing = {**(timing or {}), **{k: v for k, v in timing_fields.items() if v is not None}}
        return {"robot": robot, "path": path, "timing": timing}

    def plan(
        self,
        robot: str,
        waypoints=None,
        *,
        path: dict | None = None,
        method: str | None = None,
        constraints: list[str] | None = None,
        timing: dict | None = None,
        dt: float = 0.01,
    ) -> Trajectory:
        """``POST /v1/trajectories``: time the path (``waypoints``, or a whole ``path`` object)
        under ``constraints`` with ``method`` (the service's defaults otherwise)."""
        body = self._request(robot, path, waypoints, timing, method=method, constraints=constraints)
        body["output"] = {"dt": dt}
        return Trajectory.from_body(self._call("POST", "/v1/trajectories", body))

    def compare(
        self,
        robot: str,
        waypoints=None,
        *,
        methods: list[str],
        path: dict | None = None,
        constraints: list[str] | None = None,
        timing: dict | None = None,
    ) -> list[Comparison]:
        """``POST /v1/trajectories/compare``: the same path under each of ``methods``."""
        body = self._request(robot, path, waypoints, timing, constraints=constraints)
        body["methods"] = list(methods)
        results = self._call("POST", "/v1/trajectories/compare", body)["results"]
        return [Comparison(r["method"], r.get("duration"), r.get("solve_ms"), r.get("error")) for r in results]

    def plan_in_background(self, request: dict, budget_s: float | None = None, poll_s: float = 0.5, timeout_s: float = 3600.0) -> Trajectory:
        """A long request (a free path) as a job: submitted, waited for, and returned."""
        job = self._call("POST", "/v1/jobs", {"trajectory": request, **({"budget_s": budget_s} if budget_s else {})})
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            state = self._call("GET", f"/v1/jobs/{job['id']}")
            if state["status"] == "done":
                return Trajectory.from_body(state["result"])
            if state["status"] == "failed":
                raise ProblemError(state["error"])
            if state["status"] in ("cancelled", "interrupted"):
                raise ProblemError({"status": 409, "title": "Job ended", "detail": f"the job was {state['status']}"})
            time.sleep(poll_s)
        self._call("DELETE", f"/v1/jobs/{job['id']}")
        raise TimeoutError(f"the job did not end within {timeout_s} s; it was cancelled")
