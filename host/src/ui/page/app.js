// The workbench page: one WebSocket for the live data and every command, the panels, and the computations
// (cueing, rig checks, run records) over the token-checked API.
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
  if (b.dataset.panel === "rig" && !$("rig-text").value) loadDeviceRig();
  if (b.dataset.panel === "cueing" && !cue.config) loadCueDefaults();
}));

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
    if (m.type === "hello") state.page = m.page;
    else if (m.type === "rig") showRig(m);
    else if (m.type === "frame") showFrame(m);
    else if (m.type === "reply") showReply(m);
    else if (m.type === "halted") { state.halted = m; log(m.text); }
    else if (m.type === "stop_pending") showStopPending(m);
    else if (m.type === "notice") showNotice(m);
    else if (m.type === "report") log(`report: ${m.outcome}, ${m.setpoints_applied}/${m.setpoints_sent} applied, limited ${m.limited.host} on the host and ${m.limited.device} on the device`, m.exit_code !== 0 && m.exit_code !== 130);
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
const history = { t: [], pose: [], target: [], cost: [] };
const liveCharts = [];

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
  axis.onchange = () => { $("jog-unit").textContent = rig.axes[axis.value - 1] === "linear" ? "mm" : "deg"; };
  axis.onchange();
  const charts = $("live-charts");
  charts.innerHTML = "";
  liveCharts.length = 0;
  AXES.forEach((a, i) => liveCharts.push(new Chart(charts, a, i < 3 ? " m" : " rad")));
  liveCharts.push(new Chart(charts, "tick cost", ""));
  view.show(rig, null, null);
}

function lamp(on, label, alarm) {
  return `<span class="lamp ${on ? (alarm ? "alarm" : "on") : ""}">${label}</span>`;
}

// A pose value as the table shows it: mm for a position, degrees for an angle.
const show = (v, i) => (i < 3 ? v * 1000 : v * 180 / Math.PI).toFixed(2);

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
  const rows = [["applied", f.applied], ["limited", f.limited], ["refused", f.refused], ["tick cost", f.tick_cost],
    ["device time", f.t.toFixed(2) + " s"], ["streaming", f.streaming ? "yes" : "no"]];
  $("counters").innerHTML = rows.map(([k, v]) => `<tr><td>${k}</td><td id="count-${k.replace(" ", "-")}">${v}</td></tr>`).join("");
  $("pose").innerHTML = `<tr><th>axis</th><th>followed</th><th>commanded</th></tr>` +
    AXES.map((a, i) => `<tr><td>${a} (${i < 3 ? "mm" : "deg"})</td><td>${show(f.pose[i], i)}</td><td class="muted">${show(f.target[i], i)}</td></tr>`).join("");
  // The rolling history.
  history.t.push(f.t); history.pose.push(f.pose); history.target.push(f.target); history.cost.push(f.tick_cost);
  while (history.t.length && history.t[0] < f.t - HISTORY_S) {
    history.t.shift(); history.pose.shift(); history.target.shift(); history.cost.shift();
  }
  if (document.querySelector("#panel-live.active") && state.frames % 5 === 0) {
    liveCharts.forEach((c, i) => {
      if (i < 6) {
        c.set([
          { x: history.t, y: history.target.map((p) => p[i]), colour: pale(COLOURS[i]), width: 4 },
          { x: history.t, y: history.pose.map((p) => p[i]), colour: COLOURS[i] },
        ]);
      } else {
        c.set([{ x: history.t, y: history.cost, colour: "#374151" }]);
      }
    });
  }
  showGates(f.gates);
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
  send(request);
});
$("park").addEventListener("click", () => send({ do: "park" }));
$("start-help").textContent = "Start lets the device follow setpoints: it waits for a stream (Run motion, Stream file, Start session), which starts by itself.";

// ---- Cueing ----
const cue = { config: null, fields: [], drive: null, charts: [], timer: null };

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

async function loadCueDefaults() {
  const r = await fetch(api("/api/cue/defaults"));
  const j = await r.json();
  cue.config = j.config;
  cue.fields = j.fields;
  buildCueControls();
  const charts = $("cue-charts");
  charts.innerHTML = "";
  cue.charts = ["surge (x)", "sway (y)", "heave (z)"].map((n) => new Chart(charts, n, " m/s²"));
  recue();
}

// The controls, from the server's list of them (the core's parameter list, each per-axis key spread over its
// axes): a fieldset per channel in the list's order, each value labelled with its unit and range, a select where
// it takes one of a few values. A value read only with a choice of another (a median's window) shows with it.
function buildCueControls() {
  const parent = $("cue-controls");
  parent.innerHTML = "";
  const groups = new Map();
  for (const f of cue.fields) {
    if (f.only_with && getPath(cue.config, f.only_with.path) !== f.only_with.value) continue;
    if (!groups.has(f.channel)) {
      const fs = document.createElement("fieldset");
      const lg = document.createElement("legend");
      lg.textContent = f.channel;
      fs.appendChild(lg);
      parent.appendChild(fs);
      groups.set(f.channel, fs);
    }
    groups.get(f.channel).appendChild(cueControl(f));
  }
}

function cueControl(f) {
  const label = document.createElement("label");
  const name = document.createElement("span");
  name.textContent = f.label;
  label.appendChild(name);
  const value = getPath(cue.config, f.path);
  let input;
  if (f.choices) {
    input = document.createElement("select");
    f.choices.forEach((c, i) => {
      const o = document.createElement("option");
      o.value = String(i); o.textContent = String(c); o.selected = c === value;
      input.appendChild(o);
    });
    input.addEventListener("change", () => cueChoose(f, f.choices[+input.value]));
  } else {
    input = document.createElement("input");
    input.type = "number"; input.step = "any"; input.min = f.min; input.max = f.max; input.value = value;
    input.title = `${f.min} to ${f.max}${f.unit ? " " + f.unit : ""}`;
    input.addEventListener("input", () => {
      setPath(cue.config, f.path, parseFloat(input.value));
      cue.edited = input;
      clearTimeout(cue.timer);
      cue.timer = setTimeout(recue, 200);
    });
  }
  input.dataset.path = f.path.join(".");
  const unit = document.createElement("span");
  unit.className = "unit";
  unit.textContent = f.unit;
  const box = document.createElement("span");
  box.appendChild(input); box.appendChild(unit);
  label.appendChild(box);
  return label;
}

// A choice: the values read only with another choice of it go, the ones read with this one come with their
// starting value, and the controls follow.
function cueChoose(f, v) {
  setPath(cue.config, f.path, v);
  const key = f.path.join(".");
  for (const g of cue.fields) {
    if (!g.only_with || g.only_with.path.join(".") !== key) continue;
    const table = getPath(cue.config, g.path.slice(0, -1));
    const leaf = g.path[g.path.length - 1];
    if (g.only_with.value === v) { if (!(leaf in table)) table[leaf] = g.only_with.initial; }
    else delete table[leaf];
  }
  buildCueControls();
  clearTimeout(cue.timer);
  cue.timer = setTimeout(recue, 300);
}

function getPath(obj, path) {
  return path.reduce((o, k) => (o === undefined || o === null ? undefined : o[k]), obj);
}

function setPath(obj, path, v) {
  let o = obj;
  for (const k of path.slice(0, -1)) o = o[k];
  o[path[path.length - 1]] = v;
}

async function recue() {
  const status = $("cue-status");
  try {
    const j = await post("/api/cue", { config: cue.config, drive: cue.drive, compare: $("cue-compare").checked });
    // What the rider perceives, scored as the bench scores it, for this cueing and (compared) the other one.
    const scored = (s) => `${s.algorithm}: perceived force error ${s.force_rms.toFixed(2)} m/s² RMS, ${s.false_cues} false cues, ${s.limited} limited` + (s.fallbacks == null ? "" : `, ${s.fallbacks} fallbacks`);
    status.className = "small"; status.textContent = `${j.t.length} samples cued. ${scored(j.score)}` + (j.other ? `. ${scored(j.other.score)} (grey)` : "") + (j.errors.length ? `; ${j.errors.length} rows unusable` : "");
    $("cue-summary").textContent = cue.drive ? "(your drive)" : "(the example drive)";
    cue.toml = j.toml;
    // For tests and the curious: how many replays, and the largest surge delivered in the last.
    state.cueRuns = (state.cueRuns || 0) + 1;
    state.cuePeak = Math.max(...j.delivered.map((f) => Math.abs(f[0])));
    state.cueScores = [j.score, j.other && j.other.score];
    cue.charts.forEach((c, i) => c.set([
      { x: j.t, y: j.asked.map((f) => f[i]), colour: pale(COLOURS[i]), width: 4 },
      ...(j.other ? [{ x: j.t, y: j.other.delivered.map((f) => f[i]), colour: "#888888", width: 1 }] : []),
      { x: j.t, y: j.delivered.map((f) => f[i]), colour: COLOURS[i] },
    ]));
    document.querySelectorAll("#cue-controls input, #cue-controls select").forEach((i) => i.classList.remove("bad"));
  } catch (e) {
    status.className = "small msg bad"; status.textContent = e.message;
    // The value just typed is the one refused (the others were taken before it): marked where the eye is.
    if (cue.edited) cue.edited.classList.add("bad");
    // The plots were of other parameters: not shown as if they were of these.
    cue.charts.forEach((c) => c.set([]));
  }
}

$("cue-save").addEventListener("click", () => {
  if (!cue.toml) return;
  const a = document.createElement("a");
  a.href = URL.createObjectURL(new Blob([cue.toml], { type: "application/toml" }));
  a.download = "cueing.toml";
  a.click();
});
$("cue-apply").addEventListener("click", async () => {
  try {
    const j = await post("/api/cue/apply", { config: cue.config });
    $("cue-status").textContent = `applied: ${j.applied} (a running telemetry session blends them in)`;
  } catch (e) { $("cue-status").textContent = e.message; }
});
$("cue-compare").addEventListener("change", () => recue());
$("cue-drive").addEventListener("change", async (e) => {
  const file = e.target.files[0];
  if (file) { cue.drive = await file.text(); recue(); }
});

// ---- Rig ----
let rigTimer = null;
async function loadDeviceRig() {
  const r = await fetch(api("/api/rig/current"));
  const j = await r.json();
  if (j.text) { $("rig-text").value = j.text; checkRig(); }
}
$("rig-text").addEventListener("input", () => { clearTimeout(rigTimer); rigTimer = setTimeout(checkRig, 300); });
$("rig-reset").addEventListener("click", loadDeviceRig);
$("rig-load").addEventListener("click", () => send({ do: "load_rig", text: $("rig-text").value }));

async function checkRig() {
  let j;
  try { j = await post("/api/rig/check", { text: $("rig-text").value }); }
  catch (e) { $("rig-messages").innerHTML = `<div class="msg bad">${escapeHtml(e.message)}</div>`; return; }
  const m = [];
  for (const e of j.errors) m.push(`<div class="msg bad rig-error"><code>${escapeHtml(e.key || "file")}</code>: ${escapeHtml(e.why)}</div>`);
  if (j.analysable) m.push(`<div class="msg ok">analysable: yes</div>`);
  if (j.analysable) m.push(j.drivable ? `<div class="msg ok">drivable: yes</div>` : `<div class="msg warn">drivable: no, because ${escapeHtml(j.why)}</div>`);
  $("rig-messages").innerHTML = m.join("");
  if (!j.analysable) {
    // The drawings were of the last file that read: cleared, not left as if they were of this one.
    ["rig-view", "rig-section"].forEach((id) => $(id).getContext("2d").clearRect(0, 0, $(id).width, $(id).height));
    $("rig-legend").textContent = ""; $("rig-coverage").innerHTML = "";
    return;
  }
  const v = new View3d($("rig-view"));
  v.pitch = 0.35;
  v.show(j.rig, j.at_home, null);
  drawSection(j.section);
  const cov = j.coverage;
  $("rig-coverage").innerHTML = cov
    ? cov.per_axis.map((a) => `<tr><td>${a.axis}</td><td>${a.inside} of ${a.tried}</td></tr>`).join("") +
      `<tr><td>all at once</td><td>${cov.combined[0]} of ${cov.combined[1]}</td></tr>`
    : `<tr><td class="muted">no [spec] ranges in the file</td></tr>`;
}

const CHECK_COLOURS = ["#f97316", "#a855f7", "#ec4899", "#eab308", "#ef4444", "#14b8a6"];
function drawSection(s) {
  const c = $("rig-section"), g = c.getContext("2d");
  const n = s.rows.length, w = c.width / n;
  g.clearRect(0, 0, c.width, c.height);
  s.rows.forEach((row, j) => [...row].forEach((ch, i) => {
    g.fillStyle = ch === "#" ? "#16a34a" : ch === "." ? "#e5e7eb" : CHECK_COLOURS[+ch - 1];
    g.fillRect(i * w, c.height - (j + 1) * w, w + 0.5, w + 0.5);
  }));
  $("rig-legend").innerHTML = `xy at z = ${s.z.toFixed(3)} m over ±${s.half_width} m: <span style="color:#16a34a">■</span> inside every check, ` +
    `<span style="color:#9ca3af">■</span> no solution, ` +
    s.checks.map((n, i) => `<span style="color:${CHECK_COLOURS[i]}">■</span> ${n}`).join(", ");
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
  AXES.forEach((a, i) => new Chart(charts, a, i < 3 ? " m" : " rad").set([
    { x: run.t, y: run.commanded.map((p) => p[i]), colour: pale(COLOURS[i]), width: 4 },
    { x: run.t, y: run.target.map((p) => p[i]), colour: COLOURS[i] },
  ], events));
  for (let k = 0; k < 6; k++) {
    new Chart(charts, `steps ${k + 1}`, "").set([{ x: run.t, y: run.steps.map((s) => s[k]), colour: COLOURS[k] }], events);
  }
}

connect();
