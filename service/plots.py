"""The web page's plots of one planned trajectory as a self-contained HTML file
(``toptraj plot``): the phase plane with its maximum velocity curve and switching points, the
joints against their limits, and the arm stroboscopically (``toptraj.planners.kinematics.skeleton``).
Plotly's JavaScript is inlined once, so the file opens offline."""

from __future__ import annotations

import html

import numpy as np
import plotly.graph_objects as go
from plotly.io import to_html
from plotly.subplots import make_subplots

from toptraj import robots
from toptraj.planners import PlannedTrajectory
from toptraj.planners.kinematics.skeleton import skeleton
from toptraj.planners.paths.grid import spread_indices
from toptraj.service.errors import note_text

#: Instants of the stroboscopic picture.
STROBE = 12


def phase_plane_figure(result: PlannedTrajectory) -> go.Figure:
    plane = result.phase_plane
    s, sd = np.asarray(plane.s), np.asarray(plane.sd)
    mvc = np.asarray(plane.sd_max, dtype=float)
    figure = go.Figure()
    figure.add_scatter(x=s, y=np.where(np.isfinite(mvc), mvc, np.nan), name="maximum velocity curve", line={"dash": "dot", "color": "#c0392b"})
    figure.add_scatter(x=s, y=sd, name="path speed ṡ", line={"color": "#1f5fbf"})
    for kind in sorted({kind for _, kind in plane.switch_points}):
        at = np.array([point for point, k in plane.switch_points if k == kind])
        figure.add_scatter(x=at, y=np.interp(at, s, sd), mode="markers", name=f"switch: {kind}", marker={"size": 9})
    top = float(sd.max()) if sd.size else 1.0
    yaxis: dict[str, object] = {"title": {"text": "ṡ (1/s)"}, "rangemode": "tozero"}
    if np.nanmax(np.append(mvc[np.isfinite(mvc)], 0.0)) > 2 * top:
        yaxis["range"] = [0, 1.6 * top]
    figure.update_layout(title={"text": "Phase plane"}, xaxis={"title": {"text": "s"}}, yaxis=yaxis)
    return figure


def joints_figure(result: PlannedTrajectory, limits) -> go.Figure:
    samples = result.samples
    rows = (("q", "q (rad)", None, None), ("qd", "q̇ (rad/s)", limits.velocity, "velocity"),
            ("qdd", "q̈ (rad/s²)", limits.acceleration, "acceleration"), ("tau", "τ (N m)", limits.torque, "torque"))
    figure = make_subplots(rows=4, cols=1, shared_xaxes=True, vertical_spacing=0.04)
    palette = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22"]
    for row, (key, label, limit, kind) in enumerate(rows, start=1):
        values = getattr(samples, key)
        for joint, name in enumerate(result.joint_names):
            color = palette[joint % len(palette)]
            figure.add_scatter(x=samples.t, y=values[:, joint], name=name, legendgroup=name, showlegend=row == 1,
                               line={"color": color}, row=row, col=1)
            utilization = None if kind is None else result.peak_utilization.get(kind)
            if limit is not None and np.isfinite(limit[joint]) and utilization is not None and utilization[joint] > 0.5:
                for sign in (1, -1):
                    figure.add_scatter(x=[samples.t[0], samples.t[-1]], y=[sign * limit[joint]] * 2, mode="lines", showlegend=False,
                                       legendgroup=name, hoverinfo="skip", line={"color": color, "dash": "dash", "width": 1}, row=row, col=1)
        figure.update_yaxes(title_text=label, row=row, col=1)
    figure.update_xaxes(title_text="t (s)", row=4, col=1)
    figure.update_layout(title={"text": "Joints against their limits (dashed)"}, height=800)
    return figure


def arm_figure(result: PlannedTrajectory, robot: robots.Robot) -> go.Figure:
    t = result.samples.t
    rows = spread_indices(len(t), STROBE)
    _, points = skeleton(robot, result.samples.q[rows])
    planar = np.ptp(points[..., 2]) < 1e-9
    figure = go.Figure()
    for k, (row, figure_points) in enumerate(zip(rows, points)):
        shade = k / max(1, len(rows) - 1)
        style = {"line": {"color": f"rgba(31, 95, 191, {0.15 + 0.85 * shade})", "width": 3}, "name": f"t = {t[row]:.3f} s",
                 "showlegend": k in (0, len(rows) - 1), "mode": "lines+markers"}
        if planar:
            figure.add_scatter(x=figure_points[:, 0], y=figure_points[:, 1], **style)
        else:
            figure.add_scatter3d(x=figure_points[:, 0], y=figure_points[:, 1], z=figure_points[:, 2], **style)
    figure.update_layout(title={"text": "The arm, stroboscopically (light: start, dark: end)"})
    if planar:
        figure.update_layout(xaxis={"title": {"text": "x (m)"}}, yaxis={"title": {"text": "y (m)"}, "scaleanchor": "x"})
    else:
        figure.update_layout(scene={"aspectmode": "data"})
    return figure


def figures_html(result: PlannedTrajectory) -> str:
    """One HTML page with the three figures of ``result`` and its duration and warnings."""
    robot = robots.load(result.robot)
    parts = [
        to_html(figure, full_html=False, include_plotlyjs=(k == 0))
        for k, figure in enumerate((phase_plane_figure(result), joints_figure(result, robot.limits), arm_figure(result, robot)))
    ]
    warnings = "".join(f"<li>{html.escape(note_text(text))}</li>" for text in result.warnings)
    title = f"{html.escape(result.robot)}, {html.escape(result.method)}: {result.duration:.4f} s"
    return (
        f"<!doctype html><html><head><meta charset='utf-8'><title>toptraj: {title}</title></head>"
        f"<body style='font-family: system-ui, sans-serif'><h1>{title}</h1><ul>{warnings}</ul>{''.join(parts)}</body></html>"
    )
