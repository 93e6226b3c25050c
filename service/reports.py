"""The JSON bodies of the answer's ``solver``, ``switching_times`` and ``search``
(``SearchPublic`` of ``toptraj.service.schemas.answers``), built from the library's typed
reports; a non-finite number (no bound, no timing) is written as null."""

from __future__ import annotations

import dataclasses
import math
from typing import TYPE_CHECKING

from toptraj.planners.trajectory import SwitchingTimes

if TYPE_CHECKING:  # the generators' reports: a typical request imports neither generator
    from toptraj.planners.generators.collocation.report import CollocationReport
    from toptraj.planners.generators.search.report import LocalReport, SearchReport


def solver_body(report: CollocationReport | None) -> dict | None:
    """The collocation's figures; ``switching`` only for a minimum-time collocation."""
    if report is None:
        return None
    body = dataclasses.asdict(report)
    if report.switching is None:
        del body["switching"]
    return body


def switching_body(switching: SwitchingTimes | None) -> dict[str, list[float]] | None:
    """{joint name: [t, ...]} (s)."""
    if switching is None:
        return None
    return {name: [float(t) for t in times] for name, times in zip(switching.joint_names, switching.times)}


def search_body(report: SearchReport | None) -> dict | None:
    """What the global search did: its statistics, tubes, the tube followed, the region
    searched, the shadows, each tube's local optimization and the final time."""
    if report is None:
        return None
    statistics = report.statistics
    body = {field.name: getattr(statistics, field.name) for field in dataclasses.fields(statistics)}
    body["pruned"] = dict(statistics.pruned)
    for key in ("v_max", "best_grid_time", "upper_bound"):
        body[key] = _finite(body[key])
    body["tube_radius"] = report.tube_radius
    body["tubes"] = [
        {"time": tube.time, "t1": tube.bounds[0], "t2": tube.bounds[1], "t3": tube.bounds[2], "points": tube.points.tolist()}
        for tube in report.tubes
    ]
    body["chosen_tube"] = report.chosen_tube
    body["region"] = {"lower": report.low.tolist(), "upper": report.high.tolist()}
    body["shadows"] = report.shadows
    body["local"] = [_local_body(local) for local in report.local]
    body["final_time"] = report.final_time
    return body


def _local_body(local: LocalReport) -> dict:
    """A tube's local optimization (times in s)."""
    return {
        "grid_time": local.grid_time,
        "seed_time": _finite(local.seed_time),
        "time": local.time,
        "control_points": list(local.control_points),
        "round_times": [_finite(t) for t in local.round_times],
        "evaluations": local.evaluations,
        "stopped": local.stopped,
        "wall_s": local.wall_s,
    }


def _finite(value: float | None) -> float | None:
    """``value``, or ``None`` where it is not finite."""
    return value if value is not None and math.isfinite(value) else None
