"""The page of ``toptraj plot`` for a comparison: every method of one path timed, and drawn
over the others: the phase plane (path speed ṡ over s under the maximum velocity curve) and
the use of each limit over time (at each instant, the largest |value| / limit over the
joints; 1 is at the limit), with the comparison's table (``toptraj.service.compare_table``). Plotly's
JavaScript is inlined once, so the file opens offline."""

from __future__ import annotations

import html

import numpy as np
import plotly.graph_objects as go
from plotly.io import to_html
from plotly.subplots import make_subplots

from toptraj import robots
from toptraj.planners import Deadline, PlannedTrajectory
from toptraj.service.compare_table import compare_table
from toptraj.service.planning import compare_results, requested_limits
from toptraj.service.schemas.trajectories import CompareRequest

#: One color per method, in the order of ``methods``.
PALETTE = ("#1f5fbf", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf")
#: Sample period of each method's trajectory on the page, s.
DT = 0.01
#: The limits whose use is drawn: the sample field and its label.
USES = (("qd", "velocity"), ("qdd", "acceleration"), ("tau", "torque"))


def phase_planes_figure(planned: list[PlannedTrajectory]) -> go.Figure:
    """Each method's path speed ṡ(s) (1/s), over the maximum velocity curve of the first."""
    figure = go.Figure()
    mvc = np.asarray(planned[0].phase_plane.sd_max, dtype=float)
    figure.add_scatter(x=planned[0].phase_plane.s, y=np.where(np.isfinite(mvc), mvc, np.nan), name="maximum velocity curve",
                       line={"dash": "dot", "color": "#555"})
    for k, result in enumerate(planned):
        figure.add_scatter(x=result.phase_plane.s, y=result.phase_plane.sd, name=result.method, line={"color": PALETTE[k % len(PALETTE)]})
    top = max(float(np.max(result.phase_plane.sd)) for result in planned)
    yaxis: dict[str, object] = {"title": {"text": "ṡ (1/s)"}, "rangemode": "tozero"}
    if np.nanmax(np.append(mvc[np.isfinite(mvc)], 0.0)) > 2 * top:
        yaxis["range"] = [0, 1.6 * top]
    figure.update_layout(title={"text": "Phase plane, every method"}, xaxis={"title": {"text": "s"}}, yaxis=yaxis)
    return figure


def limit_use(values: np.ndarray, limit: np.ndarray) -> np.ndarray | None:
    """At each sample, the largest |value| / limit over the joints with a finite limit:
    ``values`` of shape (n_samples, n_dof), ``limit`` (n_dof,); ``None`` when no joint has one."""
    limited = np.isfinite(limit) & (limit > 0)
    if not limited.any():
        return None
    return np.max(np.abs(values[:, limited]) / limit[limited], axis=1)


def limit_use_figure(planned: list[PlannedTrajectory], limits: robots.JointLimits) -> go.Figure:
    """For velocity, acceleration and torque, each method's use of the limit over time."""
    figure = make_subplots(rows=len(USES), cols=1, shared_xaxes=True, vertical_spacing=0.06)
    for row, (key, kind) in enumerate(USES, start=1):
        for k, result in enumerate(planned):
            use = limit_use(getattr(result.samples, key), getattr(limits, kind))
            if use is not None:
                figure.add_scatter(x=result.samples.t, y=use, name=result.method, legendgroup=result.method, showlegend=row == 1,
                                   line={"color": PALETTE[k % len(PALETTE)]}, row=row, col=1)
        figure.add_hline(y=1.0, line={"dash": "dash", "width": 1, "color": "#555"}, row=row, col=1)
        figure.update_yaxes(title_text=f"{kind} / limit", rangemode="tozero", row=row, col=1)
    figure.update_xaxes(title_text="t (s)", row=len(USES), col=1)
    figure.update_layout(title={"text": "Each limit's use over time (largest over the joints; 1: at the limit)"}, height=700)
    return figure


def compare_html(request: CompareRequest, deadline: Deadline) -> str:
    """One HTML page comparing the methods of ``request``: its table, each method's warnings
    and the two overlaid figures (none when every method failed)."""
    outcomes = compare_results(request, deadline, DT)
    planned = [result for _, result in outcomes if result is not None]
    table = compare_table({"results": [entry for entry, _ in outcomes]})
    warnings = "".join(
        f"<li>{html.escape(entry['method'])}: {html.escape(text)}</li>" for entry, _ in outcomes for text in entry.get("warnings") or ()
    )
    parts = []
    if planned:
        limits = requested_limits(request, robots.load(request.robot))
        figures = (phase_planes_figure(planned), limit_use_figure(planned, limits))
        parts = [to_html(figure, full_html=False, include_plotlyjs=(k == 0)) for k, figure in enumerate(figures)]
    title = f"{html.escape(request.robot)}: {html.escape(', '.join(request.methods))} compared"
    return (
        f"<!doctype html><html><head><meta charset='utf-8'><title>toptraj: {title}</title></head>"
        f"<body style='font-family: system-ui, sans-serif'><h1>{title}</h1><pre>{html.escape(table)}</pre>"
        f"<ul>{warnings}</ul>{''.join(parts)}</body></html>"
    )
