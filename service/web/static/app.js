// The toptraj page: builds a request from the form, plans it through the service's own HTTP API
// (POST /v1/trajectories, /compare, or a job for free paths) and draws the answer with Plotly.
"use strict";

const FALLBACK_METHODS = ["phase_plane", "toppra", "min_cost", "quintic", "cubic", "trapezoidal", "cycloidal", "ruckig", "collocation", "search"];
const CONSTRAINTS = ["velocity", "acceleration", "torque", "jerk"];

const PRESETS = {
  "ur5, spline through 4 waypoints": {
    robot: "ur5",
    path: {kind: "waypoints", interpolation: "spline", waypoints: [
      [0.0, -1.2, 1.0, 0.0, 0.3, 0.0], [0.8, -1.0, 1.4, -0.5, 0.6, 0.3],
      [1.5, -0.5, 0.8, -1.0, 1.0, 0.8], [2.0, -1.3, 1.2, 0.2, 0.4, 1.2]]},
    methods: ["phase_plane", "toppra", "quintic"],
    constraints: ["velocity", "acceleration", "torque"],
  },
  "Geering arm, free path (Jeong & Lee type 3)": {
    robot: "geering_2r",
    path: {kind: "free", start: [0.0, 0.0], goal: [0.76, 0.0], revolutions: true},
    methods: ["collocation"],
    constraints: ["torque"],
  },
  "Geering arm around a sphere (global search, Jeong & Lee §2)": {
    robot: "geering_2r",
    path: {kind: "free", start: [0.0, 0.0], goal: [0.76, 0.0], revolutions: true,
           obstacles: [{kind: "sphere", center: [0.52, 0.28, 0.0], radius: 0.05}]},
    methods: ["search"],
    constraints: ["torque"],
  },
  "Yamamoto arm, straight line": {
    robot: "yamamoto_2r",
    path: {kind: "waypoints", interpolation: "spline", waypoints: [[0.7853981633974483, -1.5707963267948966], [-1.5707963267948966, 0.0]]},
    methods: ["phase_plane", "min_cost", "quintic"],
    constraints: ["torque"],
  },
};

const $ = (id) => document.getElementById(id);
const robotLimits = {};

async function getJSON(url, options) {
  const response = await fetch(url, options);
  const text = await response.text();
  let body = null;
  try { body = text ? JSON.parse(text) : null; } catch (e) { body = {detail: text}; }
  if (!response.ok) {
    const detail = body && (body.detail || body.title) ? `${body.title || "Error"} (${response.status}): ${body.detail || ""}` : `HTTP ${response.status}`;
    const error = new Error(detail);
    error.problem = body;
    throw error;
  }
  return body;
}

function postJSON(url, body) {
  return getJSON(url, {method: "POST", headers: {"content-type": "application/json"}, body: JSON.stringify(body)});
}

function checkboxes(container, names, checked) {
  container.querySelectorAll("label").forEach((label) => label.remove());
  for (const name of names) {
    const label = document.createElement("label");
    const box = document.createElement("input");
    box.type = "checkbox";
    box.value = name;
    box.checked = checked.includes(name);
    label.append(box, " " + name);
    container.append(label);
  }
}

function checked(container) {
  return [...container.querySelectorAll("input:checked")].map((box) => box.value);
}

function applyPreset(name) {
  const preset = PRESETS[name];
  $("robot").value = preset.robot;
  $("path").value = formatPath(preset.path);
  const methods = [...$("methods").querySelectorAll("input")].map((box) => box.value);
  checkboxes($("methods"), methods, preset.methods);
  checkboxes($("constraints"), CONSTRAINTS, preset.constraints);
}

function formatPath(path) {
  // one key per line, and each waypoint (a list of numbers) on a line of its own
  const lines = Object.entries(path).map(([key, value]) => {
    const text = Array.isArray(value) && value.every(Array.isArray)
      ? "[\n    " + value.map((row) => JSON.stringify(row)).join(",\n    ") + "\n  ]"
      : JSON.stringify(value);
    return `  ${JSON.stringify(key)}: ${text}`;
  });
  return "{\n" + lines.join(",\n") + "\n}";
}

async function init() {
  const [robots, openapi] = await Promise.all([getJSON("/v1/robots"), getJSON("/openapi.json")]);
  for (const robot of robots) {
    const option = new Option(`${robot.name} (${robot.dof} joints, ${robot.source})`, robot.name);
    $("robot").append(option);
  }
  const method = openapi.components.schemas.TimingRequest.properties.method;
  const methods = (method && method.enum) || FALLBACK_METHODS;
  checkboxes($("methods"), methods, []);
  for (const name of Object.keys(PRESETS)) $("preset").append(new Option(name, name));
  $("preset").addEventListener("change", () => applyPreset($("preset").value));
  applyPreset(Object.keys(PRESETS)[0]);
  $("plan").addEventListener("click", plan);
  document.body.dataset.ready = "true";
}

function showError(message) {
  $("error").textContent = message;
  $("error").hidden = false;
}

async function limitsOf(robot) {
  if (!robotLimits[robot]) robotLimits[robot] = (await getJSON(`/v1/robots/${encodeURIComponent(robot)}`)).limits;
  return robotLimits[robot];
}

async function runJob(request) {
  const job = await postJSON("/v1/jobs", {trajectory: request});
  for (;;) {
    await new Promise((resolve) => setTimeout(resolve, 400));
    const state = await getJSON(`/v1/jobs/${job.id}`);
    $("status").textContent = `job ${state.status}: ${Math.round(100 * state.progress.fraction)} % ${state.progress.stage}`;
    if (state.status === "done") return state.result;
    if (state.status === "failed") throw new Error(`${state.error.title} (${state.error.status}): ${state.error.detail}`);
    if (state.status === "cancelled" || state.status === "interrupted") throw new Error(`the job was ${state.status}`);
  }
}

async function plan() {
  $("error").hidden = true;
  $("results").hidden = true;
  document.body.dataset.planned = "";
  let path;
  try {
    path = JSON.parse($("path").value);
  } catch (e) {
    showError(`The path is not valid JSON: ${e.message}`);
    return;
  }
  const methods = checked($("methods"));
  if (!methods.length) {
    showError("Choose at least one method.");
    return;
  }
  const robot = $("robot").value;
  const timing = {method: methods[0], constraints: checked($("constraints"))};
  const request = {robot, path, timing, output: {dt: Number($("dt").value)}};
  $("plan").disabled = true;
  $("status").textContent = "planning…";
  try {
    const answer = path.kind === "free" ? await runJob(request) : await postJSON("/v1/trajectories", request);
    let compared = null;
    if (methods.length > 1) {
      const body = {robot, path, methods, timing: {constraints: timing.constraints}};
      compared = await postJSON("/v1/trajectories/compare", body);
    }
    await show(answer, compared, await limitsOf(robot), path);
    $("status").textContent = `planned in ${answer.solve_ms.toFixed(1)} ms`;
    document.body.dataset.planned = "true";
  } catch (error) {
    $("status").textContent = "";
    showError(error.message);
  } finally {
    $("plan").disabled = false;
  }
}

function showDurations(compared) {
  const table = $("durations");
  const body = table.querySelector("tbody");
  body.replaceChildren();
  if (!compared) {
    table.hidden = true;
    return;
  }
  for (const result of compared.results) {
    const row = body.insertRow();
    row.insertCell().textContent = result.method;
    row.insertCell().textContent = result.duration == null ? "–" : result.duration.toFixed(4);
    row.insertCell().textContent = result.solve_ms == null ? "–" : result.solve_ms.toFixed(1);
    row.insertCell().textContent = result.error ? result.error.detail : (result.binding ? `${result.binding.kind} ${result.binding.joint || ""}` : "");
  }
  table.hidden = false;
}

async function show(answer, compared, limits, path) {
  $("results").hidden = false;
  $("duration").textContent = `${answer.method}: ${answer.duration.toFixed(4)} s`;
  $("duration").dataset.duration = String(answer.duration);
  $("binding").textContent = answer.binding ? `(binding: ${answer.binding.kind} of ${answer.binding.joint || "the path"} at s = ${answer.binding.s.toFixed(3)})` : "";
  $("warnings").replaceChildren(...answer.warnings.map((text) => Object.assign(document.createElement("li"), {textContent: text})));
  showDurations(compared);
  drawPhasePlane(answer);
  drawJoints(answer, limits);
  await drawArm(answer, path);
}

const LAYOUT = {margin: {l: 55, r: 15, t: 40, b: 45}, font: {size: 11}, legend: {orientation: "h"}};

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
  Plotly.newPlot("phase-plane", traces, {...LAYOUT, title: {text: "Phase plane"}, xaxis: {title: {text: "s"}}, yaxis}, {responsive: true});
}

function interpolate(xs, ys, x) {
  let i = 1;
  while (i < xs.length - 1 && xs[i] < x) i += 1;
  const t = xs[i] === xs[i - 1] ? 0 : (x - xs[i - 1]) / (xs[i] - xs[i - 1]);
  return ys[i - 1] + t * (ys[i] - ys[i - 1]);
}

function drawJoints(answer, limits) {
  const samples = answer.samples;
  const rows = [["q", "q (rad)", null], ["qd", "q̇ (rad/s)", limits.velocity], ["qdd", "q̈ (rad/s²)", limits.acceleration], ["tau", "τ (N m)", limits.torque]];
  const colors = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22"];
  const traces = [];
  const layout = {...LAYOUT, title: {text: "Joints against their limits (dashed)"}, grid: {rows: 4, columns: 1, pattern: "independent"}, height: 640, showlegend: true};
  rows.forEach(([key, label, limit], row) => {
    const axis = row === 0 ? "" : String(row + 1);
    answer.joint_names.forEach((name, joint) => {
      const color = colors[joint % colors.length];
      traces.push({x: samples.t, y: samples[key].map((values) => values[joint]), name, legendgroup: name, showlegend: row === 0,
                   mode: "lines", line: {color}, xaxis: `x${axis}`, yaxis: `y${axis}`});
      if (limit && limit[joint] != null && answer.peak_utilization[{qd: "velocity", qdd: "acceleration", tau: "torque"}[key]][joint] > 0.5) {
        for (const sign of [1, -1]) {
          traces.push({x: [samples.t[0], samples.t[samples.t.length - 1]], y: [sign * limit[joint], sign * limit[joint]], mode: "lines",
                       line: {color, dash: "dash", width: 1}, legendgroup: name, showlegend: false, hoverinfo: "skip", xaxis: `x${axis}`, yaxis: `y${axis}`});
        }
      }
    });
    layout[`yaxis${axis}`] = {title: {text: label}};
    layout[`xaxis${axis}`] = {title: {text: row === 3 ? "t (s)" : ""}};
  });
  Plotly.newPlot("joints", traces, layout, {responsive: true});
}

async function drawArm(answer, path) {
  const count = Math.min(12, answer.samples.t.length);
  const indices = [...Array(count).keys()].map((k) => Math.round((k * (answer.samples.t.length - 1)) / Math.max(1, count - 1)));
  const figure = await postJSON(`/v1/robots/${encodeURIComponent(answer.robot)}/skeleton`, {q: indices.map((i) => answer.samples.q[i])});
  const all = figure.positions.flat();
  const planar = all.every((p) => Math.abs(p[2] - all[0][2]) < 1e-9);
  const traces = figure.positions.map((points, k) => {
    const shade = count > 1 ? k / (count - 1) : 1;
    const color = `rgba(31, 95, 191, ${0.15 + 0.85 * shade})`;
    const trace = {x: points.map((p) => p[0]), y: points.map((p) => p[1]), mode: "lines+markers", line: {color, width: 3}, marker: {size: 4, color},
                   name: `t = ${answer.samples.t[indices[k]].toFixed(3)} s`, showlegend: k === 0 || k === count - 1};
    if (!planar) Object.assign(trace, {type: "scatter3d", z: points.map((p) => p[2])});
    return trace;
  });
  if (planar) traces.unshift(...obstacleTraces(answer, path));
  const layout = {...LAYOUT, title: {text: "The arm, stroboscopically (light: start, dark: end)"}};
  if (planar) Object.assign(layout, {xaxis: {title: {text: "x (m)"}}, yaxis: {title: {text: "y (m)"}, scaleanchor: "x"}});
  else layout.scene = {aspectmode: "data", xaxis: {title: {text: "x (m)"}}, yaxis: {title: {text: "y (m)"}}, zaxis: {title: {text: "z (m)"}}};
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

init().catch((error) => showError(`The page could not start: ${error.message}`));
