// The workbench page: one WebSocket for the live data and every command, the panels, and the computations
// (cueing, run records; the rig editor in rig.js) over the token-checked API.
"use strict";

const token = new URLSearchParams(location.search).get("token") || "";
const api = (path) => `${path}?token=${encodeURIComponent(token)}`;
const $ = (id) => document.getElementById(id);
const AXES = ["x", "y", "z", "alpha", "beta", "gamma"];
const HISTORY_S = 10;

// What tests and curious users can read: the newest frame and counts of what the page did.
const state = { rig: null, frame: null, frames: 0, page: 0, nextId: 1, replies: [], connected: false };
window.ringpod = state;

// ---- tabs: each keeps its own scroll position ----
const scrolled = {};
document.querySelectorAll(".tab").forEach((b) => b.addEventListener("click", () => {
  const was = document.querySelector(".tab.active");
  if (was) scrolled[was.dataset.panel] = window.scrollY;
  document.querySelectorAll(".tab").forEach((t) => t.classList.toggle("active", t === b));
  document.querySelectorAll(".panel").forEach((p) => p.classList.toggle("active", p.id === "panel-" + b.dataset.panel));
  window.scrollTo(0, scrolled[b.dataset.panel] || 0);
  if (b.dataset.panel === "rig" && !state.rigEditor.file) loadDeviceRig();
  if (b.dataset.panel === "cueing" && !cue.config) loadCueDefaults();
  placeLiveCharts();
}));

// A stream's report ends this page's session: the live charts go back to the Live panel.
function endSession(m) {
  if (state.session) { state.session = null; showSession(); }
}

// ---- the WebSocket ----
let ws = null;
function connect() {
  const scheme = location.protocol === "https:" ? "wss" : "ws";
  ws = new WebSocket(`${scheme}://${location.host}/ws?token=${encodeURIComponent(token)}`);
  ws.onopen = () => { state.connected = true; document.body.classList.remove("offline"); $("link").textContent = "connected"; };
  ws.onclose = (e) => {
    state.connected = false;
    if (leaving) return;
    // What is on screen is no longer the platform: the pose and the STOP are greyed and the header says so.
    document.body.classList.add("offline");
    $("link").textContent = `connection lost${e.reason ? ` (${e.reason})` : ""}: the pose shown is the last one received; reconnecting…`;
    // A workbench started again has a new token: this tab's URL will never connect.
    fetch(api("/")).then((r) => {
      if (r.status === 403) {
        state.restarted = true;
        $("link").textContent = "the workbench was restarted: open the new URL `ringpod ui` printed";
      } else setTimeout(connect, 1000);
    }).catch(() => setTimeout(connect, 1000));
  };
  ws.onmessage = (e) => {
    const m = JSON.parse(e.data);
    if (m.type === "hello") { state.page = m.page; $("file-name-row").hidden = !m.files; }
    else if (m.type === "rig") showRig(m);
    else if (m.type === "frame") showFrame(m);
    else if (m.type === "spare") showSpare(m);
    else if (m.type === "reply") showReply(m);
    else if (m.type === "halted") { state.halted = m; log(m.text); }
    else if (m.type === "stop_pending") showStopPending(m);
    else if (m.type === "notice") showNotice(m);
    else if (m.type === "report") endSession(m), log(`report: ${m.outcome}, ${m.setpoints_applied}/${m.setpoints_sent} applied, limited ${m.limited.host} on the host and ${m.limited.device} on the device`, m.exit_code !== 0 && m.exit_code !== 130);
  };
}

// A page the user leaves closes its connection at once, so that a stream it started stops (the browser may keep
// the page frozen, its socket open, for the back button); coming back connects again.
let leaving = false;
window.addEventListener("pagehide", () => { leaving = true; if (ws) ws.close(); });
window.addEventListener("pageshow", (e) => { if (e.persisted) { leaving = false; connect(); } });

function send(request) {
  const id = state.nextId++;
  if (!ws || ws.readyState !== WebSocket.OPEN) { log(`${request.do}: not connected`, true); return; }
  ws.send(JSON.stringify(Object.assign({ id }, request)));
  log(`> ${request.do}`);
  return id;
}

// Each line numbered from the page's first (the oldest go past 200 lines; the numbers stay those they were given).
let logged = 0;
function log(text, error) {
  const li = document.createElement("li");
  li.value = ++logged;
  li.textContent = `${new Date().toLocaleTimeString()}  ${text}`;
  if (error) li.className = "error";
  const list = $("log");
  list.appendChild(li);
  while (list.children.length > 200) list.removeChild(list.firstChild);
  list.scrollTop = list.scrollHeight;
}

// What the workbench did on its own (a stream stopped because its page went away, a STOP's outcome): a page that
// opens later (a reload) is told what happened before it, at the time it happened.
function showNotice(m) {
  if (m.earlier) log(`before this page opened, at ${new Date(m.at_ms).toLocaleTimeString()}: ${m.text}`);
  else log(m.text, true);
}

function showReply(m) {
  if (m.page !== state.page) { log(`(another page) ${m.text}`, !m.ok); return; }
  state.replies.push(m);
  log(m.text, !m.ok);
}

// ---- the STOP: always on screen, space anywhere but in a text field ----
function halt() {
  send({ do: "halt" });
}
$("halt").addEventListener("click", halt);
// Only where a space is typed does it stay a space: on a checkbox, a select, a number field or a button it is the
// STOP, and their own use of it (a toggle, a click on release) is kept from happening.
const TEXT_INPUTS = ["text", "search", "url", "email", "password", "tel"];
function typing(el) {
  return el.tagName === "TEXTAREA" || el.isContentEditable || (el.tagName === "INPUT" && TEXT_INPUTS.includes(el.type));
}
document.addEventListener("keydown", (e) => {
  if (e.code === "Space" && !typing(document.activeElement)) { e.preventDefault(); e.stopPropagation(); if (!e.repeat) halt(); }
}, true);
document.addEventListener("keyup", (e) => {
  if (e.code === "Space" && !typing(document.activeElement)) { e.preventDefault(); e.stopPropagation(); }
}, true);

// ---- Live ----
const view = new View3d($("view3d"));
const history = { t: [], pose: [], target: [], cost: [], cue: [], limits: [] };
const liveCharts = [];
state.history = history;
let costChart = null;
// The axes as people say them, each with the unit its motion is shown in and the unit of the game's cue beside it.
const AXIS_NAMES = ["surge", "sway", "heave", "roll", "pitch", "yaw"];
const MOTION_UNIT = ["mm", "mm", "mm", "deg", "deg", "deg"];
const CUE_UNIT = ["g", "g", "g", "deg/s", "deg/s", "deg/s"];
// A pose about home in the shown units (mm, deg).
const shown = (v, i) => (i < 3 ? v * 1000 : v * 180 / Math.PI);
// Yaw as one continuous angle: each new value is taken nearest the last one, so a turn past 180 deg goes on
// to 181 rather than jumping to -179.
function unwrap(v, last) {
  if (last === undefined) return v;
  return v + 2 * Math.PI * Math.round((last - v) / (2 * Math.PI));
}

function showRig(rig) {
  state.rig = rig;
  $("rig-name").textContent = `${rig.name} (${rig.source})` + (rig.firmware ? ` · ${rig.firmware}` : "");
  const axis = $("jog-axis");
  axis.innerHTML = "";
  rig.axes.forEach((kind, i) => {
    const o = document.createElement("option");
    o.value = i + 1;
    o.textContent = `${i + 1} (${kind === "ring" ? "carriage" : kind === "angle" ? "shoulder" : kind})`;
    axis.appendChild(o);
  });
  // Degrees of ring for a carriage and of a shoulder's angle, mm for a linear actuator (as `device jog`).
  // The longest jog the device takes, said before it is refused (a carriage its homing back-off).
  axis.onchange = () => {
    const unit = rig.axes[axis.value - 1] === "linear" ? "mm" : "deg", most = (rig.jog_most || [])[axis.value - 1];
    $("jog-unit").textContent = unit;
    $("jog-most").textContent = most ? `at most ${most.toPrecision(3)} ${unit} (${rig.axes[axis.value - 1] === "ring" ? "the carriage's homing back-off" : "its homing search travel"})` : "";
    if (most) $("jog-distance").max = most;
  };
  axis.onchange();
  const charts = $("live-charts");
  charts.innerHTML = "";
  liveCharts.length = 0;
  AXIS_NAMES.forEach((a, i) => {
    const c = new Chart(charts, `${a} (${MOTION_UNIT[i]})`, "");
    c.rightUnit = " " + CUE_UNIT[i];
    // At rest: 2 mm or 1 deg of scale, 0.2 g or 10 deg/s of cue.
    c.minSpan = i < 3 ? 2 : 1;
    c.rightMinSpan = i < 3 ? 0.2 : 10;
    c.canvas.id = `live-${a}`;
    liveCharts.push(c);
  });
  $("live-cost").innerHTML = "";
  costChart = new Chart($("live-cost"), `tick cost (${rig.tick_unit})`, "");
  costChart.canvas.id = "live-tick-cost";
  view.show(rig, null, null);
}

function lamp(on, label, alarm) {
  return `<span class="lamp ${on ? (alarm ? "alarm" : "on") : ""}">${label}</span>`;
}


// ---- the link's health: what is shown is as old as the newest frame ----
// Telemetry comes at 50 frames a second: none for half a second is a stalled link, none for five a lost one. The
// values shown are then greyed, the header says how old they are, and the log says when it began and ended.
const STALLED_MS = 500, LOST_MS = 5000;
let lastFrameAt = 0, stalledSince = 0;
setInterval(() => {
  if (!lastFrameAt || !state.connected) return;
  const age = Date.now() - lastFrameAt;
  if (age < STALLED_MS) return;
  if (!stalledSince) { stalledSince = lastFrameAt; log("no telemetry from the device for half a second: the link is stalled", true); }
  state.link = age >= LOST_MS ? "lost" : "stalled";
  document.body.classList.add("stale");
  $("link").textContent = `link ${state.link}: no telemetry for ${(age / 1000).toFixed(1)} s; the values shown are that old`;
}, 250);

function showStopPending(m) {
  const was = state.stopPending;
  state.stopPending = m.pending;
  document.body.classList.toggle("stop-pending", m.pending);
  $("stop-pending").textContent = m.pending ? "STOP pending: not yet confirmed by the device" : "";
  // Given and confirmed within a moment is the usual case; a STOP the device did not answer is said once, in red,
  // however often it is sent again.
  const unanswered = m.pending && m.text.startsWith("STOP pending");
  if (m.pending !== was || (unanswered && !state.stopUnanswered)) log(m.text, unanswered);
  state.stopUnanswered = m.pending && (state.stopUnanswered || unanswered);
}

function showFrame(f) {
  state.frame = f;
  state.frames++;
  lastFrameAt = Date.now();
  state.link = "live";
  if (stalledSince) {
    log(`telemetry back after ${((lastFrameAt - stalledSince) / 1000).toFixed(1)} s`);
    stalledSince = 0;
    document.body.classList.remove("stale");
  }
  const s = $("state");
  s.textContent = f.state;
  s.className = "state " + f.state.split(/[ :(]/)[0].toLowerCase();
  $("link").textContent = `telemetry ${f.rate_hz.toFixed(0)} Hz, ${f.received} samples`;
  view.show(state.rig, f.placed, f.ghost);
  $("view3d").dataset.pose = f.pose.map((v) => v.toFixed(5)).join(",");
  $("outputs").innerHTML = lamp(f.outputs & 1, "LOGIC_EN") + lamp(f.outputs & 2, "POWER_EN") + lamp(f.outputs & 4, "DRIVERS") + lamp(f.outputs & 8, "AUX1") + lamp(f.outputs & 16, "AUX2");
  if (state.rig) {
    $("inputs").innerHTML = state.rig.inputs.map(([mask, name]) => {
      const on = (f.inputs & mask) !== 0;
      const alarm = name === "e-stop" || name.startsWith("end");
      return lamp(on, name, alarm);
    }).join("");
  }
  const unit = state.rig ? state.rig.tick_unit : "";
  const rows = [["applied", f.applied], ["limited", f.limited], ["refused", f.refused], ["tick cost", `${f.tick_cost} ${unit}`],
    ["device time", f.t.toFixed(2) + " s"], ["streaming", f.streaming ? "yes" : "no"]];
  // The lap preview of a telemetry session: the lap matched, the preview's share, and its departures (fades).
  const lp = f.lap_preview;
  if (lp) rows.push(["lap preview", `lap ${lp.lap}, ${lp.matched ? "matched to lap " + lp.matched : "no match"}, share ${lp.confidence.toFixed(2)}, ${lp.kept}/${lp.laps} laps kept, ${lp.departures} departures`]);
  $("counters").innerHTML = rows.map(([k, v]) => `<tr><td>${k}</td><td id="count-${k.replace(" ", "-")}">${v}</td></tr>`).join("");
  remember(f);
  // A session of this page begins or ends streaming: the live charts go where the user tunes, or back.
  if (f.streaming !== state.wasStreaming) { state.wasStreaming = f.streaming; placeLiveCharts(); }
  // Drawn where the charts are on screen (the Live panel, or the Cueing panel while a session runs).
  if (state.frames % 5 === 0 && $("live-charts").offsetParent !== null) drawLive(f);
  showGates(f.gates);
}

// The rolling history: the motion about home in mm and deg (yaw unwrapped), the game's cue in g and deg/s, and
// where the device limited a setpoint (its count grew).
function remember(f) {
  const home = state.rig ? state.rig.home : [0, 0, 0, 0, 0, 0];
  const n = history.t.length;
  const about = (p, last) => p.map((v, i) => {
    const d = v - home[i];
    return shown(i === 5 ? unwrap(d, last && last[5] * Math.PI / 180) : d, i);
  });
  history.pose.push(about(f.pose, n ? history.pose[n - 1] : null));
  history.target.push(about(f.target, n ? history.target[n - 1] : null));
  history.cue.push(f.cue_input ? [...f.cue_input.force_g, ...f.cue_input.rate_deg_s] : null);
  if (n && f.limited > history.limitedCount) history.limits.push(f.t);
  history.limitedCount = f.limited;
  history.t.push(f.t); history.cost.push(f.tick_cost);
  while (history.t.length && history.t[0] < f.t - HISTORY_S) {
    history.t.shift(); history.pose.shift(); history.target.shift(); history.cost.shift(); history.cue.shift();
  }
  while (history.limits.length && history.limits[0] < f.t - HISTORY_S) history.limits.shift();
}

// Each axis's chart and caption: the followed and commanded motion now, the game's cue now, and the share of
// the platform's reach on that side of home the followed pose uses (the envelope the cueing scans).
function drawLive(f) {
  const env = state.rig && state.rig.envelope;
  const last = history.t.length - 1;
  const events = history.limits.map((x) => ({ x, colour: "#f59e0b" }));
  liveCharts.forEach((c, i) => {
    const cue = history.cue.map((q) => (q ? q[i] : NaN));
    c.set([
      { x: history.t, y: history.target.map((p) => p[i]), colour: pale(COLOURS[i]), width: 4 },
      { x: history.t, y: history.pose.map((p) => p[i]), colour: COLOURS[i], width: 2 },
      { x: history.t, y: cue, colour: "#6b7280", width: 1.5, dash: [5, 3], right: true },
    ], events);
    const followed = history.pose[last][i], commanded = history.target[last][i];
    let share = "";
    if (env && i < 5) {
      const [lo, hi] = env[i];
      const reach = shown(followed >= 0 ? hi : lo, i);
      const used = reach ? Math.min(Math.abs(followed / reach), 1) : 0;
      share = `<span class="share" title="the share of the platform's reach on this side of home the followed pose uses">reach ${(used * 100).toFixed(0)} % <meter min="0" max="1" low="0.7" high="0.9" optimum="0" value="${used.toFixed(3)}"></meter></span>`;
    } else if (i === 5) share = `<span class="share muted">turns freely</span>`;
    const q = history.cue[last];
    const cueText = q ? `cue <b>${q[i].toFixed(i < 3 ? 2 : 1)}</b> ${CUE_UNIT[i]}` : `<span class="muted">no cue</span>`;
    const limited = events.length ? ` <span class="limited">limited ${events.length}×</span>` : "";
    c.caption.innerHTML = `<b>${AXIS_NAMES[i]}</b> <b>${followed.toFixed(1)}</b> ${MOTION_UNIT[i]}` +
      ` <span class="muted">(commanded ${commanded.toFixed(1)})</span> ${cueText} ${share}${limited}`;
  });
  if (costChart) {
    costChart.set([{ x: history.t, y: history.cost, colour: "#374151" }]);
    costChart.caption.textContent = `tick cost (${state.rig ? state.rig.tick_unit : ""}): ${history.cost[last]}`;
  }
}

// ---- Control ----
function showGates(gates) {
  document.querySelectorAll("[data-do]").forEach((b) => {
    const why = gates[b.dataset.do];
    b.disabled = !!why;
    b.title = why || "";
  });
  document.querySelectorAll("[data-gate]").forEach((b) => {
    const why = gates[b.dataset.gate];
    b.disabled = !!why;
    b.title = why || "";
  });
  // One line per reason, naming the actions it holds back: six buttons refused for the same reason read as one.
  const byWhy = new Map();
  for (const [k, why] of Object.entries(gates)) if (why) byWhy.set(why, [...(byWhy.get(why) || []), k]);
  $("gates").innerHTML = [...byWhy].map(([why, ks]) => `<div><b>${ks.join(", ")}</b>: ${escapeHtml(why)}</div>`).join("");
}
document.querySelectorAll("[data-do]").forEach((b) => b.addEventListener("click", () => send({ do: b.dataset.do })));
$("jog").addEventListener("click", () => send({ do: "jog", axis: +$("jog-axis").value, distance: +$("jog-distance").value }));
$("buzz").addEventListener("click", () => send({ do: "buzz", axis: +$("jog-axis").value }));
// The spare axes: shown while one is fitted, their positions from the device's counted steps.
function showSpare(m) {
  const fitted = [7, 8].filter((_, i) => m.fitted[i]);
  $("spare-card").hidden = fitted.length === 0;
  const select = $("spare-axis");
  if (select.options.length !== fitted.length) select.innerHTML = fitted.map((a) => `<option>${a}</option>`).join("");
  $("spare-positions").textContent = fitted.map((a) => `axis ${a}: ${m.position[a - 7].toFixed(4)} (${m.steps[a - 7]} steps)`).join(", ");
}
$("spare-jog").addEventListener("click", () => send({ do: "spare_jog", axis: +$("spare-axis").value, distance: +$("spare-amount").value }));
$("spare-to").addEventListener("click", () => send({ do: "spare_to", axis: +$("spare-axis").value, value: +$("spare-amount").value }));
$("run-motion").addEventListener("click", () => send({
  do: "motion", motion: $("motion").value, seconds: +$("motion-seconds").value, rate_hz: +$("motion-rate").value,
}));
// A picked file goes as its text (the workbench reads no path the page gives, but under `ui --files DIR`).
$("stream-file").addEventListener("click", async () => {
  const degrees = $("file-degrees").checked, picked = $("file-pick").files[0];
  if (picked) send({ do: "file", name: picked.name, text: await picked.text(), degrees });
  else send({ do: "file", name: $("file-name").value, degrees });
});
// A session's card shows the settings of what it holds only (a pose format for front-end strings, a format and
// OutSim Opts for telemetry): the card stays short enough for a 1366x768 screen.
function showHolds() {
  document.querySelectorAll("[data-holds]").forEach((l) => { l.hidden = l.dataset.holds !== $("udp-holds").value; });
}
$("udp-holds").addEventListener("change", showHolds);
showHolds();
$("run-udp").addEventListener("click", () => {
  const holds = $("udp-holds").value;
  const format = holds === "strings" ? $("udp-template").value : $("udp-format").value;
  const request = { do: "udp", port: +$("udp-port").value, holds, format, idle: +$("udp-idle").value };
  if ($("udp-from").value.trim()) request.from = $("udp-from").value.trim();
  if ($("udp-outsim-opts").value.trim()) request.outsim_opts = $("udp-outsim-opts").value.trim();
  if (holds === "telemetry") request.lap_preview = $("udp-lap-preview").checked;
  startSession(request);
});
$("park").addEventListener("click", () => send({ do: "park" }));
$("start-help").textContent = "Start lets the device follow setpoints: it waits for a stream (Run motion, Stream file, Start session), which starts by itself.";

// ---- the API ----
async function post(path, body) {
  return answered(await fetch(api(path), { method: "POST", headers: { "content-type": "application/json" }, body: JSON.stringify(body) }));
}

// A response's JSON, or an error in the words the server gave: its JSON's `error`, else its text or the status's
// name with the status (a proxy's or the server's own refusal in front of the workbench's).
async function answered(r) {
  const text = await r.text();
  let j = null;
  try { j = JSON.parse(text); } catch (_) { j = null; }
  if (r.ok && j) return j;
  if (j && j.error) throw new Error(j.error);
  throw new Error(`${text.trim() || r.statusText || "no reason given"} (HTTP ${r.status})`);
}

function escapeHtml(s) {
  return String(s).replace(/[&<>"]/g, (c) => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;" }[c]));
}

// ---- Runs ----
// The file goes as its bytes (never held as text here) and comes back drawn at a few thousand points: a record of
// a whole evening opens. The most the server reads (its `ui::runs::MOST_BYTES`), said before sending.
const RUN_MOST_BYTES = 1073741824;
$("run-file").addEventListener("change", async (e) => {
  const file = e.target.files[0];
  if (!file) return;
  const status = $("run-status");
  try {
    if (file.size > RUN_MOST_BYTES) throw new Error(`${(file.size / 1048576).toFixed(0)} MiB: the Runs panel reads at most ${RUN_MOST_BYTES / 1048576} MiB; plot a part of it with \`ringpod plot\``);
    status.className = "small"; status.textContent = `${file.name}: reading ${(file.size / 1048576).toFixed(1)} MiB…`;
    const r = await fetch(api("/api/run"), { method: "POST", headers: { "content-type": "text/csv" }, body: file });
    showRun(await answered(r), file.name);
  } catch (err) {
    status.className = "small msg bad"; status.textContent = `${file.name}: ${err.message}`;
    $("run-charts").innerHTML = "";
  }
});

function showRun(run, name) {
  const events = run.changes.map((c) => ({ x: c.t, colour: "#9ca3af", label: c.state }));
  run.limited.forEach((l, i) => { if (l && (i === 0 || !run.limited[i - 1])) events.push({ x: run.t[i], colour: "#f59e0b" }); });
  run.refused.forEach((r, i) => { if (r && (i === 0 || !run.refused[i - 1])) events.push({ x: run.t[i], colour: "#dc2626" }); });
  state.run = { rows: run.rows, points: run.t.length };
  const drawn = run.rows_per_span > 1 ? `, drawn as ${run.t.length} points (the lowest and highest of each ${run.rows_per_span} rows)` : "";
  const more = run.more_changes ? `, ${run.more_changes} more state changes not marked` : "";
  $("run-status").className = "small";
  $("run-status").textContent = `${name}: ${run.rows} rows over ${(run.t[run.t.length - 1] - run.t[0]).toFixed(2)} s${drawn}; ` +
    `grey lines: state changes${more}, amber: limited, red: refused`;
  const charts = $("run-charts");
  charts.innerHTML = "";
  // The record keeps m and rad; the charts say mm and deg, as the Live view and the rig editor do.
  const NAMES = ["surge x", "sway y", "heave z", "roll", "pitch", "yaw"];
  AXES.forEach((a, i) => {
    const k = i < 3 ? 1000 : 180 / Math.PI, unit = i < 3 ? "mm" : "deg";
    new Chart(charts, `${NAMES[i]} (${unit})`, " " + unit).set([
      { x: run.t, y: run.commanded.map((p) => p[i] * k), colour: pale(COLOURS[i]), width: 4 },
      { x: run.t, y: run.target.map((p) => p[i] * k), colour: COLOURS[i] },
    ], events);
  });
  for (let k = 0; k < 6; k++) {
    new Chart(charts, `steps ${k + 1}`, "").set([{ x: run.t, y: run.steps.map((s) => s[k]), colour: COLOURS[k] }], events);
  }
}

connect();
