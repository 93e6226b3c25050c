// The toptraj page: builds a request from the form, plans it through the service's own HTTP API
// (POST /v1/trajectories, /compare, or a job for free paths, which can be cancelled) and shows
// the answer (draw.js: the plots; exports.js: the utilization table, downloads, the URL).
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

const CELL_PRESET_NAME = "Two ur5 across a table, crossing paths (a cell: POST /v1/cells)";
const $ = (id) => document.getElementById(id);
const robotLimits = {};
// the job being planned: its id, and whether the page asked to cancel it
let running = null;

class Cancelled extends Error {}

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

function showFormFor(text) {
  // a cell's request (with arms) takes its robots, limits and constraints from its body: the
  // single-arm controls are hidden while the path field holds one
  let cell = false;
  try {
    cell = isCell(JSON.parse(text));
  } catch (error) {
    cell = document.body.dataset.form === "cell" && /"arms"/.test(text);  // mid-edit: as it was
  }
  document.body.dataset.form = cell ? "cell" : "trajectory";
}

function applyPreset(name) {
  applyPresetFields(name);
  showFormFor($("path").value);
}

function applyPresetFields(name) {
  if (name === CELL_PRESET_NAME) {
    // one line per arm
    const lines = Object.entries(CELL_PRESET).map(([key, value]) => (Array.isArray(value)
      ? `  ${JSON.stringify(key)}: [\n    ${value.map((item) => JSON.stringify(item)).join(",\n    ")}\n  ]`
      : `  ${JSON.stringify(key)}: ${JSON.stringify(value)}`));
    $("path").value = "{\n" + lines.join(",\n") + "\n}";
    return;
  }
  const preset = PRESETS[name];
  if (!preset) return;
  $("robot").value = preset.robot;
  $("path").value = formatPath(preset.path);
  const methods = [...$("methods").querySelectorAll("input")].map((box) => box.value);
  checkboxes($("methods"), methods, preset.methods);
  checkboxes($("constraints"), CONSTRAINTS, preset.constraints);
}

function formatPath(path) {
  // one key per line, and each waypoint (a list of numbers), or each arm of a cell, on a line of its own
  const lines = Object.entries(path).map(([key, value]) => {
    const text = Array.isArray(value) && value.length && value.every((item) => item !== null && typeof item === "object")
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
  for (const name of [...Object.keys(PRESETS), CELL_PRESET_NAME]) $("preset").append(new Option(name, name));
  $("preset").addEventListener("change", () => applyPreset($("preset").value));
  $("path").addEventListener("input", () => showFormFor($("path").value));
  applyPreset(Object.keys(PRESETS)[0]);
  $("plan").addEventListener("click", plan);
  $("cancel").addEventListener("click", cancel);
  // a link pasted over this page's own (the page only ever replaces its fragment itself)
  window.addEventListener("hashchange", () => location.reload());
  let shared = null;
  try {
    shared = await requestInURL();
  } catch (error) {
    showError(`The link's request was not opened: ${error.message}`);
  }
  if (shared) applyForm(shared);
  document.body.dataset.ready = "true";
  // a shared waypoint or Cartesian path is planned at once; a free path (a job that may run for
  // minutes) waits for Plan
  if (shared && shared.path.kind !== "free") await plan();
  else if (shared) $("status").textContent = "The link's request is in the form: press Plan to plan it.";
}

function applyForm(form) {
  if (![...$("robot").options].some((option) => option.value === form.robot)) $("robot").append(new Option(form.robot, form.robot));
  $("preset").prepend(new Option("(the link's request)", ""));
  $("preset").value = "";
  $("robot").value = form.robot;
  $("path").value = formatPath(form.path);
  const methods = [...$("methods").querySelectorAll("input")].map((box) => box.value);
  checkboxes($("methods"), [...methods, ...form.methods.filter((name) => !methods.includes(name))], form.methods);
  checkboxes($("constraints"), CONSTRAINTS, form.constraints);
  $("dt").value = String(form.dt);
  showFormFor($("path").value);
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
  running = {id: job.id, cancelling: false, started: Date.now()};
  document.body.dataset.job = job.id;
  $("cancel").hidden = false;
  try {
    for (;;) {
      await new Promise((resolve) => setTimeout(resolve, 400));
      const state = await getJSON(`/v1/jobs/${job.id}`).catch((error) => {
        // a job that ended as it was cancelled is deleted with its answer (DELETE of an ended job)
        if (running.cancelling && error.problem && error.problem.status === 404) throw new Cancelled("Cancelled: the job ended as it was cancelled, and its answer was deleted.");
        throw error;
      });
      if (!running.cancelling) $("status").textContent = `job ${state.status}: ${Math.round(100 * state.progress.fraction)} % ${state.progress.stage}`;
      if (state.status === "done") return state.result;
      if (state.status === "failed") throw new Error(`${state.error.title} (${state.error.status}): ${state.error.detail}`);
      if (state.status === "cancelled") throw new Cancelled(`Cancelled: the job ran ${((Date.now() - running.started) / 1000).toFixed(1)} s and was stopped; nothing was planned.`);
      if (state.status === "interrupted") throw new Error("the job was interrupted (the server stopped); plan again");
    }
  } finally {
    running = null;
    $("cancel").hidden = true;
    $("cancel").disabled = false;
  }
}

async function cancel() {
  // DELETE /v1/jobs/{id}: a running job's worker is stopped; the polling loop then sees it
  // cancelled
  if (!running || running.cancelling) return;
  running.cancelling = true;
  $("cancel").disabled = true;
  $("status").textContent = "cancelling the job…";
  try {
    await getJSON(`/v1/jobs/${running.id}`, {method: "DELETE"});
  } catch (error) {
    if (running) running.cancelling = false;
    $("cancel").disabled = false;
    showError(`The job could not be cancelled: ${error.message}`);
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
  if (isCell(path)) {
    await planAsCell(path);
    return;
  }
  document.body.dataset.view = "trajectory";
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
    $("link-note").textContent = await keepInURL({robot, path, methods, constraints: timing.constraints, dt: request.output.dt});
    const answer = path.kind === "free" ? await runJob(request) : await postJSON("/v1/trajectories", request);
    let compared = null;
    if (methods.length > 1) {
      const body = {robot, path, methods, timing: {constraints: timing.constraints}};
      compared = await postJSON("/v1/trajectories/compare", body);
    }
    await show(answer, compared, await limitsOf(robot), path, timing.constraints);
    $("status").textContent = `planned in ${answer.solve_ms.toFixed(1)} ms`;
    document.body.dataset.planned = "true";
  } catch (error) {
    $("status").textContent = error instanceof Cancelled ? error.message : "";
    if (!(error instanceof Cancelled)) showError(error.message);
  } finally {
    $("plan").disabled = false;
  }
}

async function planAsCell(request) {
  $("plan").disabled = true;
  $("status").textContent = "planning the cell…";
  try {
    const dt = Number($("dt").value);
    // the cell in the URL, before planning as a trajectory's request is (robot, methods and
    // constraints are the form's: a cell takes its own from its body)
    const note = await keepInURL({robot: $("robot").value, path: request, methods: checked($("methods")), constraints: checked($("constraints")), dt});
    const answer = await planCell(request, dt);
    $("link-note").textContent = note;
    $("status").textContent = `planned: ${answer.arms.length} arms on one clock`;
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

async function show(answer, compared, limits, path, constraints) {
  $("results").hidden = false;
  $("duration").textContent = `${answer.method}: ${answer.duration.toFixed(4)} s`;
  $("duration").dataset.duration = String(answer.duration);
  $("binding").textContent = answer.binding ? `(binding: ${answer.binding.kind} of ${answer.binding.joint || "the path"} at s = ${answer.binding.s.toFixed(3)})` : "";
  $("warnings").replaceChildren(...answer.warnings.map((text) => Object.assign(document.createElement("li"), {textContent: text})));
  showDurations(compared);
  showUtilization(answer, constraints);
  offerDownloads(answer);
  drawPhasePlane(answer);
  drawJoints(answer, limits);
  await drawArm(answer, path);
}

init().catch((error) => showError(`The page could not start: ${error.message}`));
