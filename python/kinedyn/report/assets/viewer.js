// kinedyn report: a small 3-D view of a robot (canvas 2-D, orthographic), no external library.
// The model (bodies, joint axes, placements, frames) comes from the JSON block #kinedyn-model; the
// forward kinematics below is the one of kinedyn.Robot: T_i = T_parent(i) * placement_i * motion_i(q_i + offset_i).
// Drag to rotate, wheel to zoom, sliders to move the joints. window.kinedyn exposes fk() for tests.
(function () {
  "use strict";
  const model = JSON.parse(document.getElementById("kinedyn-model").textContent);
  const n = model.bodies.length;

  // 4x4 row-major matrices as flat arrays of 16 numbers
  function mul(A, B) {
    const C = new Array(16).fill(0);
    for (let i = 0; i < 4; i++)
      for (let k = 0; k < 4; k++) {
        const a = A[4 * i + k];
        if (a !== 0) for (let j = 0; j < 4; j++) C[4 * i + j] += a * B[4 * k + j];
      }
    return C;
  }
  const I4 = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];
  // Rodrigues: rotation by angle about the unit axis (x, y, z)
  function rotation(axis, angle) {
    const [x, y, z] = axis, c = Math.cos(angle), s = Math.sin(angle), v = 1 - c;
    return [c + x * x * v, x * y * v - z * s, x * z * v + y * s, 0,
            y * x * v + z * s, c + y * y * v, y * z * v - x * s, 0,
            z * x * v - y * s, z * y * v + x * s, c + z * z * v, 0, 0, 0, 0, 1];
  }
  function translation(axis, d) {
    return [1, 0, 0, axis[0] * d, 0, 1, 0, axis[1] * d, 0, 0, 1, axis[2] * d, 0, 0, 0, 1];
  }
  // forward kinematics: body poses and named frame poses in the base
  function fk(q) {
    const body = [];
    for (let i = 0; i < n; i++) {
      const b = model.bodies[i];
      const x = q[i] + b.offset;
      const motion = b.kind === "revolute" ? rotation(b.axis, x) : translation(b.axis, x);
      body.push(mul(mul(b.parent < 0 ? I4 : body[b.parent], b.placement), motion));
    }
    const frames = {};
    for (const f of model.frames) frames[f.name] = mul(f.body < 0 ? I4 : body[f.body], f.placement);
    return { body: body, frames: frames };
  }
  const origin = (T) => [T[3], T[7], T[11]];

  // ---------------------------------------------------------------- camera
  const canvas = document.getElementById("kinedyn-view");
  const ctx = canvas.getContext("2d");
  const norm = (v) => { const l = Math.hypot(v[0], v[1], v[2]) || 1; return [v[0] / l, v[1] / l, v[2] / l]; };
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const up = norm(model.up);                 // opposite to gravity
  const back0 = norm(model.view_from);       // from the scene towards the viewer
  const right0 = norm(cross(up, back0));
  const view = { yaw: 0, pitch: 0, zoom: 1 };
  let q = model.q.slice();

  function basis() {
    const cy = Math.cos(view.yaw), sy = Math.sin(view.yaw);
    const right = [0, 1, 2].map((k) => cy * right0[k] + sy * back0[k]);
    const back = [0, 1, 2].map((k) => -sy * right0[k] + cy * back0[k]);
    const cp = Math.cos(view.pitch), sp = Math.sin(view.pitch);
    const scrUp = [0, 1, 2].map((k) => cp * up[k] - sp * back[k]);
    const depth = [0, 1, 2].map((k) => cp * back[k] + sp * up[k]);
    return { right: right, up: scrUp, depth: depth };
  }
  function projector() {
    const B = basis();
    const w = canvas.width, h = canvas.height;
    const scale = view.zoom * 0.42 * Math.min(w, h) / model.reach;
    const c = model.center;
    return function (p) {
      const d = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
      return [w / 2 + scale * dot(d, B.right), h / 2 - scale * dot(d, B.up), dot(d, B.depth)];
    };
  }

  // ---------------------------------------------------------------- drawing
  function line(P, a, b, color, width) {
    const A = P(a), B = P(b);
    ctx.strokeStyle = color; ctx.lineWidth = width; ctx.lineCap = "round";
    ctx.beginPath(); ctx.moveTo(A[0], A[1]); ctx.lineTo(B[0], B[1]); ctx.stroke();
  }
  function triad(P, T, len, width, labels) {
    const o = origin(T);
    const cols = ["#d62728", "#2ca02c", "#1f77b4"];
    for (let k = 0; k < 3; k++) {
      const e = [o[0] + len * T[k], o[1] + len * T[4 + k], o[2] + len * T[8 + k]];
      line(P, o, e, cols[k], width);
      if (labels) { const E = P(e); ctx.fillStyle = cols[k]; ctx.font = "12px sans-serif"; ctx.fillText("xyz"[k], E[0] + 3, E[1] - 3); }
    }
  }
  function draw() {
    const w = canvas.width, h = canvas.height;
    ctx.clearRect(0, 0, w, h);
    ctx.fillStyle = "#fbfbf8"; ctx.fillRect(0, 0, w, h);
    const P = projector();
    // ground grid, perpendicular to "up", through the base
    const g1 = norm(cross(up, Math.abs(up[0]) < 0.9 ? [1, 0, 0] : [0, 1, 0])), g2 = cross(up, g1);
    const R = model.reach * 1.1, steps = 8;
    for (let i = -steps; i <= steps; i++) {
      const t = (i / steps) * R;
      const col = i === 0 ? "#c8c8c0" : "#e6e6df";
      line(P, [g1[0] * t - g2[0] * R, g1[1] * t - g2[1] * R, g1[2] * t - g2[2] * R], [g1[0] * t + g2[0] * R, g1[1] * t + g2[1] * R, g1[2] * t + g2[2] * R], col, 1);
      line(P, [g2[0] * t - g1[0] * R, g2[1] * t - g1[1] * R, g2[2] * t - g1[2] * R], [g2[0] * t + g1[0] * R, g2[1] * t + g1[1] * R, g2[2] * t + g1[2] * R], col, 1);
    }
    triad(P, I4, 0.25 * model.reach, 2, true);
    const K = fk(q);
    // links: parent body origin -> body origin, body origin -> each frame it carries
    const segs = [];
    for (let i = 0; i < n; i++) {
      const b = model.bodies[i];
      segs.push([b.parent < 0 ? [0, 0, 0] : origin(K.body[b.parent]), origin(K.body[i])]);
    }
    for (const f of model.frames) if (f.body >= 0) segs.push([origin(K.body[f.body]), origin(K.frames[f.name])]);
    const drawn = segs.filter((s) => Math.hypot(s[0][0] - s[1][0], s[0][1] - s[1][1], s[0][2] - s[1][2]) > 1e-9)
      .map((s) => ({ s: s, z: (P(s[0])[2] + P(s[1])[2]) / 2 })).sort((a, b) => a.z - b.z);
    for (const d of drawn) { line(P, d.s[0], d.s[1], "#37474f", 9); line(P, d.s[0], d.s[1], "#78909c", 5); }
    // joints: a disc at each joint origin, coloured by kind
    for (let i = 0; i < n; i++) {
      const p = P(origin(K.body[i]));
      ctx.fillStyle = model.bodies[i].kind === "revolute" ? "#ff9800" : "#8e24aa";
      ctx.strokeStyle = "#4e342e"; ctx.lineWidth = 1.5;
      ctx.beginPath(); ctx.arc(p[0], p[1], 7, 0, 2 * Math.PI); ctx.fill(); ctx.stroke();
      ctx.fillStyle = "#333"; ctx.font = "12px sans-serif"; ctx.fillText(model.joint_names[i], p[0] + 9, p[1] + 14);
    }
    const tool = K.frames[model.tool];
    triad(P, tool, 0.15 * model.reach, 2.5, false);
    const t = origin(tool), T = P(t);
    ctx.fillStyle = "#000"; ctx.beginPath(); ctx.arc(T[0], T[1], 4, 0, 2 * Math.PI); ctx.fill();
    const out = document.getElementById("kinedyn-tool");
    if (out) out.textContent = "tool at (" + t.map((v) => v.toFixed(4)).join(", ") + ") m";
  }

  // ---------------------------------------------------------------- interaction
  let drag = null;
  canvas.addEventListener("pointerdown", (e) => { drag = [e.clientX, e.clientY]; canvas.setPointerCapture(e.pointerId); });
  canvas.addEventListener("pointerup", () => { drag = null; });
  canvas.addEventListener("pointermove", (e) => {
    if (!drag) return;
    view.yaw -= (e.clientX - drag[0]) * 0.01;
    view.pitch = Math.max(-1.5, Math.min(1.5, view.pitch + (e.clientY - drag[1]) * 0.01));
    drag = [e.clientX, e.clientY];
    draw();
  });
  canvas.addEventListener("wheel", (e) => { e.preventDefault(); view.zoom *= Math.exp(-e.deltaY * 0.001); draw(); }, { passive: false });
  const sliders = document.getElementById("kinedyn-sliders");
  function label(i) {
    const b = model.bodies[i];
    return b.kind === "revolute" ? (q[i] * 180 / Math.PI).toFixed(1) + "\u00b0" : q[i].toFixed(3) + " m";
  }
  if (sliders) {
    for (let i = 0; i < n; i++) {
      const row = document.createElement("label");
      const b = model.bodies[i];
      const span = b.kind === "revolute" ? Math.PI : model.reach;
      const lo = Number.isFinite(model.lower[i]) ? model.lower[i] : -span;
      const hi = Number.isFinite(model.upper[i]) ? model.upper[i] : span;
      row.innerHTML = "<span class='jn'></span><input type='range'><output></output>";
      row.querySelector(".jn").textContent = model.joint_names[i];
      const input = row.querySelector("input");
      input.min = lo; input.max = hi; input.step = (hi - lo) / 1000; input.value = q[i];
      const out = row.querySelector("output");
      out.textContent = label(i);
      input.addEventListener("input", () => { q[i] = parseFloat(input.value); out.textContent = label(i); draw(); });
      sliders.appendChild(row);
    }
  }
  const reset = document.getElementById("kinedyn-reset");
  if (reset) reset.addEventListener("click", () => {
    q = model.q.slice(); view.yaw = 0; view.pitch = 0; view.zoom = 1;
    document.querySelectorAll("#kinedyn-sliders input").forEach((el, i) => { el.value = q[i]; el.nextElementSibling.textContent = label(i); });
    draw();
  });
  window.kinedyn = { model: model, fk: fk, draw: draw, view: view, setQ: (v) => { q = v.slice(); draw(); } };
  draw();
})();
