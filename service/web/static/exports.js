// What the toptraj page gives back: the peak utilization per joint, the answer as files (JSON,
// CSV, trajectory_msgs/JointTrajectory, the page itself as one HTML file), and the request kept
// in the URL so that a page can be shared.
"use strict";

const KINDS = ["velocity", "acceleration", "jerk", "torque"];
// limits are held within 0.5 % on a dense resampling (the service's contract)
const TOLERANCE = 0.005;

function showUtilization(answer, constraints) {
  // one row per joint, a column per limit kind the answer reports (a kind left out of the
  // constraints only where some joint uses its limit; a joint without a finite limit reads null,
  // shown as "no limit"); a limit held that the joint reaches (within the tolerance of 0.5 %) is
  // marked: those bind the motion
  const used = (kind) => constraints.includes(kind) || answer.peak_utilization[kind].some((value) => value > 0);
  const kinds = KINDS.filter((kind) => answer.peak_utilization[kind] && used(kind));
  const head = $("utilization").querySelector("thead tr");
  head.replaceChildren(...["joint", ...kinds].map((kind) => {
    const cell = document.createElement("th");
    cell.textContent = kind === "joint" || constraints.includes(kind) ? kind : `${kind} (not constrained)`;
    return cell;
  }));
  const body = $("utilization").querySelector("tbody");
  body.replaceChildren();
  answer.joint_names.forEach((name, joint) => {
    const row = body.insertRow();
    row.insertCell().textContent = name;
    const values = kinds.map((kind) => answer.peak_utilization[kind][joint]);
    kinds.forEach((kind, k) => {
      const cell = row.insertCell();
      cell.dataset.kind = kind;
      cell.dataset.value = String(values[k]);
      if (values[k] === null) {
        cell.textContent = "no limit";
        cell.title = "this joint has no finite limit of this kind";
        return;
      }
      cell.textContent = values[k].toFixed(4);
      if (constraints.includes(kind) && values[k] >= 1 - TOLERANCE) {
        cell.classList.add("binding");
        cell.title = "this joint reaches this limit: it binds the motion";
        cell.textContent += " ◀";
      }
      if (constraints.includes(kind) && values[k] > 1 + TOLERANCE) cell.classList.add("over");
    });
  });
}

function csvText(answer) {
  // the samples as shown, laid out as the service's CSV (service/formats.py): its header, then a
  // row per sample (without the service's "#" lines of metadata, which the JSON download holds)
  const names = answer.joint_names;
  // a name holding a comma or a quote is quoted, as the service writes it (RFC 4180)
  const field = (text) => (/[",]/.test(text) ? `"${text.replaceAll('"', '""')}"` : text);
  const header = ["t", ...["q", "qd", "qdd", "tau"].flatMap((quantity) => names.map((name) => field(`${quantity}.${name}`)))];
  const s = answer.samples;
  const rows = s.t.map((t, k) => [t, ...s.q[k], ...s.qd[k], ...s.qdd[k], ...s.tau[k]].join(","));
  return [header.join(","), ...rows].join("\n") + "\n";
}

function jointTrajectory(answer) {
  // the samples as trajectory_msgs/JointTrajectory (service/formats.py): time_from_start in
  // whole seconds and the nanoseconds within the second
  const s = answer.samples;
  const points = s.t.map((t, k) => {
    const nanoseconds = Math.round(t * 1e9);
    return {positions: s.q[k], velocities: s.qd[k], accelerations: s.qdd[k], effort: s.tau[k],
            time_from_start: {sec: Math.floor(nanoseconds / 1e9), nanosec: nanoseconds % 1e9}};
  });
  return {joint_names: answer.joint_names, points};
}

function save(name, type, text) {
  const link = document.createElement("a");
  link.href = URL.createObjectURL(new Blob([text], {type}));
  link.download = name;
  document.body.append(link);
  link.click();
  link.remove();
  setTimeout(() => URL.revokeObjectURL(link.href), 10_000);
}

async function pageHTML() {
  // the answer as one HTML file that opens offline: the style and Plotly's JavaScript inlined,
  // the answer's text as shown, and each plot redrawn from its data and layout
  const [style, plotly] = await Promise.all(["/static/web/style.css", "/static/web/plotly.min.js"].map(async (url) => (await fetch(url)).text()));
  const results = $("results").cloneNode(true);
  results.querySelector("#downloads").remove();
  const plots = {};
  for (const div of results.querySelectorAll(".plot")) {
    const shown = $(div.id);
    plots[div.id] = {data: shown.data, layout: shown.layout};
    div.replaceChildren();
  }
  const data = JSON.stringify(plots).replace(/</g, "\\u003c");
  const draw = `const plots = ${data};\nfor (const [id, plot] of Object.entries(plots)) Plotly.newPlot(id, plot.data, plot.layout, {responsive: true});`;
  const escape = (text) => text.replace(/<\/script/gi, "<\\/script");
  const title = `${document.title}: ${$("duration").textContent}`.replace(/&/g, "&amp;").replace(/</g, "&lt;");
  return `<!doctype html>\n<html lang="en"><head><meta charset="utf-8"><title>${title}</title>`
    + `<meta name="viewport" content="width=device-width, initial-scale=1"><style>${style}</style><script>${escape(plotly)}</script></head>`
    + `<body><main class="saved">${results.outerHTML}</main><script>${escape(draw)}</script></body></html>`;
}

function offerDownloads(answer) {
  const stem = `${answer.robot}_${answer.method}`;
  $("download-json").onclick = () => save(`${stem}.json`, "application/json", JSON.stringify(answer, null, 1));
  $("download-csv").onclick = () => save(`${stem}.csv`, "text/csv", csvText(answer));
  $("download-joint-trajectory").onclick = () => save(`${stem}_joint_trajectory.json`, "application/json", JSON.stringify(jointTrajectory(answer)));
  $("download-html").onclick = async () => save(`${stem}.html`, "text/html", await pageHTML());
}

// The request in the URL's fragment: its JSON, deflated and base64url-encoded, after "#r=".
// Bounded both ways: a longer fragment is refused before it is decoded, and the inflated text
// is read no further than MAX_REQUEST_CHARS.
const MAX_FRAGMENT_CHARS = 16_384;
const MAX_REQUEST_CHARS = 262_144;

async function deflate(text) {
  const stream = new Blob([text]).stream().pipeThrough(new CompressionStream("deflate-raw"));
  const bytes = new Uint8Array(await new Response(stream).arrayBuffer());
  let binary = "";
  for (let k = 0; k < bytes.length; k += 8192) binary += String.fromCharCode(...bytes.subarray(k, k + 8192));
  return btoa(binary).replace(/\+/g, "-").replace(/\//g, "_").replace(/=+$/, "");
}

async function inflate(encoded) {
  const binary = atob(encoded.replace(/-/g, "+").replace(/_/g, "/"));
  const bytes = Uint8Array.from(binary, (c) => c.charCodeAt(0));
  const reader = new Blob([bytes]).stream().pipeThrough(new DecompressionStream("deflate-raw")).pipeThrough(new TextDecoderStream()).getReader();
  let text = "";
  for (;;) {
    const {done, value} = await reader.read();
    if (done) return text;
    text += value;
    if (text.length > MAX_REQUEST_CHARS) {
      reader.cancel();
      throw new Error(`it holds more than ${MAX_REQUEST_CHARS} characters of request`);
    }
  }
}

async function keepInURL(form) {
  // the form's request in the URL (replacing the entry, not adding one); a request too large
  // for a URL is left out, and the page says so
  const encoded = await deflate(JSON.stringify({v: 1, ...form}));
  if (encoded.length > MAX_FRAGMENT_CHARS) {
    history.replaceState(null, "", location.pathname + location.search);
    return `The request is too large to keep in the URL (${encoded.length} characters compressed, at most ${MAX_FRAGMENT_CHARS}): this page's link does not reopen it.`;
  }
  history.replaceState(null, "", `${location.pathname}${location.search}#r=${encoded}`);
  return "";
}

async function requestInURL() {
  // the request a shared URL holds (robot, path, methods, constraints, dt), or null
  const match = /^#r=([A-Za-z0-9_-]*)$/.exec(location.hash);
  if (!location.hash) return null;
  if (!match) throw new Error("the URL's fragment is not a request of this page (it should read #r= and base64url text)");
  if (match[1].length > MAX_FRAGMENT_CHARS) throw new Error(`the URL's request is ${match[1].length} characters long, more than the ${MAX_FRAGMENT_CHARS} a link may hold`);
  let form;
  try {
    form = JSON.parse(await inflate(match[1]));
  } catch (error) {
    throw new Error(`the URL's request cannot be read (${error.message}); open the page without its #r= part and plan again`);
  }
  const strings = (value) => Array.isArray(value) && value.length <= 16 && value.every((item) => typeof item === "string");
  if (!form || form.v !== 1 || typeof form.robot !== "string" || typeof form.path !== "object" || !form.path
      || !strings(form.methods) || !strings(form.constraints) || typeof form.dt !== "number") {
    throw new Error("the URL's request lacks robot, path, methods, constraints or dt; open the page without its #r= part and plan again");
  }
  return form;
}
