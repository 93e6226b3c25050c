// A cell on the page: a request with `arms` (POST /v1/cells) is shown as every arm in one
// stroboscope, each placed by its base pose (the skeleton endpoint with its mounting), and the
// coordination diagram of arms 0 and 1: the collision region in (s1, s2) and the curve taken.
"use strict";

const CELL_COLORS = [[31, 95, 191], [214, 39, 40], [44, 160, 44], [148, 103, 189]];
const CELL_PRESET = {
  clearance: 0.02,
  arms: [
    {robot: "ur5", base: {position: [0.0, 0.0, 0.0]},
     waypoints: [[1.5, -0.5, 0.5, 0.0, 0.0, 0.0], [0.0, -0.6, 0.6, 0.0, 0.3, 0.0], [-1.5, -0.5, 0.5, 0.0, 0.0, 0.0]]},
    {robot: "ur5", base: {position: [1.2, 0.0, 0.0], rotation: [[-1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]]},
     waypoints: [[1.5, -0.5, 0.5, 0.0, 0.0, 0.0], [0.0, -0.6, 0.6, 0.0, -0.3, 0.0], [-1.5, -0.5, 0.5, 0.0, 0.0, 0.0]]},
  ],
};

function isCell(request) {
  return request !== null && typeof request === "object" && Array.isArray(request.arms);
}

async function planCell(request, dt) {
  // the cell as written, sampled every dt, all its arms on one clock
  const body = {...request, dt, format: "samples"};
  document.body.dataset.view = "cell";
  $("link-note").textContent = "";
  const answer = await postJSON("/v1/cells", body);
  $("results").hidden = false;
  $("duration").textContent = `cell of ${answer.arms.length} arms: ${answer.duration.toFixed(4)} s`;
  $("duration").dataset.duration = String(answer.duration);
  $("binding").textContent = `(${answer.schedule}; each arm alone ${answer.solo_durations.map((d) => d.toFixed(4)).join(", ")} s, `
    + `lost to coordination ${answer.time_lost.toFixed(4)} s; closest ${(1000 * answer.min_distance.distance).toFixed(1)} mm)`;
  $("warnings").replaceChildren(...(answer.warnings || []).map((text) => Object.assign(document.createElement("li"), {textContent: text})));
  drawDiagram(answer.diagram);
  await drawCellArms(answer, body);
  return answer;
}

function drawDiagram(diagram) {
  // blocked[i][j] is (s1 = s[i], s2 = s[j]): a heatmap's z is indexed [y][x], so s2 up the side
  const z = diagram.s.map((_, j) => diagram.s.map((__, i) => diagram.blocked[i][j]));
  const traces = [
    {type: "heatmap", x: diagram.s, y: diagram.s, z, name: "arms too close", showscale: false, hoverinfo: "skip",
     colorscale: [[0, "rgba(255, 255, 255, 0)"], [1, "rgba(192, 57, 43, 0.55)"]]},
    {x: diagram.curve.map((p) => p[0]), y: diagram.curve.map((p) => p[1]), mode: "lines", name: "the arms' coordination",
     line: {color: "#1f5fbf", width: 3}},
  ];
  const layout = {...LAYOUT, title: plotTitle("Coordination diagram (red: arms too close)"),
    xaxis: {title: {text: "s of arms[0]", standoff: 4}, range: [0, 1], automargin: true},
    yaxis: {title: {text: "s of arms[1]"}, range: [0, 1], scaleanchor: "x"}};
  Plotly.newPlot("phase-plane", traces, layout, {responsive: true});
}

async function drawCellArms(answer, body) {
  const t = answer.t;
  const count = Math.min(12, t.length);
  const indices = [...Array(count).keys()].map((k) => Math.round((k * (t.length - 1)) / Math.max(1, count - 1)));
  const traces = [];
  for (const [index, arm] of answer.arms.entries()) {
    const base = arm.base || body.arms[index].base || {};  // the pose planned with (a quaternion given, a matrix echoed)
    const mounting = {position: base.position || [0, 0, 0], rotation: base.rotation || [[1, 0, 0], [0, 1, 0], [0, 0, 1]]};
    const figure = await postJSON(`/v1/robots/${encodeURIComponent(arm.robot)}/skeleton`, {q: indices.map((i) => arm.samples.q[i]), mounting});
    const [r, g, b] = CELL_COLORS[index % CELL_COLORS.length];
    figure.positions.forEach((points, k) => {
      const color = `rgba(${r}, ${g}, ${b}, ${0.15 + 0.85 * (count > 1 ? k / (count - 1) : 1)})`;
      traces.push({type: "scatter3d", mode: "lines+markers", line: {color, width: 3}, marker: {size: 3, color},
        x: points.map((p) => p[0]), y: points.map((p) => p[1]), z: points.map((p) => p[2]),
        name: `arms[${index}] t = ${t[indices[k]].toFixed(3)} s`, showlegend: k === 0 || k === count - 1});
    });
  }
  const shown = traces.filter((trace) => trace.showlegend).length;
  const layout = {...LAYOUT, title: plotTitle("The arms, stroboscopically (light: start, dark: end)"),
    margin: {...LAYOUT.margin, b: legendMargin(shown, $("arm").clientWidth)},
    scene: {aspectmode: "data", camera: {eye: {x: 0.4, y: -2.0, z: 1.2}}, xaxis: {title: {text: "x (m)"}}, yaxis: {title: {text: "y (m)"}}, zaxis: {title: {text: "z (m)"}}}};
  Plotly.newPlot("arm", traces, layout, {responsive: true});
}
