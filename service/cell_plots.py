"""The web page's plots of one planned cell as a self-contained HTML file (``toptraj plot`` of a
body with ``arms``): the coordination diagram of arms 0 and 1 (the collision region in
(s1, s2) and the curve taken), each arm's joints against time, and every arm
stroboscopically, each placed by its base pose (p_world = R p_base + t). Plotly's JavaScript is
inlined once, so the file opens offline."""

from __future__ import annotations

import html

import numpy as np
import plotly.graph_objects as go
from plotly.io import to_html
from plotly.subplots import make_subplots

from toptraj import robots
from toptraj.planners.kinematics.skeleton import skeleton
from toptraj.planners.paths.grid import spread_indices
from toptraj.service.plots import STROBE

#: Each arm's colour (red, green, blue), as on the web page.
COLORS = ((31, 95, 191), (214, 39, 40), (44, 160, 44), (148, 103, 189))


def diagram_figure(diagram: dict) -> go.Figure:
    """The collision region (``blocked`` (M + 1, M + 1), rows s1) and the ``curve`` (n, 2)."""
    s, curve = np.asarray(diagram["s"]), np.asarray(diagram["curve"])
    figure = go.Figure()
    figure.add_heatmap(x=s, y=s, z=np.asarray(diagram["blocked"]).T, name="arms too close", showscale=False, hoverinfo="skip",
                       colorscale=[[0, "rgba(255, 255, 255, 0)"], [1, "rgba(192, 57, 43, 0.55)"]])
    figure.add_scatter(x=curve[:, 0], y=curve[:, 1], mode="lines", name="the arms' coordination", line={"color": "#1f5fbf", "width": 3})
    a, b = diagram["arms"]
    figure.update_layout(title={"text": "Coordination diagram (red: arms too close)"}, width=700, height=700,
                         xaxis={"title": {"text": f"s of arms[{a}]"}, "range": [0, 1]},
                         yaxis={"title": {"text": f"s of arms[{b}]"}, "range": [0, 1], "scaleanchor": "x"})
    return figure


def joints_figure(answer: dict) -> go.Figure:
    """Each arm's joint positions (rad or m) against time, one row per arm."""
    arms = answer["arms"]
    figure = make_subplots(rows=len(arms), cols=1, shared_xaxes=True, vertical_spacing=0.05)
    t = np.asarray(answer["t"])
    for row, arm in enumerate(arms, start=1):
        q = np.asarray(arm["samples"]["q"])
        for joint, name in enumerate(arm["joint_names"]):
            figure.add_scatter(x=t, y=q[:, joint], name=f"arms[{row - 1}].{name}", row=row, col=1)
        figure.update_yaxes(title_text=f"arms[{row - 1}] q (rad)", row=row, col=1)
    figure.update_xaxes(title_text="t (s)", row=len(arms), col=1)
    figure.update_layout(title={"text": "Each arm's joints on one clock"}, height=260 * len(arms))
    return figure


def arms_figure(answer: dict) -> go.Figure:
    """Every arm at ``STROBE`` instants in the world (light: start, dark: end)."""
    t = np.asarray(answer["t"])
    rows = spread_indices(len(t), STROBE)
    figure = go.Figure()
    for index, arm in enumerate(answer["arms"]):
        _, points = skeleton(robots.load(arm["robot"]), np.asarray(arm["samples"]["q"])[rows])
        rotation, position = np.asarray(arm["base"]["rotation"]), np.asarray(arm["base"]["position"])
        points = points @ rotation.T + position
        red, green, blue = COLORS[index % len(COLORS)]
        for k, (row, arm_points) in enumerate(zip(rows, points)):
            color = f"rgba({red}, {green}, {blue}, {0.15 + 0.85 * k / max(1, len(rows) - 1)})"
            figure.add_scatter3d(x=arm_points[:, 0], y=arm_points[:, 1], z=arm_points[:, 2], mode="lines+markers",
                                 line={"color": color, "width": 3}, marker={"size": 3, "color": color},
                                 name=f"arms[{index}] t = {t[row]:.3f} s", showlegend=k in (0, len(rows) - 1))
    figure.update_layout(title={"text": "The arms, stroboscopically (light: start, dark: end)"}, width=760, height=700,
                         scene={"aspectmode": "data", "camera": {"eye": {"x": 0.4, "y": -2.0, "z": 1.2}}},
                         margin={"l": 10, "r": 10, "t": 60, "b": 10})
    return figure


def cell_html(answer: dict) -> str:
    """One HTML page with the three figures of a cell's ``samples`` answer (``POST /v1/cells``)."""
    figures = (diagram_figure(answer["diagram"]), joints_figure(answer), arms_figure(answer))
    parts = [to_html(figure, full_html=False, include_plotlyjs=(k == 0)) for k, figure in enumerate(figures)]
    robots_ = ", ".join(html.escape(arm["robot"]) for arm in answer["arms"])
    title = f"cell of {robots_}: {answer['duration']:.4f} s"
    summary = (
        f"{html.escape(answer['schedule'])}; each arm alone {', '.join(f'{d:.4f}' for d in answer['solo_durations'])} s, "
        f"lost to coordination {answer['time_lost']:.4f} s; closest {1000 * answer['min_distance']['distance']:.1f} mm"
    )
    return (
        f"<!doctype html><html><head><meta charset='utf-8'><title>toptraj: {title}</title></head>"
        f"<body style='font-family: system-ui, sans-serif'><h1>{title}</h1><p>{summary}</p>{''.join(parts)}</body></html>"
    )
