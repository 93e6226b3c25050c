"""The shapes a planned trajectory is served in (``output.format``).

* ``samples``: the DESIGN.md body, ``samples = {t, q, qd, qdd, tau}`` with one row per instant.
* ``joint_trajectory``: the same body with ``joint_trajectory`` in place of ``samples``, shaped
  as ROS's ``trajectory_msgs/JointTrajectory`` message in JSON: ``joint_names`` and ``points``,
  each with ``positions`` (rad or m), ``velocities``, ``accelerations``, ``effort`` (N m or N)
  and ``time_from_start = {sec, nanosec}`` (``builtin_interfaces/Duration``: whole seconds and
  the nanoseconds within the second, rounded to the nanosecond), ready for a
  ``FollowJointTrajectory`` goal.
* ``csv``: ``text/csv``, a header ``t,q.<joint>,…,qd.<joint>,…,qdd.<joint>,…,tau.<joint>,…``,
  then the answer's metadata as lines starting with ``#`` (``# key: value``: robot, method,
  duration and sampled_duration in s, each peak utilization per joint in the columns' order,
  the binding limit, the warnings), then a row per sample (numbers as JSON writes them,
  shortest round trip). Chosen by ``output.format = "csv"`` or by ``Accept: text/csv`` (a
  client that prefers CSV over JSON). The header comes first so that readers skipping comment
  lines read it as the header: ``pandas.read_csv(f, comment="#")``,
  ``numpy.loadtxt(f, delimiter=",", skiprows=1)``, ``numpy.genfromtxt(f, delimiter=",",
  names=True)``, ``csv.DictReader`` over the lines not starting with ``#`` (docs/http-api.md,
  "Reading the CSV"; a reader that does not skip them takes them for rows).

Controllers consume points at a fixed period, so ``joint_trajectory`` and ``csv`` put the
samples on whole periods by default (``output.exact_period``, see
``toptraj.planners.trajectory.sample_trajectory``).
"""

from __future__ import annotations

import csv
import io
from collections.abc import Mapping

import numpy as np

from toptraj.planners import PlannedTrajectory
from toptraj.planners.checks.gate import PROMISED_TOLERANCE

FORMATS = ("samples", "joint_trajectory", "csv")
CSV_MEDIA_TYPE = "text/csv; charset=utf-8"
#: How far past a limit asked an answer may go on a dense resampling, in percent of the limit
#: (the promise, ``toptraj.planners.checks.gate.PROMISED_TOLERANCE``).
TOLERANCE_PERCENT = round((PROMISED_TOLERANCE - 1.0) * 100, 6)


def _quality(accept: str, media: str) -> float:
    """The q-value ``accept`` (an HTTP Accept header) gives ``media``: that of its most specific
    matching range (``type/subtype`` over ``type/*`` over ``*/*``, RFC 9110 §12.5.1), 0 if none."""
    main = media.split("/")[0]
    ranks = {media: 2, f"{main}/*": 1, "*/*": 0}
    best_rank, best_q = -1, 0.0
    for part in accept.split(","):
        fields = [f.strip() for f in part.split(";")]
        rank = ranks.get(fields[0].lower(), -1)
        if rank <= best_rank:
            continue
        q = 1.0
        for field in fields[1:]:
            if field.startswith("q="):
                try:
                    q = float(field[2:])
                except ValueError:
                    q = 0.0
        best_rank, best_q = rank, q
    return best_q


def chosen_format(requested: str, accept: str | None) -> str:
    """``output.format``, except that a request left at the default ``samples`` whose Accept
    header prefers ``text/csv`` to ``application/json`` gets ``csv``."""
    if requested != "samples" or not accept:
        return requested
    csv_q, json_q = _quality(accept, "text/csv"), _quality(accept, "application/json")
    return "csv" if csv_q > json_q or (csv_q > 0 and csv_q == json_q and "text/csv" in accept.lower()) else requested


def exact_period_for(format_: str, exact_period: bool | None) -> bool:
    """Whether samples lie on whole periods: as asked, else for the controller formats."""
    return format_ != "samples" if exact_period is None else exact_period


def time_from_start(t: np.ndarray) -> list[dict]:
    """``builtin_interfaces/Duration`` of each time ``t`` (s, >= 0): whole seconds and the
    nanoseconds within the second, rounded to the nearest nanosecond."""
    nanoseconds = np.rint(np.asarray(t, dtype=float) * 1e9).astype(np.int64)
    seconds, rest = np.divmod(nanoseconds, 1_000_000_000)
    return [{"sec": int(s), "nanosec": int(n)} for s, n in zip(seconds, rest)]


def joint_trajectory(result: PlannedTrajectory) -> dict:
    """The samples as a ``trajectory_msgs/JointTrajectory`` (without its header)."""
    samples = result.samples
    stamps = time_from_start(samples.t)
    return {
        "joint_names": list(result.joint_names),
        "points": [
            {
                "positions": samples.q[k],
                "velocities": samples.qd[k],
                "accelerations": samples.qdd[k],
                "effort": samples.tau[k],
                "time_from_start": stamps[k],
            }
            for k in range(len(samples.t))
        ],
    }


def _utilization_text(value) -> str:
    """A peak utilization as the CSV writes it: ``null`` for a joint without a finite limit."""
    return "null" if value is None or not np.isfinite(float(value)) else repr(float(value))


def csv_metadata(body: Mapping) -> list[str]:
    """The ``# key: value`` lines of a trajectory body's CSV (``body`` as
    ``toptraj.service.planning.trajectory_body`` builds it, or as its JSON decodes): robot, method,
    durations (s), peak utilization per limit (one value per joint, in the columns' order),
    the binding limit and the warnings, one line each. Line breaks within a value become
    spaces, so that every line stays a comment."""
    lines = [
        f"robot: {body['robot']}",
        f"method: {body['method']}",
        f"duration: {float(body['duration'])!r} s",
        f"sampled_duration: {float(body['sampled_duration'])!r} s",
        "peak_utilization: peak |value| / limit per joint on a dense resampling; 1 is at the limit, and the "
        f"limits asked are held within {TOLERANCE_PERCENT:g} %",
    ]
    for kind, values in body["peak_utilization"].items():
        lines.append(f"peak_utilization.{kind}: " + ",".join(_utilization_text(v) for v in np.atleast_1d(np.asarray(values, dtype=object))))
    binding = body.get("binding")
    if binding is not None:
        where = "the whole path" if binding["joint"] is None else f"joint {binding['joint']}"
        lines.append(f"binding: {binding['kind']}, {where}, s = {float(binding['s'])!r}")
    lines.append(f"warnings: {len(body['warnings'])}")
    lines += [f"warning: {text}" for text in body["warnings"]]
    return ["# " + " ".join(line.split()) for line in lines]


def csv_bytes(body: Mapping) -> bytes:
    """A trajectory body as CSV: a header naming each column, the ``#`` lines of
    ``csv_metadata``, then one row per sample. ``body["samples"]`` holds numpy arrays or lists."""
    samples = body["samples"]
    names = list(body["joint_names"])
    header = ["t"] + [f"{quantity}.{name}" for quantity in ("q", "qd", "qdd", "tau") for name in names]
    table = np.column_stack([np.asarray(samples[key], dtype=float) for key in ("t", "q", "qd", "qdd", "tau")])
    out = io.StringIO()
    # quoted as RFC 4180 asks where a joint's name holds a comma or a quote
    csv.writer(out, lineterminator="\n").writerow(header)
    out.write("\n".join(csv_metadata(body)) + "\n")
    for row in table:
        out.write(",".join(repr(float(v)) for v in row) + "\n")
    return out.getvalue().encode()
