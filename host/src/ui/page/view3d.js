// The platform in 3D on a 2D canvas: an orbit camera (drag to turn, wheel to zoom), the ring, each chain from
// its carriage to its platform joint, the platform, and the commanded pose as a ghost. z is up, metres.
"use strict";

class View3d {
  constructor(canvas) {
    this.canvas = canvas;
    // The box keeps the shape the page gave it; the drawing is made at its CSS size x devicePixelRatio (sharp on
    // a high-density screen, never stretched), so the attributes' size is only the shape.
    canvas.style.aspectRatio = `${canvas.width} / ${canvas.height}`;
    this.W = canvas.width; this.H = canvas.height;
    this.yaw = -0.6;
    this.pitch = 0.45;
    this.zoom = 1;
    this.rig = null;
    this.placed = null;
    this.ghost = null;
    let drag = null;
    canvas.addEventListener("mousedown", (e) => { drag = [e.clientX, e.clientY]; });
    window.addEventListener("mouseup", () => { drag = null; });
    window.addEventListener("mousemove", (e) => {
      if (!drag) return;
      this.yaw -= (e.clientX - drag[0]) * 0.01;
      this.pitch = Math.min(1.5, Math.max(-0.2, this.pitch + (e.clientY - drag[1]) * 0.01));
      drag = [e.clientX, e.clientY];
      this.draw();
    });
    canvas.addEventListener("wheel", (e) => {
      e.preventDefault();
      this.zoom = Math.min(8, Math.max(0.3, this.zoom * (e.deltaY < 0 ? 1.1 : 0.9)));
      this.draw();
    }, { passive: false });
  }

  // rig: {ring_radius, chains}; placed and ghost: {carriages: [[x,y,z]], joints: [[x,y,z]]} or null.
  show(rig, placed, ghost) {
    this.rig = rig;
    if (placed) this.placed = placed;
    this.ghost = ghost;
    this.draw();
  }

  project(p) {
    const r = this.rig ? this.rig.ring_radius : 0.3;
    const W = this.W, H = this.H;
    const s = Math.min(W, H) * 0.42 / r * this.zoom;
    const cy = Math.cos(this.yaw), sy = Math.sin(this.yaw);
    const x = p[0] * cy - p[1] * sy, y = p[0] * sy + p[1] * cy;
    const cp = Math.cos(this.pitch), sp = Math.sin(this.pitch);
    const depth = y * cp + p[2] * sp;
    const up = p[2] * cp - y * sp;
    // A mild perspective: nearer is a little larger.
    const k = 1 / (1 + depth / (6 * r));
    return [W / 2 + x * s * k, H * 0.62 - up * s * k];
  }

  line(g, a, b) {
    const p = this.project(a), q = this.project(b);
    g.beginPath(); g.moveTo(p[0], p[1]); g.lineTo(q[0], q[1]); g.stroke();
  }

  dot(g, a, radius) {
    const p = this.project(a);
    g.beginPath(); g.arc(p[0], p[1], radius, 0, 2 * Math.PI); g.fill();
  }

  mechanism(g, m, ghost) {
    const rod = ghost ? "rgba(148,163,184,0.45)" : "#f59e0b";
    const radial = ghost ? "rgba(148,163,184,0.45)" : "#38bdf8";
    g.lineWidth = ghost ? 2 : 3;
    g.setLineDash(ghost ? [6, 4] : []);
    const elbow = ghost ? "rgba(148,163,184,0.45)" : "#a3e635";
    m.joints.forEach((j, i) => {
      const arm = m.arms && m.arms[i];
      if (arm) {
        // An elbow chain: the carriage's post to the shoulder axis, the upper arm, the forearm.
        g.strokeStyle = elbow;
        this.line(g, m.carriages[i], arm[0]);
        this.line(g, arm[0], arm[1]);
        this.line(g, arm[1], j);
        return;
      }
      g.strokeStyle = (this.rig.chains[i] === "radial") ? radial : rod;
      this.line(g, m.carriages[i], j);
    });
    // The platform: its joints in chain order, closed.
    g.strokeStyle = ghost ? "rgba(226,232,240,0.5)" : "#e2e8f0";
    g.fillStyle = ghost ? "rgba(226,232,240,0.06)" : "rgba(96,165,250,0.25)";
    g.beginPath();
    m.joints.forEach((j, i) => {
      const p = this.project(j);
      if (i === 0) g.moveTo(p[0], p[1]); else g.lineTo(p[0], p[1]);
    });
    g.closePath(); g.fill(); g.stroke();
    g.setLineDash([]);
    if (!ghost) {
      g.fillStyle = "#fbbf24";
      m.carriages.forEach((c) => this.dot(g, c, 6));
      g.fillStyle = "#e2e8f0";
      m.joints.forEach((j) => this.dot(g, j, 4));
      g.fillStyle = "#a3e635";
      (m.arms || []).forEach((a) => { if (a) { this.dot(g, a[0], 4); this.dot(g, a[1], 4); } });
    }
  }

  draw() {
    const c = this.canvas, box = c.getBoundingClientRect(), dpr = window.devicePixelRatio || 1;
    // Hidden (another tab): drawn at the attributes' size until shown.
    if (box.width >= 1 && box.height >= 1) {
      const pw = Math.round(box.width * dpr), ph = Math.round(box.height * dpr);
      if (c.width !== pw || c.height !== ph) { c.width = pw; c.height = ph; }
    }
    const g = c.getContext("2d");
    const k = box.width >= 1 ? c.width / box.width : 1;
    g.setTransform(k, 0, 0, k, 0, 0);
    const W = this.W = c.width / k, H = this.H = c.height / k;
    g.fillStyle = "#0f1420"; g.fillRect(0, 0, W, H);
    if (!this.rig) return;
    const r = this.rig.ring_radius;
    // The floor grid and the axes.
    g.strokeStyle = "#1f2937"; g.lineWidth = 1;
    for (let k = -4; k <= 4; k++) {
      const v = k * r / 4 * 1.25;
      this.line(g, [v, -1.25 * r, 0], [v, 1.25 * r, 0]);
      this.line(g, [-1.25 * r, v, 0], [1.25 * r, v, 0]);
    }
    g.lineWidth = 2;
    [["#ef4444", [0.3 * r, 0, 0], "x"], ["#22c55e", [0, 0.3 * r, 0], "y"], ["#3b82f6", [0, 0, 0.3 * r], "z"]].forEach(([c, p, n]) => {
      g.strokeStyle = c; this.line(g, [0, 0, 0], p);
      const q = this.project(p); g.fillStyle = c; g.font = "13px system-ui"; g.fillText(n, q[0] + 3, q[1]);
    });
    // The ring.
    g.strokeStyle = "#64748b"; g.lineWidth = 4;
    g.beginPath();
    for (let k = 0; k <= 96; k++) {
      const a = k / 96 * 2 * Math.PI;
      const p = this.project([r * Math.cos(a), r * Math.sin(a), 0]);
      if (k === 0) g.moveTo(p[0], p[1]); else g.lineTo(p[0], p[1]);
    }
    g.stroke();
    if (this.ghost) this.mechanism(g, this.ghost, true);
    if (this.placed) this.mechanism(g, this.placed, false);
    else { g.fillStyle = "#94a3b8"; g.fillText("the pose has no inverse kinematics", 12, 20); }
  }
}
