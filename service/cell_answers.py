"""The answer to a cell request in each output format of the trajectory endpoint
(``toptraj.service.formats``), every arm sampled on the same times:

* ``samples``: each arm's ``samples = {t, q, qd, qdd, tau}``, one row per instant;
* ``joint_trajectory``: each arm's ``joint_trajectory``, a ``trajectory_msgs/JointTrajectory``
  (positions, velocities, accelerations, effort, time_from_start), one per arm;
* ``csv``: ``text/csv``, a header ``t,arms[i].q.<joint>,…,arms[i].qd.<joint>,…,arms[i].qdd.<joint>,…,
  arms[i].tau.<joint>,…`` arm after arm, the answer's facts as ``# key: value`` lines, then a row
  per sample (numbers as JSON writes them, shortest round trip).

As the trajectory endpoint's, ``joint_trajectory`` and ``csv`` put the samples on whole periods
by default (``exact_period``, ``toptraj.service.formats.exact_period_for``).

Beside the samples: the durations (the cell's, each arm's own optimum, one after the other, the
time lost to coordination), each arm's peak utilization per limit on a dense resampling, the
arms' smallest distance (the closest pair), and the coordination diagram of arms 0 and 1
(``diagram``) and of every pair (``diagrams``), and the ``warnings``
(``toptraj.service.cell_warnings``).
"""

from __future__ import annotations

import csv
import io
import math

import numpy as np

from toptraj.planners.coordination import Cell, Coordination
from toptraj.planners.coordination.limits import KINDS, dense_loads, peak_utilization
from toptraj.planners.coordination.timing import Schedule
from toptraj.planners.errors import InvalidRequest
from toptraj.service.cell_warnings import cell_warnings
from toptraj.service.equipping import mounting_body, payload_body
from toptraj.service.formats import time_from_start

#: Most samples per arm in an answer.
MAX_SAMPLES = 20_000
#: Points of the chosen curve in the answer's diagram.
CURVE_POINTS = 200
QUANTITIES = ("q", "qd", "qdd", "tau")


def sample_times(duration: float, dt: float) -> np.ndarray:
    """Every ``dt`` from 0, the last sample at ``duration`` (s); InvalidRequest past ``MAX_SAMPLES``."""
    count = int(np.ceil(duration / dt))
    if count > MAX_SAMPLES:
        enough = math.ceil(duration / MAX_SAMPLES * 1e4) / 1e4  # the least dt on a 0.1 ms step
        raise InvalidRequest(
            "dt", dt,
            detail=f"the cell's motion lasts {duration:.4g} s: {count} samples of dt = {dt:g} s exceed {MAX_SAMPLES}; "
            f"give dt >= {enough:g} s",
        )
    return np.minimum(np.arange(count + 1) * dt, duration)


def _joint_trajectory(names, t: np.ndarray, samples: dict) -> dict:
    stamps = time_from_start(t)
    q, qd, qdd, tau = (samples[key] for key in QUANTITIES)
    points = [
        {"positions": q[k], "velocities": qd[k], "accelerations": qdd[k], "effort": tau[k], "time_from_start": stamps[k]}
        for k in range(len(t))
    ]
    return {"joint_names": list(names), "points": points}


def _arm_body(arm, t: np.ndarray, states, peaks: dict, format_: str, s: np.ndarray) -> dict:
    q, qd, qdd = states
    # At rest, Coulomb friction opposes the path's tangent at ``s``, as the arm's planning holds it.
    direction = arm.path.evaluate(s).dq if arm.robot.has_coulomb_friction else None
    samples = {"t": t, "q": q, "qd": qd, "qdd": qdd, "tau": arm.robot.inverse_dynamics(q, qd, qdd, direction)}
    body = {
        "robot": arm.robot.name,
        "joint_names": list(arm.robot.joint_names),
        "peak_utilization": peaks,
        "payload": payload_body(arm.robot.payload, arm.robot.end_effector),
        "base": mounting_body(arm.robot.mounting, arm.robot.model.gravity.linear),
    }
    if format_ == "joint_trajectory":
        body["joint_trajectory"] = _joint_trajectory(arm.robot.joint_names, t, samples)
    else:
        body["samples"] = samples
    return body


def on_whole_periods(schedule: Schedule, dt: float) -> Schedule:
    """``schedule`` slowed uniformly (by less than one period ``dt``, s) to end on a whole
    period: velocities scale by 1/k, accelerations by 1/k^2 and torques move towards the static
    torque of the same pose (``toptraj.planners.coordination.limits``); the arms pass through
    the same configurations together, so their clearance is the same."""
    periods = max(1, math.ceil(schedule.duration / dt - 1e-9))
    return Schedule(schedule.motions, schedule.kind, schedule.stretch * periods * dt / schedule.duration)


def reported_utilization(peaks: dict[str, np.ndarray], limits) -> dict[str, list[float | None]]:
    """An arm's peak utilization per kind and joint, null for a joint without a finite limit of
    that kind (its peak, |value| / inf, reads 0)."""
    return {
        kind: [None if not math.isfinite(limit) else float(value) for value, limit in zip(values, np.asarray(getattr(limits, kind), dtype=float))]
        for kind, values in peaks.items()
    }


def cell_body(cell: Cell, found: Coordination, dt: float, format_: str, exact_period: bool, notes: list[str] | None = None) -> dict:
    """The answer (module docstring); ``format_`` ``csv`` gives the ``samples`` body that
    ``csv_bytes`` writes. With ``exact_period`` the samples lie on whole periods ``dt``, the
    final state included (``on_whole_periods``); ``duration`` stays the planned one and
    ``sampled_duration`` is the last sample's time. The peak utilization is that of the
    samples' motion. ``notes``: warnings from building the arms, first among the answer's."""
    schedule = on_whole_periods(found.schedule, dt) if exact_period else found.schedule
    t = sample_times(schedule.duration, dt)
    loads = dense_loads(cell, schedule)
    peaks = peak_utilization(cell, loads)
    unheld = peak_utilization(cell, loads, kinds=tuple(kind for kind in KINDS if kind not in cell.kinds))
    pick = np.linspace(0, len(found.curve) - 1, CURVE_POINTS).round().astype(int)
    clearance = found.clearance
    return {
        "duration": found.schedule.duration,
        "sampled_duration": float(t[-1]),
        "solo_durations": list(found.solo),
        "sequential_duration": sum(found.solo),
        "time_lost": found.time_lost,
        "schedule": schedule.kind,
        "t": t,
        "arms": [
            _arm_body(arm, t, states, reported_utilization(arm_peaks, arm.limits), format_, s)
            for arm, states, arm_peaks, s in zip(cell.arms, schedule.states(cell, t), peaks, schedule.path_parameters(t).T)
        ],
        "min_distance": {
            "distance": clearance.distance,
            "t": clearance.t,
            "arms": list(clearance.arms),
            "links": list(clearance.links),
            "guaranteed": clearance.bound,
        },
        "diagram": _diagram(found, (0, 1), pick),
        "diagrams": [_diagram(found, pair, pick) for pair in found.diagrams],
        "warnings": [*(notes or []), *cell_warnings(cell, unheld, found.schedule.duration, schedule.duration, dt, len(t))],
    }


def _diagram(found: Coordination, pair: tuple[int, int], pick: np.ndarray) -> dict:
    """The coordination diagram of arms ``pair`` = (a, b): the grid ``s``, ``blocked`` (rows
    s_a: the collision region's nodes, none a corner of a cell the curve enters) and the
    ``curve`` (s_a, s_b) the schedule passes through."""
    diagram = found.diagrams[pair]
    return {"arms": list(pair), "s": diagram.s, "blocked": diagram.region.astype(int), "curve": found.curve[pick][:, list(pair)]}


def _metadata(body: dict) -> list[str]:
    """The ``# key: value`` lines of a cell's CSV."""
    arms = body["arms"]
    distance = body["min_distance"]
    lines = [
        "robots: " + ", ".join(arm["robot"] for arm in arms),
        f"duration: {float(body['duration'])!r} s",
        f"sampled_duration: {float(body['sampled_duration'])!r} s",
        "solo_durations: " + ",".join(repr(float(d)) for d in body["solo_durations"]) + " s",
        f"sequential_duration: {float(body['sequential_duration'])!r} s",
        f"time_lost: {float(body['time_lost'])!r} s",
        f"schedule: {body['schedule']}",
        f"min_distance: {float(distance['distance'])!r} m at t = {float(distance['t'])!r} s between link {distance['links'][0]} "
        f"of arms[{distance['arms'][0]}] and link {distance['links'][1]} of arms[{distance['arms'][1]}]; "
        f"guaranteed {float(distance['guaranteed'])!r} m",
    ]
    for index, arm in enumerate(arms):
        for kind, values in arm["peak_utilization"].items():
            lines.append(f"peak_utilization.arms[{index}].{kind}: " + ",".join("null" if v is None else repr(float(v)) for v in values))
    lines.append(f"warnings: {len(body['warnings'])}")
    lines += [f"warning: {text}" for text in body["warnings"]]
    return ["# " + " ".join(line.split()) for line in lines]


def csv_bytes(body: dict) -> bytes:
    """A cell's ``samples`` body as CSV (module docstring)."""
    header = ["t"]
    columns = [np.asarray(body["t"], dtype=float)[:, None]]
    for index, arm in enumerate(body["arms"]):
        for quantity in QUANTITIES:
            header += [f"arms[{index}].{quantity}.{name}" for name in arm["joint_names"]]
            columns.append(np.asarray(arm["samples"][quantity], dtype=float))
    out = io.StringIO()
    csv.writer(out, lineterminator="\n").writerow(header)  # quoted where a joint's name needs it (RFC 4180)
    out.write("\n".join(_metadata(body)) + "\n")
    for row in np.hstack(columns):
        out.write(",".join(repr(float(v)) for v in row) + "\n")
    return out.getvalue().encode()
