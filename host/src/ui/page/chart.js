// Line charts on a canvas: time on x, one or more series on y, optional event lines, wheel zoom on x.
"use strict";

const COLOURS = ["#dc2626", "#2563eb", "#16a34a", "#9333ea", "#0891b2", "#ca8a04"];

// A paler shade of a "#rrggbb" colour (the commanded line under the followed one).
function pale(hex) {
  const n = parseInt(hex.slice(1), 16);
  const mix = (c) => Math.round(c / 2 + 128);
  return `rgb(${mix(n >> 16)},${mix((n >> 8) & 255)},${mix(n & 255)})`;
}

class Chart {
  // title: the caption above the plot (text of the page, readable and found by tests); unit: after the y labels.
  // The canvas is drawn at its CSS size times the screen's pixel ratio, never stretched.
  constructor(parent, title, unit) {
    this.figure = document.createElement("figure");
    this.figure.className = "chart";
    this.caption = document.createElement("figcaption");
    this.caption.textContent = title;
    this.canvas = document.createElement("canvas");
    this.canvas.title = title;
    this.figure.appendChild(this.caption);
    this.figure.appendChild(this.canvas);
    parent.appendChild(this.figure);
    this.title = title;
    this.unit = unit || "";
    this.rightUnit = "";
    this.minSpan = 0; // the least span of the y scale (left), and of the right one
    this.rightMinSpan = 0;
    this.series = [];
    this.events = [];
    this.view = null; // [x0, x1] when zoomed
    this.canvas.addEventListener("wheel", (e) => this.zoom(e), { passive: false });
    this.canvas.addEventListener("dblclick", () => { this.view = null; this.draw(); });
    // Shown, hidden or resized (a tab, the window): drawn again at the new size.
    if (window.ResizeObserver) new ResizeObserver(() => this.draw()).observe(this.canvas);
  }

  // series: [{x: [], y: [], colour, width}]; events: [{x, colour, label}]
  set(series, events) {
    this.series = series;
    this.events = events || [];
    this.draw();
  }

  extent() {
    let x0 = Infinity, x1 = -Infinity;
    for (const s of this.series) {
      if (s.x.length) { x0 = Math.min(x0, s.x[0]); x1 = Math.max(x1, s.x[s.x.length - 1]); }
    }
    return [x0, x1];
  }

  zoom(e) {
    e.preventDefault();
    const [a, b] = this.view || this.extent();
    if (!isFinite(a) || b <= a) return;
    const r = this.canvas.getBoundingClientRect();
    const f = Math.min(Math.max((e.clientX - r.left) / r.width, 0), 1);
    const at = a + f * (b - a);
    const k = e.deltaY < 0 ? 0.8 : 1.25;
    this.view = [at - (at - a) * k, at + (b - at) * k];
    this.draw();
  }

  // The y range of the series on one side (`right` or not) within [x0, x1], padded; none when nothing is there.
  range(x0, x1, right) {
    right = !!right;
    let y0 = Infinity, y1 = -Infinity;
    for (const s of this.series) {
      if (!!s.right !== right) continue;
      for (let i = 0; i < s.x.length; i++) {
        if (s.x[i] < x0 || s.x[i] > x1 || !isFinite(s.y[i])) continue;
        y0 = Math.min(y0, s.y[i]); y1 = Math.max(y1, s.y[i]);
      }
    }
    if (!isFinite(y0)) return null;
    // A span of at least `minSpan` (a platform at rest drawn as a line at its value, not its noise magnified).
    const least = right ? this.rightMinSpan : this.minSpan;
    if (least && y1 - y0 < least) {
      const mid = (y0 + y1) / 2;
      y0 = mid - least / 2; y1 = mid + least / 2;
    }
    if (y1 - y0 < 1e-9) {
      // A flat series: a band around it, scaled to its value (not a whole metre around a millimetre).
      const h = Math.max(Math.abs(y0) * 0.05, 1e-3);
      y0 -= h; y1 += h;
    }
    const pad = (y1 - y0) * 0.08;
    // A quantity that is never negative (a cost, a count) keeps its axis at zero and above.
    y0 = y0 >= 0 ? Math.max(0, y0 - pad) : y0 - pad; y1 += pad;
    return [y0, y1];
  }

  draw() {
    const c = this.canvas, box = c.getBoundingClientRect();
    // Hidden (another tab): drawn when shown.
    if (box.width < 1 || box.height < 1) return;
    const dpr = window.devicePixelRatio || 1;
    const pw = Math.round(box.width * dpr), ph = Math.round(box.height * dpr);
    if (c.width !== pw || c.height !== ph) { c.width = pw; c.height = ph; }
    const g = c.getContext("2d");
    g.setTransform(dpr, 0, 0, dpr, 0, 0);
    const W = box.width, H = box.height;
    g.clearRect(0, 0, W, H);
    const [x0, x1] = this.view || this.extent();
    if (!isFinite(x0) || x1 <= x0) return;
    const left = this.range(x0, x1, false), right = this.range(x0, x1, true);
    if (!left && !right) return;
    // The right-hand scale takes room only while it has something to show (a game's cue).
    const L = 62, R = right ? 62 : 8, T = 6, B = 20;
    const X = (x) => L + (x - x0) / (x1 - x0) * (W - L - R);
    const Yof = ([y0, y1]) => (y) => H - B - (y - y0) / (y1 - y0) * (H - T - B);
    g.strokeStyle = "#e5e7eb"; g.lineWidth = 1; g.fillStyle = "#4b5563"; g.font = "12px system-ui";
    if (left) {
      const Y = Yof(left), yt = ticks(left[0], left[1], 4);
      g.textAlign = "right";
      for (const y of yt.at) {
        g.beginPath(); g.moveTo(L, Y(y)); g.lineTo(W - R, Y(y)); g.stroke();
        g.fillText(y.toFixed(yt.decimals) + this.unit, L - 4, Y(y) + 4);
      }
    }
    if (right) {
      const Y = Yof(right), yt = ticks(right[0], right[1], 4);
      g.textAlign = "left"; g.fillStyle = "#6b7280";
      for (const y of yt.at) g.fillText(y.toFixed(yt.decimals) + this.rightUnit, W - R + 4, Y(y) + 4);
    }
    g.textAlign = "center"; g.fillStyle = "#4b5563";
    const xt = ticks(x0, x1, Math.max(2, Math.floor((W - L - R) / 90)));
    for (const x of xt.at) {
      // Kept whole inside the canvas at either end.
      const label = x.toFixed(xt.decimals) + " s", half = g.measureText(label).width / 2;
      g.fillText(label, Math.min(Math.max(X(x), half + 2), W - half - 2), H - 5);
    }
    g.textAlign = "left";
    // Each event's line, and its label (a state change's new state) beside its top, unless the last label is
    // still there.
    let freeFrom = -Infinity;
    for (const e of this.events) {
      if (e.x < x0 || e.x > x1) continue;
      g.strokeStyle = e.colour; g.beginPath(); g.moveTo(X(e.x), T); g.lineTo(X(e.x), H - B); g.stroke();
      if (e.label && X(e.x) >= freeFrom) {
        // Right of its line, or left of it where the plot ends first.
        const w = g.measureText(e.label).width;
        const at = X(e.x) + 3 + w <= W - R ? X(e.x) + 3 : X(e.x) - 3 - w;
        g.fillStyle = "#374151";
        g.fillText(e.label, at, T + 12);
        freeFrom = X(e.x) + w + 8;
      }
    }
    g.save();
    g.beginPath(); g.rect(L, T, W - L - R, H - T - B); g.clip();
    for (const s of this.series) {
      const r = s.right ? right : left;
      if (!r) continue;
      const Y = Yof(r);
      g.strokeStyle = s.colour; g.lineWidth = s.width || 1.5;
      g.setLineDash(s.dash || []);
      g.beginPath();
      let started = false;
      for (let i = 0; i < s.x.length; i++) {
        if (!isFinite(s.y[i])) { started = false; continue; }
        const px = X(s.x[i]), py = Y(s.y[i]);
        if (started) g.lineTo(px, py); else { g.moveTo(px, py); started = true; }
      }
      g.stroke();
    }
    g.restore();
  }
}

// Round tick values over [a, b], about n of them, a step of 1, 2 or 5 times a power of ten, with the decimals
// that step needs: each label differs from the next, none shows more digits than the step.
function ticks(a, b, n) {
  const raw = (b - a) / n, p = Math.pow(10, Math.floor(Math.log10(raw)));
  const step = [1, 2, 5, 10].map((m) => m * p).find((s) => s >= raw);
  const decimals = Math.max(0, -Math.floor(Math.log10(step) + 1e-9));
  const at = [];
  for (let v = Math.ceil(a / step) * step; v <= b + step * 1e-9; v += step) at.push(Math.abs(v) < step * 1e-9 ? 0 : v);
  return { at, decimals };
}
