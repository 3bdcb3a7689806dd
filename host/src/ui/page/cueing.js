// The Cueing panel: the washout's parameters as controls for people (grouped by axis and by what they do, in the
// units people use, slider and number, default and meaning), the profiles of the workbench's cueing file (one per
// game), and the drive they are tried on: the live session while one runs, else the example drive replayed.
"use strict";

const cue = { config: null, saved: null, fields: [], drive: null, charts: [], timer: null, profile: "", profiles: null };

// What each key does, in a line (the key's first part; a corner's two numbers share their key's line).
const MEANING = {
  translation_scale: "how much of the game's force becomes motion (0.1: a tenth)",
  translation_limit: "the largest force passed on; more is clipped",
  translation_high_pass: "how soon a held push washes back to centre (higher: sooner)",
  translation_break: "a third corner that keeps a long push from drifting (0: off)",
  tilt_scale: "how much of a held force is given as a tilt of the seat",
  tilt_low_pass: "how soon the tilt follows the force (lower: smoother, later)",
  tilt_limit_deg: "the largest tilt used for a held force",
  tilt_rate_deg: "how fast the tilt may turn (slow enough not to be felt as turning)",
  rotation_scale: "how much of the game's rate the seat turns",
  rotation_limit: "the largest rate passed on",
  rotation_high_pass: "how soon a held rotation washes back to level",
  yaw: "heading: follow the car's heading; washout: only the turn-in",
  yaw_scale: "how much of the yaw rate the seat turns",
  yaw_rate_limit: "the largest yaw rate passed on",
  yaw_high_pass: "in washout mode, how soon a turn washes back",
  forward: "which platform direction faces the car's front",
  smoothing: "filtering of the game's telemetry before the washout",
  algorithm: "classical: filters (light); optimal: plans the next moments in the envelope (heavier)",
  optimal: "the optimal cueing's",
};
// What a key does, for its place in an axis's group.
const ROLE = {
  translation_scale: "strength", rotation_scale: "strength", yaw_scale: "strength",
  translation_high_pass: "washout", translation_break: "washout", rotation_high_pass: "washout",
  yaw_high_pass: "washout", yaw: "washout",
  tilt_scale: "tilt", tilt_low_pass: "tilt", tilt_limit_deg: "tilt", tilt_rate_deg: "tilt",
  translation_limit: "envelope", rotation_limit: "envelope", yaw_rate_limit: "envelope",
};
const ROLES = ["strength", "washout", "tilt", "envelope"];
const GROUPS = ["surge", "sway", "heave", "roll", "pitch", "yaw", "smoothing", "platform and algorithm", "optimal cueing"];

// The group a control is shown in: its axis (a tilt with the force it cues: x pitches for surge, y rolls for
// sway), smoothing, the rest, or the optimal cueing's own.
function groupOf(f) {
  const first = f.key.split(".")[0];
  if (first === "optimal") return "optimal cueing";
  if (first === "smoothing") return "smoothing";
  if (first.startsWith("tilt_")) return f.path[1] === 0 ? "surge" : "sway";
  if (GROUPS.includes(f.channel)) return f.channel;
  return "platform and algorithm";
}

// A value as shown and as stored: a filter corner in Hz (stored in rad/s), a rate in deg/s (rad/s), an angle in
// degrees (rad). Converted here, at the edge: the parameters stay as the cueing file writes them.
function unitOf(f) {
  const corner = f.key.endsWith(".omega") || f.key === "translation_break";
  if (f.unit === "rad/s" && corner) return { unit: "Hz", k: 1 / (2 * Math.PI) };
  if (f.unit === "rad/s") return { unit: "deg/s", k: 180 / Math.PI };
  if (f.unit === "rad") return { unit: "deg", k: 180 / Math.PI };
  return { unit: f.unit, k: 1 };
}
const round = (v) => +(+v).toPrecision(4);
const shownName = (f) => `${groupOf(f)}: ${f.label}`;

async function loadCueDefaults() {
  const j = await (await fetch(api("/api/cue/defaults"))).json();
  cue.defaults = j.config;
  cue.config = JSON.parse(JSON.stringify(j.config));
  cue.saved = JSON.stringify(cue.config);
  cue.fields = j.fields;
  buildCueControls();
  const charts = $("cue-charts");
  charts.innerHTML = "";
  cue.charts = ["surge (x)", "sway (y)", "heave (z)"].map((n) => new Chart(charts, `specific force ${n}, m/s²`, ""));
  await loadProfiles();
  recue();
}

// ---- the controls ----
function buildCueControls() {
  const parent = $("cue-controls");
  parent.innerHTML = "";
  const sets = new Map();
  const classical = cue.config.algorithm !== "optimal";
  const shown = cue.fields.filter((f) => {
    if (f.only_with && getPath(cue.config, f.only_with.path) !== f.only_with.value) return false;
    // Only the chosen algorithm's: the optimal cueing's values are neither shown nor checked with the classical.
    return !(classical && groupOf(f) === "optimal cueing");
  });
  const order = (f) => GROUPS.indexOf(groupOf(f)) * 10 + Math.max(0, ROLES.indexOf(ROLE[f.key.split(".")[0]]));
  shown.sort((a, b) => order(a) - order(b));
  for (const f of shown) {
    const g = groupOf(f);
    if (!sets.has(g)) {
      const fs = document.createElement("fieldset");
      fs.dataset.group = g;
      fs.innerHTML = `<legend>${g}</legend>`;
      parent.appendChild(fs);
      sets.set(g, fs);
    }
    const role = ROLE[f.key.split(".")[0]];
    const fs = sets.get(g);
    if (role && fs.dataset.role !== role) {
      fs.dataset.role = role;
      const h = document.createElement("div");
      h.className = "role";
      h.textContent = role;
      fs.appendChild(h);
    }
    fs.appendChild(cueControl(f));
  }
}

function cueControl(f) {
  const row = document.createElement("div");
  row.className = "cue-row";
  const value = getPath(cue.config, f.path);
  const first = f.key.split(".")[0];
  const meaning = f.key.endsWith(".zeta") ? "its damping: 1 settles without overshoot, lower overshoots, higher is slower"
    : MEANING[first] ? (first === "optimal" ? `${MEANING.optimal} ${f.label.replace("optimal: ", "")}` : MEANING[first]) : "";
  const name = document.createElement("label");
  name.className = "cue-name";
  name.textContent = f.label.replace(/^optimal: /, "");
  row.appendChild(name);
  let input;
  if (f.choices) {
    input = document.createElement("select");
    f.choices.forEach((c, i) => {
      const o = document.createElement("option");
      o.value = String(i); o.textContent = String(c); o.selected = c === value;
      input.appendChild(o);
    });
    input.addEventListener("change", () => cueChoose(f, f.choices[+input.value]));
    row.appendChild(input);
    const dflt = getPath(cue.defaults, f.path);
    if (dflt !== undefined) row.dataset.default = `default ${dflt}`;
  } else {
    const u = unitOf(f);
    const dflt = getPath(cue.defaults, f.path);
    input = document.createElement("input");
    input.type = "number"; input.step = "any";
    input.min = round(f.min * u.k); input.max = round(f.max * u.k); input.value = round(value * u.k);
    // The slider over the range people use: up to ten times the default where the check allows far more.
    const slider = document.createElement("input");
    slider.type = "range"; slider.className = "cue-slider";
    const top = dflt > 0 && f.max > dflt * 10 ? dflt * 10 : f.max;
    slider.min = round(f.min * u.k); slider.max = round(top * u.k); slider.step = "any"; slider.value = round(value * u.k);
    slider.tabIndex = -1;
    const take = (from) => {
      if (from === slider) input.value = slider.value; else slider.value = input.value;
      setPath(cue.config, f.path, parseFloat(input.value) / u.k);
      cue.edited = input;
      changed();
    };
    slider.addEventListener("input", () => take(slider));
    input.addEventListener("input", () => take(input));
    row.appendChild(slider);
    row.appendChild(input);
    const unit = document.createElement("span");
    unit.className = "unit";
    unit.textContent = u.unit;
    row.appendChild(unit);
    input.title = `${round(f.min * u.k)} to ${round(f.max * u.k)} ${u.unit}; default ${round(dflt * u.k)}`;
    input.dataset.shownMin = round(f.min * u.k); input.dataset.shownMax = round(f.max * u.k); input.dataset.unit = u.unit;
    row.dataset.default = `default ${round(dflt * u.k)} ${u.unit}`.trim();
  }
  input.dataset.path = f.path.join(".");
  input.dataset.name = shownName(f);
  input.id = "cue-" + f.path.join("-");
  name.htmlFor = input.id;
  const m = document.createElement("div");
  m.className = "meaning";
  m.textContent = [row.dataset.default, meaning].filter(Boolean).join(" · ");
  row.appendChild(m);
  return row;
}

// An edit: checked here against the ranges shown (an invalid value is named as it is on screen), then tried.
function changed() {
  $("cue-dirty").textContent = JSON.stringify(cue.config) === cue.saved ? "" : "changed, not saved";
  clearTimeout(cue.timer);
  cue.timer = setTimeout(() => { if (checkShown()) recue(); }, 200);
}

function checkShown() {
  for (const i of document.querySelectorAll("#cue-controls input[type=number]")) {
    const v = parseFloat(i.value), lo = +i.dataset.shownMin, hi = +i.dataset.shownMax;
    i.classList.toggle("bad", !(isFinite(v) && v >= lo && v <= hi));
    if (i.classList.contains("bad")) {
      cueStatus(`${i.dataset.name} must be ${lo} to ${hi}${i.dataset.unit ? " " + i.dataset.unit : ""}, not ${i.value || "empty"}`, true);
      return false;
    }
  }
  return true;
}

function cueStatus(text, bad) {
  const s = $("cue-status");
  s.className = bad ? "small msg bad" : "small";
  s.textContent = text;
}

// The core's error names a key (and an axis): said as the control is named on screen.
function named(message) {
  for (const f of cue.fields) {
    const at = f.axis ? `${f.key} (${f.axis})` : f.key;
    if (message.includes(at)) return { text: message.replace(at, shownName(f)), path: f.path.join(".") };
  }
  return { text: message };
}

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
  changed();
}

function getPath(obj, path) {
  return path.reduce((o, k) => (o === undefined || o === null ? undefined : o[k]), obj);
}

function setPath(obj, path, v) {
  let o = obj;
  for (const k of path.slice(0, -1)) o = o[k];
  o[path[path.length - 1]] = v;
}

// The parameters tried: on the live session while this page's telemetry session runs (applied, and the live
// charts show the next seconds), else on the drive replayed.
async function recue() {
  if (liveSession()) { await applyLive(); return; }
  try {
    const j = await post("/api/cue", { config: cue.config, drive: cue.drive, compare: $("cue-compare").checked });
    // What the rider perceives, scored as the bench scores it, for this cueing and (compared) the other one.
    const scored = (s) => `${s.algorithm}: perceived force error ${s.force_rms.toFixed(2)} m/s² RMS, ${s.false_cues} false cues, ${s.limited} limited` + (s.fallbacks == null ? "" : `, ${s.fallbacks} fallbacks`);
    cueStatus(`${j.t.length} samples cued. ${scored(j.score)}` + (j.other ? `. ${scored(j.other.score)} (grey)` : "") + (j.errors.length ? `; ${j.errors.length} rows unusable` : ""));
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
    document.querySelectorAll("#cue-controls .bad").forEach((i) => i.classList.remove("bad"));
  } catch (e) {
    refusedHere(e);
    // The plots were of other parameters: not shown as if they were of these.
    cue.charts.forEach((c) => c.set([]));
  }
}

function refusedHere(e) {
  const n = named(e.message);
  cueStatus(n.text, true);
  // The value refused is marked where the eye is: the control the error names, else the one just typed.
  const el = (n.path && document.querySelector(`#cue-controls [data-path="${n.path}"]`)) || cue.edited;
  if (el) el.classList.add("bad");
}

async function applyLive() {
  try {
    const j = await post("/api/cue/apply", { config: cue.config });
    state.cueApplied = (state.cueApplied || 0) + 1;
    cueStatus(`applied live: the running session blends them in over a second (${j.applied})`);
    document.querySelectorAll("#cue-controls .bad").forEach((i) => i.classList.remove("bad"));
  } catch (e) { refusedHere(e); }
}

// ---- profiles: the cueing file's [profiles.NAME], one per game ----
async function loadProfiles() {
  try {
    cue.profiles = await answered(await fetch(api("/api/profiles")));
  } catch (e) { cueStatus(e.message, true); return; }
  const sel = $("profile");
  sel.innerHTML = `<option value="">the file's base</option>` +
    cue.profiles.names.map((n) => `<option value="${escapeHtml(n)}">${escapeHtml(n)}</option>`).join("");
  sel.value = cue.profile;
  $("profile-file").textContent = cue.profiles.kept
    ? `in ${cue.profiles.file} (stream --cue-config it --profile NAME reads them)`
    : "kept until the workbench ends: start it with --cue-config FILE to keep them";
  $("profile-save").disabled = !cue.profile;
  $("profile-save").title = cue.profile ? `saves profile ${cue.profile}` : "the base is not saved here: duplicate it as a profile";
  fillGames();
}

async function chooseProfile(name) {
  try {
    const j = await answered(await fetch(api("/api/profile") + (name ? `&name=${encodeURIComponent(name)}` : "")));
    cue.profile = name;
    cue.config = j.config;
    cue.saved = JSON.stringify(j.config);
    $("profile").value = name;
    $("profile-save").disabled = !name;
    $("cue-dirty").textContent = "";
    buildCueControls();
    recue();
  } catch (e) { cueStatus(e.message, true); }
}

async function saveProfile(name, isNew) {
  if (!checkShown()) return false;
  try {
    await post("/api/profile", { name, config: cue.config, new: isNew });
    cue.profile = name;
    cue.saved = JSON.stringify(cue.config);
    $("cue-dirty").textContent = "";
    await loadProfiles();
    cueStatus(`saved as profile ${name}`);
    state.profileSaved = name;
    return true;
  } catch (e) { refusedHere(e); return false; }
}

$("profile").addEventListener("change", (e) => chooseProfile(e.target.value));
$("profile-save").addEventListener("click", () => saveProfile(cue.profile, false));
$("profile-duplicate").addEventListener("click", async () => {
  const name = $("profile-new").value.trim();
  if (await saveProfile(name, true)) $("profile-new").value = "";
});
$("cue-revert").addEventListener("click", () => chooseProfile(cue.profile));
$("cue-apply").addEventListener("click", () => { if (checkShown()) applyLive(); });
$("cue-save").addEventListener("click", () => {
  if (!cue.toml) return;
  const a = document.createElement("a");
  a.href = URL.createObjectURL(new Blob([cue.toml], { type: "application/toml" }));
  a.download = `${cue.profile || "cueing"}.toml`;
  a.click();
});
$("cue-compare").addEventListener("change", () => recue());
$("cue-drive").addEventListener("change", async (e) => {
  const file = e.target.files[0];
  if (file) { cue.drive = await file.text(); recue(); }
});

// ---- games: a session's game picks its format, port and profile ----
function fillGames() {
  const sel = $("udp-game");
  if (sel.options.length || !cue.profiles) return;
  cue.profiles.games.forEach((g, i) => {
    const o = document.createElement("option");
    o.value = i;
    o.textContent = g.port ? `${g.name} (port ${g.port})` : g.name;
    sel.appendChild(o);
  });
  sel.value = cue.profiles.games.length - 1;
  showGame();
}

function showGame() {
  const g = cue.profiles && cue.profiles.games[+$("udp-game").value];
  if (!g) return;
  $("udp-holds").value = "telemetry";
  showHolds();
  $("udp-format").value = g.format;
  if (g.port) $("udp-port").value = g.port;
  const has = cue.profiles.names.includes(g.profile);
  $("udp-game-help").textContent = `In the game: ${g.set}.` + (g.profile ? ` Cued with profile ${g.profile}${has ? "" : " (not saved yet: the Cueing panel's parameters)"}.` : "");
}
$("udp-game").addEventListener("change", showGame);

// A telemetry session takes its game's profile: loaded into the Cueing panel and applied before it starts.
async function startSession(request) {
  const g = cue.profiles && cue.profiles.games[+$("udp-game").value];
  const telemetry = request.holds === "telemetry";
  if (telemetry) {
    if (!cue.config) await loadCueDefaults();
    if (g && g.profile && cue.profiles.names.includes(g.profile) && cue.profile !== g.profile) await chooseProfile(g.profile);
    try { await post("/api/cue/apply", { config: cue.config }); } catch (e) { log(`cueing: ${e.message}`, true); return; }
  }
  const id = send(request);
  if (id && telemetry) {
    state.session = { id, game: g ? g.name : request.format, port: request.port, profile: cue.profile };
    showSession();
  }
}

function liveSession() {
  return !!(state.session && state.frame && state.frame.streaming);
}

function showSession() {
  const s = state.session;
  $("live-session").textContent = s
    ? `Session: ${s.game}, port ${s.port}, cued with ${s.profile ? `profile ${s.profile}` : "the file's base"}`
    : "";
  placeLiveCharts();
}

// While a session runs, the Cueing panel shows the live charts (the next seconds of the session as parameters
// change), not a replayed drive; otherwise they are on the Live panel.
function placeLiveCharts() {
  const tuning = document.querySelector("#panel-cueing.active") && liveSession();
  const charts = $("live-charts");
  const home = tuning ? $("cue-live") : $("live-home");
  if (charts.parentElement !== home) home.appendChild(charts);
  $("cue-charts").hidden = !!tuning;
  $("cue-live-note").hidden = !tuning;
  $("cue-heading").hidden = !!tuning;
}

// The games and profiles from the start: the Control panel's game list needs them.
loadProfiles();
