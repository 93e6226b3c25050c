// The toptraj page's plots (Plotly): the phase plane with its maximum velocity curve and
// switching points, each joint against its limits, and the arm stroboscopically.
"use strict";

// the legend below the plot, under the x axis title (in the container's coordinates, so that the
// two never overlap whatever the plot's height)
const LAYOUT = {margin: {l: 55, r: 15, t: 64, b: 45}, font: {size: 11}, legend: {orientation: "h", yref: "container", y: 0, yanchor: "bottom"}};

function plotTitle(text) {
  // a plot's title below Plotly's toolbar (its top 30 px), which would cover a long title on a phone
  return {text, yref: "container", y: 1, yanchor: "top", pad: {t: 30}};
}
const JOINT_COLORS = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22"];

function legendMargin(count, width) {
  // rows of a horizontal legend of `count` entries, about 130 px each, on a plot `width` px wide
  const perRow = Math.max(1, Math.floor((width - 20) / 130));
  return 45 + 20 * Math.ceil(count / perRow);
}

function drawPhasePlane(answer) {
  const plane = answer.phase_plane;
  const traces = [
    {x: plane.s, y: plane.sd_max, name: "maximum velocity curve", mode: "lines", line: {dash: "dot", color: "#c0392b"}},
    {x: plane.s, y: plane.sd, name: "path speed ṡ", mode: "lines", line: {color: "#1f5fbf"}},
  ];
  const kinds = [...new Set(plane.switch_points.map((point) => point.kind))];
  const symbols = ["circle", "diamond", "square", "triangle-up", "x"];
  kinds.forEach((kind, index) => {
    const points = plane.switch_points.filter((point) => point.kind === kind);
    const speed = points.map((point) => interpolate(plane.s, plane.sd, point.s));
    traces.push({x: points.map((p) => p.s), y: speed, name: `switch: ${kind}`, mode: "markers", marker: {symbol: symbols[index % symbols.length], size: 9}});
  });
  // the maximum velocity curve may soar where the path nearly stops (a free path's ends): keep
  // the path speed readable
  const top = Math.max(...plane.sd);
  const yaxis = {title: {text: "ṡ (1/s)"}, rangemode: "tozero"};
  if (Math.max(...plane.sd_max.filter((v) => v != null)) > 2 * top) yaxis.range = [0, 1.6 * top];
  const margin = {...LAYOUT.margin, b: legendMargin(traces.length, $("phase-plane").clientWidth)};
  Plotly.newPlot("phase-plane", traces, {...LAYOUT, margin, title: plotTitle("Phase plane"), xaxis: {title: {text: "s", standoff: 4}, automargin: true}, yaxis}, {responsive: true});
}

function interpolate(xs, ys, x) {
  let i = 1;
  while (i < xs.length - 1 && xs[i] < x) i += 1;
  const t = xs[i] === xs[i - 1] ? 0 : (x - xs[i - 1]) / (xs[i] - xs[i - 1]);
  return ys[i - 1] + t * (ys[i] - ys[i - 1]);
}

function jerkSamples(samples) {
  // the jerk between consecutive samples, (q̈[k+1] - q̈[k]) / (t[k+1] - t[k]), at the midpoints
  const t = [], values = [];
  for (let k = 0; k + 1 < samples.t.length; k += 1) {
    const step = samples.t[k + 1] - samples.t[k];
    if (!(step > 0)) continue;
    t.push((samples.t[k] + samples.t[k + 1]) / 2);
    values.push(samples.qdd[k + 1].map((value, joint) => (value - samples.qdd[k][joint]) / step));
  }
  return {t, values};
}

function jointRows(answer, limits) {
  // each plotted quantity: its samples, its axis label and each joint's [lower, upper] limit
  const samples = answer.samples;
  const symmetric = (values) => values.map((v) => (v == null ? null : [-v, v]));
  const rows = [
    {kind: "position", t: samples.t, values: samples.q, label: "q (rad)", bounds: limits.position_lower.map((low, j) => (low == null || limits.position_upper[j] == null ? null : [low, limits.position_upper[j]]))},
    {kind: "velocity", t: samples.t, values: samples.qd, label: "q̇ (rad/s)", bounds: symmetric(limits.velocity)},
    {kind: "acceleration", t: samples.t, values: samples.qdd, label: "q̈ (rad/s²)", bounds: symmetric(limits.acceleration)},
  ];
  // the jerk where the answer reports it against a finite limit (an infinite one reads 0)
  if (answer.peak_utilization.jerk && answer.peak_utilization.jerk.some((value) => value > 0)) {
    const jerk = jerkSamples(samples);
    rows.push({kind: "jerk", t: jerk.t, values: jerk.values, label: "jerk (rad/s³)", bounds: symmetric(limits.jerk)});
  }
  rows.push({kind: "torque", t: samples.t, values: samples.tau, label: "τ (N m)", bounds: symmetric(limits.torque)});
  return rows;
}

function drawJoints(answer, limits) {
  const rows = jointRows(answer, limits);
  const traces = [];
  const height = 160 * rows.length;
  const layout = {...LAYOUT, title: plotTitle("Joints against their limits (dashed)"), grid: {rows: rows.length, columns: 1, pattern: "independent"}, height, showlegend: true};
  layout.margin = {...LAYOUT.margin, b: legendMargin(answer.joint_names.length, $("joints").clientWidth)};
  const span = [answer.samples.t[0], answer.samples.t[answer.samples.t.length - 1]];
  rows.forEach((row, index) => {
    const axis = index === 0 ? "" : String(index + 1);
    const axes = {xaxis: `x${axis}`, yaxis: `y${axis}`};
    answer.joint_names.forEach((name, joint) => {
      const color = JOINT_COLORS[joint % JOINT_COLORS.length];
      traces.push({x: row.t, y: row.values.map((values) => values[joint]), name, legendgroup: name, showlegend: index === 0, mode: "lines", line: {color}, ...axes});
      for (const bound of row.bounds[joint] || []) {
        traces.push({x: span, y: [bound, bound], mode: "lines", name: `${name} ${row.kind} limit`, meta: {limit: row.kind, joint: name},
                     line: {color, dash: "dash", width: 1}, legendgroup: name, showlegend: false, hoverinfo: "skip", ...axes});
      }
    });
    layout[`yaxis${axis}`] = {title: {text: row.label}};
    layout[`xaxis${axis}`] = {title: {text: index === rows.length - 1 ? "t (s)" : "", standoff: 4}, automargin: true};
  });
  $("joints").style.minHeight = `${height}px`;
  Plotly.newPlot("joints", traces, layout, {responsive: true});
}

function planeOf(points) {
  // the two coordinates a planar arm moves in ([0, 1] for x, y), or null for a spatial arm
  const constant = [0, 1, 2].filter((axis) => points.every((p) => Math.abs(p[axis] - points[0][axis]) < 1e-9));
  if (!constant.length) return null;
  return [0, 1, 2].filter((axis) => axis !== constant[constant.length - 1]).slice(0, 2);
}

async function drawArm(answer, path) {
  const count = Math.min(12, answer.samples.t.length);
  const indices = [...Array(count).keys()].map((k) => Math.round((k * (answer.samples.t.length - 1)) / Math.max(1, count - 1)));
  const figure = await postJSON(`/v1/robots/${encodeURIComponent(answer.robot)}/skeleton`, {q: indices.map((i) => answer.samples.q[i])});
  const plane = planeOf(figure.positions.flat());
  const names = ["x (m)", "y (m)", "z (m)"];
  const traces = figure.positions.map((points, k) => {
    const shade = count > 1 ? k / (count - 1) : 1;
    const color = `rgba(31, 95, 191, ${0.15 + 0.85 * shade})`;
    const trace = {mode: "lines+markers", line: {color, width: 3}, marker: {size: 4, color},
                   name: `t = ${answer.samples.t[indices[k]].toFixed(3)} s`, showlegend: k === 0 || k === count - 1};
    if (plane) return {...trace, x: points.map((p) => p[plane[0]]), y: points.map((p) => p[plane[1]])};
    return {...trace, type: "scatter3d", x: points.map((p) => p[0]), y: points.map((p) => p[1]), z: points.map((p) => p[2])};
  });
  if (plane && plane[0] === 0 && plane[1] === 1) traces.unshift(...obstacleTraces(answer, path));
  const shown = traces.filter((trace) => trace.showlegend !== false).length;
  const layout = {...LAYOUT, title: plotTitle("The arm, stroboscopically (light: start, dark: end)"), margin: {...LAYOUT.margin, b: legendMargin(shown, $("arm").clientWidth)}};
  if (plane) Object.assign(layout, {xaxis: {title: {text: names[plane[0]], standoff: 4}, automargin: true}, yaxis: {title: {text: names[plane[1]]}, scaleanchor: "x"}});
  else layout.scene = {aspectmode: "data", camera: {eye: {x: 1.6, y: 1.6, z: 1.1}}, xaxis: {title: {text: "x (m)"}}, yaxis: {title: {text: "y (m)"}}, zaxis: {title: {text: "z (m)"}}};
  Plotly.newPlot("arm", traces, layout, {responsive: true});
}

function obstacleTraces(answer, path) {
  // a planar arm's picture: the obstacle shadows of the search (the tip positions where a link
  // would meet an obstacle, per elbow branch; Jeong & Lee §2.2) and the spheres themselves
  const traces = [];
  const shadows = answer.search && answer.search.shadows;
  const colors = ["rgba(230, 126, 34, 0.25)", "rgba(142, 68, 173, 0.25)"];
  if (shadows) {
    shadows.shadows.forEach((branch, k) => traces.push({x: branch.points.map((p) => p[0]), y: branch.points.map((p) => p[1]), mode: "markers",
      marker: {size: 3, color: colors[k % colors.length]}, name: `obstacle shadow, ${branch.branch}`, hoverinfo: "skip"}));
  }
  for (const obstacle of (path && path.obstacles) || []) {
    if (obstacle.kind !== "sphere") continue;
    const angles = [...Array(49).keys()].map((k) => (2 * Math.PI * k) / 48);
    traces.push({x: angles.map((a) => obstacle.center[0] + obstacle.radius * Math.cos(a)), y: angles.map((a) => obstacle.center[1] + obstacle.radius * Math.sin(a)),
                 mode: "lines", fill: "toself", line: {color: "#555"}, fillcolor: "rgba(85, 85, 85, 0.5)", name: "obstacle"});
  }
  return traces;
}
