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
from toptraj.service.problems import note_text

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


def _joint_rows(result: PlannedTrajectory, limits) -> list[tuple[str, np.ndarray, np.ndarray, str, np.ndarray, np.ndarray]]:
    """Each plotted quantity: its kind, times (s, shape (n,)), values (shape (n, n_dof)), axis
    label, and each joint's lower and upper limit (shape (n_dof,); not finite: none). The jerk,
    for timings with a finite one measured against a finite limit, is the difference of consecutive accelerations over their
    interval, at its midpoint."""
    samples = result.samples
    t = np.asarray(samples.t)
    rows = [("position", t, samples.q, "q (rad)", limits.position_lower, limits.position_upper),
            ("velocity", t, samples.qd, "q̇ (rad/s)", -limits.velocity, limits.velocity),
            ("acceleration", t, samples.qdd, "q̈ (rad/s²)", -limits.acceleration, limits.acceleration)]
    jerk_utilization = result.peak_utilization.get("jerk")
    if jerk_utilization is not None and np.any(np.asarray(jerk_utilization) > 0) and len(t) > 1:
        step = np.diff(t)
        keep = step > 0
        jerk = np.diff(samples.qdd, axis=0)[keep] / step[keep, None]
        rows.append(("jerk", (0.5 * (t[1:] + t[:-1]))[keep], jerk, "jerk (rad/s³)", -limits.jerk, limits.jerk))
    rows.append(("torque", t, samples.tau, "τ (N m)", -limits.torque, limits.torque))
    return rows


def joints_figure(result: PlannedTrajectory, limits) -> go.Figure:
    """Each joint's position, velocity, acceleration, jerk (when the timing has a finite one)
    and torque against its limits (dashed, in the joint's colour)."""
    rows = _joint_rows(result, limits)
    figure = make_subplots(rows=len(rows), cols=1, shared_xaxes=True, vertical_spacing=0.04)
    palette = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22"]
    span = [result.samples.t[0], result.samples.t[-1]]
    for row, (kind, t, values, label, lower, upper) in enumerate(rows, start=1):
        for joint, name in enumerate(result.joint_names):
            color = palette[joint % len(palette)]
            figure.add_scatter(x=t, y=values[:, joint], name=name, legendgroup=name, showlegend=row == 1,
                               line={"color": color}, row=row, col=1)
            for bound in (lower[joint], upper[joint]):
                if np.isfinite(bound):
                    figure.add_scatter(x=span, y=[bound] * 2, mode="lines", showlegend=False, name=f"{name} {kind} limit",
                                       legendgroup=name, hoverinfo="skip", line={"color": color, "dash": "dash", "width": 1}, row=row, col=1)
        figure.update_yaxes(title_text=label, row=row, col=1)
    figure.update_xaxes(title_text="t (s)", row=len(rows), col=1)
    figure.update_layout(title={"text": "Joints against their limits (dashed)"}, height=200 * len(rows))
    return figure


def _plane(points: np.ndarray) -> tuple[int, int] | None:
    """The two coordinates (0: x, 1: y, 2: z) a planar arm's points (shape (..., 3), m) span,
    or None for a spatial arm."""
    flat = np.ptp(points.reshape(-1, 3), axis=0) < 1e-9
    if not flat.any():
        return None
    constant = int(np.flatnonzero(flat)[-1])
    first, second = (axis for axis in range(3) if axis != constant)
    return first, second


def arm_figure(result: PlannedTrajectory, robot: robots.Robot) -> go.Figure:
    """The arm at ``STROBE`` instants: in its plane for a planar arm, else in 3-D, in a figure of
    fixed size that holds the whole scene (a 3-D scene stretched across the page's width is
    cut at its top and bottom)."""
    t = result.samples.t
    rows = spread_indices(len(t), STROBE)
    _, points = skeleton(robot, result.samples.q[rows])
    plane = _plane(points)
    figure = go.Figure()
    for k, (row, figure_points) in enumerate(zip(rows, points)):
        shade = k / max(1, len(rows) - 1)
        style = {"line": {"color": f"rgba(31, 95, 191, {0.15 + 0.85 * shade})", "width": 3}, "name": f"t = {t[row]:.3f} s",
                 "showlegend": k in (0, len(rows) - 1), "mode": "lines+markers"}
        if plane:
            figure.add_scatter(x=figure_points[:, plane[0]], y=figure_points[:, plane[1]], **style)
        else:
            figure.add_scatter3d(x=figure_points[:, 0], y=figure_points[:, 1], z=figure_points[:, 2], **style)
    figure.update_layout(title={"text": "The arm, stroboscopically (light: start, dark: end)"}, width=760, height=700)
    names = ("x (m)", "y (m)", "z (m)")
    if plane:
        figure.update_layout(xaxis={"title": {"text": names[plane[0]]}}, yaxis={"title": {"text": names[plane[1]]}, "scaleanchor": "x"})
    else:
        figure.update_layout(scene={"aspectmode": "data", "camera": {"eye": {"x": 1.8, "y": 1.8, "z": 1.2}}}, margin={"l": 10, "r": 10, "t": 60, "b": 10})
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
