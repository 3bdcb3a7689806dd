// The Rig panel: the rig file as a form (lengths in mm, angles in deg; the file keeps its own units, each field
// converts by its `scale`), drawn and checked by the server as it is typed (the code of `ringpod rig check`), saved
// to the file the workbench was started with, or downloaded as TOML; the file as TOML under the form.
"use strict";

const rig = { file: null, fields: [], toml: null, target: null, timer: null, asked: 0 };
state.rigEditor = rig;

async function loadDeviceRig() {
  let j;
  try { j = await answered(await fetch(api("/api/rig/current"))); }
  catch (e) { rigStatus(e.message, true); return; }
  rig.target = j.file;
  const save = $("rig-save");
  save.disabled = !j.file;
  save.title = j.file ? `writes ${j.file} whole (its mode kept; comments not kept)` :
    "the workbench was started without a rig file (ringpod ui --sim --geometry FILE): download the TOML instead";
  $("rig-file").textContent = j.file ? `rig file: ${j.file}` : "the device's rig (no rig file given: Save is off)";
  $("rig-text").value = j.text;
  checkRig({ text: j.text }, true);
}
$("rig-reset").addEventListener("click", loadDeviceRig);
$("rig-load").addEventListener("click", () => send({ do: "load_rig", text: rig.toml || $("rig-text").value }));
$("rig-text").addEventListener("input", () => {
  clearTimeout(rig.timer);
  rig.timer = setTimeout(() => checkRig({ text: $("rig-text").value }, true), 300);
});

function rigStatus(text, bad) {
  const s = $("rig-status");
  s.className = bad ? "small msg bad" : "small";
  s.textContent = text;
}

// ---- the form ----
const shownNumber = (v) => (typeof v === "number" ? +v.toPrecision(6) : v);
function valueAt(path) {
  return path.split(/[.[\]]/).filter((k) => k !== "").reduce((v, k) => (v == null ? v : v[k]), rig.file);
}
function setAt(path, value) {
  const keys = path.split(/[.[\]]/).filter((k) => k !== "");
  const last = keys.pop();
  keys.reduce((v, k) => v[k], rig.file)[last] = value;
}
const fieldName = (f) => `${f.group} · ${f.label}${f.part ? " " + f.part : ""}${f.unit ? ` (${f.unit})` : ""}`;
const inputId = (path) => "rig-f-" + path.replace(/[^a-z0-9]+/gi, "-");

// The groups shown open; the rest (axes, motion, inputs, supervisor) folded under one heading each.
const OPEN = (group) => /^(Rig|Geometry|Home pose|Chain \d+|Limits|Spec ranges)/.test(group);

function buildForm() {
  const form = $("rig-form");
  const open = {};
  form.querySelectorAll("details[data-group]").forEach((d) => { open[d.dataset.group] = d.open; });
  form.innerHTML = "";
  const groups = new Map();
  for (const f of rig.fields) {
    if (!groups.has(f.group)) groups.set(f.group, []);
    groups.get(f.group).push(f);
  }
  for (const [group, fields] of groups) {
    const box = document.createElement(OPEN(group) ? "fieldset" : "details");
    if (box.tagName === "DETAILS") {
      box.dataset.group = group;
      box.open = !!open[group];
      box.innerHTML = `<summary>${escapeHtml(group)}</summary>`;
    } else box.innerHTML = `<legend>${escapeHtml(group)}</legend>`;
    // The parts of one value (x, y, z; min, max) on one line.
    const rows = new Map();
    for (const f of fields) {
      const key = f.label + "|" + f.unit;
      if (!rows.has(key)) rows.set(key, []);
      rows.get(key).push(f);
    }
    for (const parts of rows.values()) box.appendChild(rowOf(parts));
    form.appendChild(box);
  }
}

function rowOf(parts) {
  const row = document.createElement("div");
  row.className = "rig-row";
  const f0 = parts[0];
  const label = document.createElement("span");
  label.className = "rig-label";
  label.textContent = f0.label;
  row.appendChild(label);
  const inputs = document.createElement("span");
  inputs.className = "rig-inputs";
  for (const f of parts) inputs.appendChild(inputOf(f));
  row.appendChild(inputs);
  const unit = document.createElement("span");
  unit.className = "unit";
  unit.textContent = f0.unit;
  row.appendChild(unit);
  const range = parts.find((f) => f.range);
  if (range) row.title = `${fieldName(range)}: ${rangeText(range)}`;
  return row;
}

function rangeText(f) {
  const r = f.range, u = f.kind === "text" ? " characters" : f.unit ? " " + f.unit : "";
  if (r.max == null) return r.above ? `more than ${r.min}${u}` : `${r.min}${u} or more`;
  return `${r.min} to ${r.max}${u}` + (r.below ? `, ${r.max} itself excluded` : "");
}

function inputOf(f) {
  const v = valueAt(f.path);
  let el;
  if (f.kind === "choice") {
    el = document.createElement("select");
    el.innerHTML = f.choices.map((c) => `<option${c === v ? " selected" : ""}>${c}</option>`).join("");
  } else if (f.kind === "bool") {
    el = document.createElement("input");
    el.type = "checkbox";
    el.checked = !!v;
  } else {
    el = document.createElement("input");
    el.type = f.kind === "text" ? "text" : "number";
    if (f.kind !== "text") el.step = "any";
    el.value = f.kind === "text" ? v : shownNumber(v * f.scale);
  }
  el.id = inputId(f.path);
  el.dataset.path = f.path;
  el.setAttribute("aria-label", fieldName(f));
  el.title = fieldName(f);
  if (f.part) {
    const wrap = document.createElement("label");
    wrap.className = "rig-part";
    wrap.append(f.part + " ", el);
    el.addEventListener(el.tagName === "SELECT" || el.type === "checkbox" ? "change" : "input", () => edited(f, el));
    return wrap;
  }
  el.addEventListener(el.tagName === "SELECT" || el.type === "checkbox" ? "change" : "input", () => edited(f, el));
  return el;
}

// A chain's keys follow its kind: a rod chain has a branch, an elbow chain its arm (a start the user then sizes).
function kindChanged(path, kind) {
  const chain = valueAt(path.replace(/\.kind$/, ""));
  for (const k of ["branch", "shoulder_radius", "shoulder_height", "upper_arm", "forearm", "elbow"]) delete chain[k];
  if (kind === "rod") chain.branch = "plus";
  if (kind === "elbow") {
    Object.assign(chain, { shoulder_radius: 0.9 * rig.file.ring_radius, shoulder_height: 0.02, upper_arm: 0.1,
      forearm: 0.19, elbow: "up" });
  }
  // The limits only some kinds have follow too (`rig check` refuses a stroke without radial chains): a start
  // from the export's presets where one is needed, gone where none is.
  const has = (k) => rig.file.chains.some((c) => c.kind === k), limits = rig.file.limits;
  if (!has("radial")) delete limits.stroke;
  else if (!limits.stroke) limits.stroke = [0.16, 0.31];
  if (!has("elbow")) { delete limits.shoulder_angle_deg; delete limits.elbow_angle_deg; }
  else if (!limits.shoulder_angle_deg) limits.shoulder_angle_deg = [100, 190];
}

function edited(f, el) {
  let value;
  if (f.kind === "bool") value = el.checked;
  else if (f.kind === "text" || f.kind === "choice") value = el.value;
  else {
    // An empty or unreadable number goes as null: the server names the field.
    const n = parseFloat(el.value);
    value = isFinite(n) ? (f.kind === "integer" ? n : n / f.scale) : null;
  }
  setAt(f.path, value);
  if (f.path.endsWith(".kind")) kindChanged(f.path, value);
  clearTimeout(rig.timer);
  rig.timer = setTimeout(() => checkRig({ rig: rig.file }, f.path.endsWith(".kind")), 200);
}

// ---- checking and drawing ----
async function checkRig(body, rebuild) {
  const asked = ++rig.asked;
  let j;
  try { j = await post("/api/rig/check", body); }
  catch (e) { $("rig-messages").innerHTML = `<div class="msg bad">${escapeHtml(e.message)}</div>`; return; }
  if (asked !== rig.asked) return;  // an older answer than the one on its way
  if (j.file) {
    const paths = (fields) => fields.map((f) => f.path).join();
    const changed = rebuild || paths(j.fields) !== paths(rig.fields);
    rig.file = j.file; rig.fields = j.fields;
    if (changed) buildForm();
  }
  document.querySelectorAll("#rig-form .bad").forEach((i) => i.classList.remove("bad"));
  const m = [];
  for (const e of j.errors) {
    // A key the server could not name (a value of the wrong type) is named by the form's own field.
    const f = rig.fields.find((g) => g.path === e.key);
    const name = e.field !== e.key || !f ? e.field : fieldName(f);
    m.push(`<div class="msg bad rig-error"><b>${escapeHtml(name)}</b>: ${escapeHtml(e.why)}</div>`);
    const input = $(inputId(e.key));
    if (input) input.classList.add("bad");
  }
  if (j.analysable) {
    m.push(`<div class="msg ok">a mechanism: yes</div>`);
    m.push(j.drivable ? `<div class="msg ok">drivable: yes</div>` : `<div class="msg warn">drivable: no, because ${escapeHtml(j.why)}</div>`);
  }
  $("rig-messages").innerHTML = m.join("");
  rig.toml = j.analysable ? j.toml : null;
  rig.drivable = !!j.drivable;
  // Save writes only a rig `rig check` calls drivable (the server checks again): said on the button until then.
  if (rig.target) {
    $("rig-save").disabled = !rig.drivable;
    $("rig-save").title = rig.drivable ? `writes ${rig.target} whole (its mode kept; comments not kept)` :
      "only a drivable rig is saved: mend what the checks name first";
  }
  $("rig-download").disabled = !rig.toml;
  $("rig-download").title = rig.toml ? "the form's values as a rig file (m and rad, as rig files are)" : "the file has an error (named above)";
  if (rig.toml && document.activeElement !== $("rig-text")) $("rig-text").value = rig.toml;
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
    : `<tr><td class="muted">no spec ranges in the file</td></tr>`;
}

$("rig-save").addEventListener("click", async () => {
  try {
    const j = await post("/api/rig/save", { rig: rig.file });
    rigStatus(`saved to ${j.saved}`, false);
  } catch (e) { rigStatus(e.message, true); }
});
$("rig-download").addEventListener("click", () => {
  if (!rig.toml) return;
  const a = document.createElement("a");
  a.href = URL.createObjectURL(new Blob([rig.toml], { type: "application/toml" }));
  a.download = `${(rig.file && rig.file.name) || "rig"}.toml`;
  a.click();
  setTimeout(() => URL.revokeObjectURL(a.href), 1000);
});

// ---- the workspace map: xy at the home height, mm on both axes ----
const CHECK_COLOURS = ["#f97316", "#a855f7", "#ec4899", "#eab308", "#ef4444", "#14b8a6"];
function niceStep(span) {
  const raw = span / 5, p = 10 ** Math.floor(Math.log10(raw)), k = raw / p;
  return (k < 1.5 ? 1 : k < 3.5 ? 2 : k < 7.5 ? 5 : 10) * p;
}
function drawSection(s) {
  const c = $("rig-section"), dpr = window.devicePixelRatio || 1;
  const css = c.clientWidth || 360;
  c.width = Math.round(css * dpr); c.height = Math.round(css * dpr);
  const g = c.getContext("2d");
  g.setTransform(dpr, 0, 0, dpr, 0, 0);
  g.clearRect(0, 0, css, css);
  const left = 52, bottom = 40, top = 8, right = 10, size = Math.min(css - left - right, css - top - bottom);
  const n = s.rows.length, w = size / n, half = s.half_width * 1000;
  const X = (mm) => left + (mm + half) / (2 * half) * size, Y = (mm) => top + size - (mm + half) / (2 * half) * size;
  s.rows.forEach((row, j) => [...row].forEach((ch, i) => {
    g.fillStyle = ch === "#" ? "#16a34a" : ch === "." ? "#e5e7eb" : CHECK_COLOURS[+ch - 1];
    g.fillRect(left + i * w, top + size - (j + 1) * w, w + 0.5, w + 0.5);
  }));
  // The ring, and the axes with their scales.
  g.strokeStyle = "#1d2330"; g.lineWidth = 1;
  g.beginPath(); g.arc(X(0), Y(0), size / 2, 0, 2 * Math.PI); g.stroke();
  g.strokeRect(left, top, size, size);
  g.fillStyle = "#1d2330"; g.font = "12px system-ui, sans-serif";
  const step = niceStep(2 * half);
  for (let v = Math.ceil(-half / step) * step; v <= half + 1e-9; v += step) {
    g.beginPath(); g.moveTo(X(v), top + size); g.lineTo(X(v), top + size + 4); g.stroke();
    g.beginPath(); g.moveTo(left - 4, Y(v)); g.lineTo(left, Y(v)); g.stroke();
    g.textAlign = "center"; g.textBaseline = "top"; g.fillText(String(Math.round(v)), X(v), top + size + 6);
    g.textAlign = "right"; g.textBaseline = "middle"; g.fillText(String(Math.round(v)), left - 6, Y(v));
  }
  g.textAlign = "center"; g.textBaseline = "bottom";
  g.fillText("x (mm)", left + size / 2, css - 2);
  g.save(); g.translate(12, top + size / 2); g.rotate(-Math.PI / 2); g.textBaseline = "middle";
  g.fillText("y (mm)", 0, 0); g.restore();
  const seen = new Set(s.rows.join(""));
  const item = (colour, text) => `<li><span class="swatch" style="background:${colour}"></span>${escapeHtml(text)}</li>`;
  $("rig-legend").innerHTML = `<p>Where the platform's centre can be at z = ${(s.z * 1000).toFixed(0)} mm, level; the circle is the ring (radius ${half.toFixed(0)} mm).</p><ul>` +
    item("#16a34a", "reachable: inside every check") + item("#e5e7eb", "no solution: the links cannot get there") +
    s.meanings.map((t, i) => (seen.has(String(i + 1)) ? item(CHECK_COLOURS[i], t) : "")).join("") + "</ul>";
}
