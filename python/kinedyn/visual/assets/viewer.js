// kinedyn report: the 3-D view of a robot, drawn with plotly.js (WebGL, inlined from the plotly Python
// package) as lit triangle meshes, with the stick figure and the base and tool frames.
// The model (bodies, joint axes, placements, frames, meshes) comes from the JSON block #kinedyn-model;
// the forward kinematics below is the one of kinedyn.Robot: T_i = T_parent(i) * placement_i * motion_i(q_i + offset_i).
// Each mesh is sent once, in its frame's coordinates (vertices quantised to 16 bits over its bounding
// box, base64); a new q moves it by its frame's pose. Sliders move the joints (a robot with closed loops:
// its independent coordinates, through configurations solved in Python), the play button replays
// the simulation (#kinedyn-data's simulation.q). window.kinedyn exposes fk(), setQ() and counts for tests.
(function () {
  "use strict";
  const model = JSON.parse(document.getElementById("kinedyn-model").textContent);
  const dataBlock = document.getElementById("kinedyn-data");
  const data = dataBlock ? JSON.parse(dataBlock.textContent) : {};
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
  // the rotation of a unit quaternion (x, y, z, w) (scalar last, as kinedyn's q), moved by p
  function quaternionPose(x, y, z, w, p) {
    return [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w), p[0],
            2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w), p[1],
            2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y), p[2], 0, 0, 0, 1];
  }
  // a joint's motion at q: its block starts at q[b.q] (b.q absent: the body's own index)
  function motion(b, i, q) {
    const k = b.q === undefined ? i : b.q;
    if (b.kind === "floating") return quaternionPose(q[k + 3], q[k + 4], q[k + 5], q[k + 6], [q[k], q[k + 1], q[k + 2]]);
    if (b.kind === "spherical") return quaternionPose(q[k], q[k + 1], q[k + 2], q[k + 3], [0, 0, 0]);
    if (b.kind === "planar") {  // (x, y) along the plane's axes e1, e2; the rotation (cos, sin) about e1 x e2
      const e1 = b.e1, e2 = b.e2, c = q[k + 2], s = q[k + 3];
      const nrm = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
      const T = rotation(nrm, Math.atan2(s, c));
      for (let r = 0; r < 3; r++) T[4 * r + 3] = q[k] * e1[r] + q[k + 1] * e2[r];
      return T;
    }
    // a mimic follower (kinedyn.description.mimic) moves by scale * q[its leader] + shift
    const x = (b.scale === undefined ? q[k] : b.scale * q[k] + b.shift) + b.offset;
    return b.kind === "revolute" ? rotation(b.axis, x) : translation(b.axis, x);
  }
  // forward kinematics: body poses and named frame poses in the base
  function fk(q) {
    const body = [];
    for (let i = 0; i < n; i++) {
      const b = model.bodies[i];
      body.push(mul(mul(b.parent < 0 ? I4 : body[b.parent], b.placement), motion(b, i, q)));
    }
    const frames = {};
    for (const f of model.frames) frames[f.name] = mul(f.body < 0 ? I4 : body[f.body], f.placement);
    return { body: body, frames: frames };
  }
  const origin = (T) => [T[3], T[7], T[11]];

  // ---------------------------------------------------------------- meshes
  function bytes(b64) {
    const s = atob(b64), out = new Uint8Array(s.length);
    for (let i = 0; i < s.length; i++) out[i] = s.charCodeAt(i);
    return out;
  }
  // one plotly trace per colour; each mesh keeps its local vertices and its place in its trace
  const traces = [], byColour = {};
  const meshes = (model.meshes || []).map(function (m) {
    const u = new Uint16Array(bytes(m.vertices).buffer);
    const local = new Float32Array(u.length);
    for (let k = 0; k < u.length; k++) local[k] = m.lo[k % 3] + m.step[k % 3] * u[k];
    const f8 = bytes(m.faces);
    const faces = m.wide ? new Uint32Array(f8.buffer) : new Uint16Array(f8.buffer);
    const key = m.rgba.join(",");
    if (!(key in byColour)) { byColour[key] = traces.length; traces.push({ rgba: m.rgba, meshes: [], vertices: 0, faces: [] }); }
    const t = traces[byColour[key]];
    const mesh = { frame: m.frame, visual: m.visual, local: local, trace: byColour[key], offset: t.vertices };
    t.meshes.push(mesh);
    for (let k = 0; k < faces.length; k++) t.faces.push(faces[k] + t.vertices);
    t.vertices += local.length / 3;
    return mesh;
  });
  for (const t of traces) {
    const F = t.faces.length / 3;
    t.i = new Int32Array(F); t.j = new Int32Array(F); t.k = new Int32Array(F);
    for (let f = 0; f < F; f++) { t.i[f] = t.faces[3 * f]; t.j[f] = t.faces[3 * f + 1]; t.k[f] = t.faces[3 * f + 2]; }
    delete t.faces;
  }
  // plotly reads <b>, <br>, <a> ... in text as markup: a name is shown as itself through entities
  const plain = (s) => String(s).replace(/&/g, "&amp;").replace(/</g, "&lt;").replace(/>/g, "&gt;");
  const colour = (c) => "rgb(" + Math.round(255 * c[0]) + "," + Math.round(255 * c[1]) + "," + Math.round(255 * c[2]) + ")";

  // ---------------------------------------------------------------- the plot
  const view = document.getElementById("kinedyn-view");
  let q = model.q.slice();
  const R = model.half, c = model.center;
  const axis = (k, name) => ({ range: [c[k] - R, c[k] + R], title: { text: name }, backgroundcolor: "#d2d9dd", showbackground: true,
                               gridcolor: "#bcc5cb", zerolinecolor: "#9aa5ac", tickfont: { size: 10 } });
  // the camera looks at the robot at q (the box of its shapes, model.focus) from model.view_from; plotly's
  // camera coordinates: the scene cube spans [-0.5, 0.5] in each axis
  const focus = model.focus || { center: c, size: 2 * R };
  const fc = [0, 1, 2].map((k) => (focus.center[k] - c[k]) / (2 * R));
  const distance = Math.max(0.3, 1.35 * focus.size / (2 * R));
  const eye = [0, 1, 2].map((k) => fc[k] + distance * model.view_from[k] / Math.hypot(...model.view_from));
  const layout = {
    margin: { l: 0, r: 0, t: 0, b: 0 }, showlegend: false, uirevision: "kinedyn", paper_bgcolor: "#eef1f2",
    scene: { xaxis: axis(0, "x [m]"), yaxis: axis(1, "y [m]"), zaxis: axis(2, "z [m]"), aspectmode: "cube",
             camera: { eye: { x: eye[0], y: eye[1], z: eye[2] }, up: { x: model.up[0], y: model.up[1], z: model.up[2] }, center: { x: fc[0], y: fc[1], z: fc[2] } } },
  };
  const config = { displaylogo: false, responsive: true, modeBarButtonsToRemove: ["toImage"] };
  const drawnVisuals = new Set();

  function figure(q) {
    const K = fk(q);
    const out = [];
    for (const t of traces) {
      const x = new Float32Array(t.vertices), y = new Float32Array(t.vertices), z = new Float32Array(t.vertices);
      for (const m of t.meshes) {
        const T = K.frames[m.frame];
        if (!T) continue;
        const L = m.local, V = L.length / 3;
        for (let v = 0; v < V; v++) {
          const a = L[3 * v], b = L[3 * v + 1], d = L[3 * v + 2];
          x[m.offset + v] = T[0] * a + T[1] * b + T[2] * d + T[3];
          y[m.offset + v] = T[4] * a + T[5] * b + T[6] * d + T[7];
          z[m.offset + v] = T[8] * a + T[9] * b + T[10] * d + T[11];
        }
        drawnVisuals.add(m.visual);
      }
      out.push({ type: "mesh3d", x: x, y: y, z: z, i: t.i, j: t.j, k: t.k, color: colour(t.rgba), opacity: t.rgba[3],
                 flatshading: false, hoverinfo: "skip",
                 lighting: { ambient: 0.45, diffuse: 0.75, specular: 0.25, roughness: 0.5, fresnel: 0.15, facenormalsepsilon: 0, vertexnormalsepsilon: 0 },
                 lightposition: { x: 2 * R * model.view_from[0] + R, y: 2 * R * model.view_from[1] + R, z: 3 * R } });
    }
    // the stick figure: parent joint -> joint, joint -> each frame its body carries
    const sx = [], sy = [], sz = [];
    const seg = (a, b) => { sx.push(a[0], b[0], null); sy.push(a[1], b[1], null); sz.push(a[2], b[2], null); };
    for (let i = 0; i < n; i++) seg(model.bodies[i].parent < 0 ? [0, 0, 0] : origin(K.body[model.bodies[i].parent]), origin(K.body[i]));
    for (const f of model.frames) if (f.body >= 0) seg(origin(K.body[f.body]), origin(K.frames[f.name]));
    out.push({ type: "scatter3d", mode: "lines", x: sx, y: sy, z: sz, line: { color: "#37474f", width: meshes.length ? 3 : 7 }, hoverinfo: "skip" });
    const jx = [], jy = [], jz = [], jc = [], jt = [];
    for (let i = 0; i < n; i++) {
      const p = origin(K.body[i]);
      jx.push(p[0]); jy.push(p[1]); jz.push(p[2]);
      const kind = model.bodies[i].kind;
      jc.push(kind === "revolute" ? "#ff9800" : kind === "prismatic" ? "#8e24aa" : "#00897b");
      jt.push(plain(model.bodies[i].name === undefined ? model.joint_names[i] : model.bodies[i].name));
    }
    out.push({ type: "scatter3d", mode: model.label_joints ? "markers+text" : "markers", x: jx, y: jy, z: jz, text: jt, textposition: "bottom right",
               textfont: { size: 11, color: "#333" }, marker: { size: 4, color: jc, line: { color: "#4e342e", width: 1 } }, hovertemplate: "%{text}<extra></extra>" });
    // base and tool frames: x red, y green, z blue
    const tool = K.frames[model.tool];
    const cols = ["#d62728", "#2ca02c", "#1f77b4"];
    for (let k = 0; k < 3; k++) {
      const ax = [], ay = [], az = [];
      for (const [T, len] of [[I4, 0.25 * model.reach], [tool, 0.15 * model.reach]]) {
        const o = origin(T);
        ax.push(o[0], o[0] + len * T[k], null); ay.push(o[1], o[1] + len * T[4 + k], null); az.push(o[2], o[2] + len * T[8 + k], null);
      }
      out.push({ type: "scatter3d", mode: "lines", x: ax, y: ay, z: az, line: { color: cols[k], width: 5 }, hoverinfo: "skip" });
    }
    const t = origin(tool);
    out.push({ type: "scatter3d", mode: "markers", x: [t[0]], y: [t[1]], z: [t[2]], marker: { size: 4, color: "#000" }, hovertemplate: "tool<extra></extra>" });
    return { traces: out, tool: tool };
  }

  // ---------------------------------------------------------------- readouts: tool position, pose table, q
  const fmt = (v) => { if (Math.abs(v) < 1e-13) v = 0; const s = Number(v.toPrecision(6)).toString(); return s; };
  // per entry of q: "rad", "m", or "" (a quaternion's, a planar (cos, sin) pair's); named: in a multi-DOF joint's block
  const units = model.coordinate_units || (model.joint_kinds || model.bodies.map((b) => b.kind)).map((kind) => kind === "revolute" ? "rad" : "m");
  const named = model.coordinate_named || units.map(() => false);
  const labels = model.coordinate_labels || model.joint_names;
  const entry = (v, i) => {
    const value = units[i] === "rad" ? fmt(v) + " rad (" + Number((v * 180 / Math.PI).toPrecision(5)) + "°)" : units[i] === "m" ? fmt(v) + " m" : fmt(v);
    return named[i] ? labels[i] + " = " + value : value;
  };
  // one slider per 1-DOF coordinate and per position of a floating or planar joint (model.sliders)
  const sliderList = model.sliders || model.joint_names.map((name, i) => ({ name: name, q: i, revolute: units[i] === "rad", lower: model.lower[i], upper: model.upper[i] }));
  function readouts(tool) {
    const t = origin(tool);
    const out = document.getElementById("kinedyn-tool");
    if (out) out.textContent = "tool at (" + t.map((v) => v.toFixed(4)).join(", ") + ") m";
    const cells = document.querySelectorAll("table.pose tbody td.num");
    if (cells.length === 16) cells.forEach((cell, k) => { cell.textContent = fmt(tool[k]); });
    const qText = document.getElementById("kinedyn-q");
    if (qText) qText.textContent = "q = (" + q.map(entry).join(", ") + ")";
  }

  let pending = false, ready = null;
  function draw() {
    const f = figure(q);
    readouts(f.tool);
    if (view && window.Plotly) ready = window.Plotly.react(view, f.traces, layout, config);
    return ready;
  }
  function schedule() {
    if (pending) return;
    pending = true;
    requestAnimationFrame(() => { pending = false; draw(); });
  }

  // ---------------------------------------------------------------- sliders, reset, playback
  // A robot with closed loops (model.loop, kinedyn.visual.loops): a slider per independent coordinate,
  // each stepping through the positions model.loop.values; the configuration drawn is the one solved
  // in Python for those positions (model.loop.states: one row-major grid over the sliders, or one
  // 1-D sweep per slider from the drawn configuration), never interpolated; null: none was reached.
  const loop = model.loop || null;
  let loopAt = loop ? loop.reference.slice() : null;
  function loopState(at) {
    if (loop.mode === "sweeps") {
      const moved = at.findIndex((k, i) => k !== loop.reference[i]);
      return moved < 0 ? loop.states[0][loop.reference[0]] : loop.states[moved][at[moved]];
    }
    let flat = 0;
    for (let i = 0; i < at.length; i++) flat = flat * loop.values[i].length + at[i];
    return loop.states[0][flat];
  }
  function nearest(values, v) {
    let best = 0;
    for (let k = 1; k < values.length; k++) if (Math.abs(values[k] - v) < Math.abs(values[best] - v)) best = k;
    return best;
  }
  const sliders = document.getElementById("kinedyn-sliders");
  let loopNote = null;
  function label(s) {
    const v = q[s.q];
    return s.revolute ? (v * 180 / Math.PI).toFixed(1) + "\u00b0" : v.toFixed(3) + " m";
  }
  function syncSliders() {
    if (loop) loopAt = loop.q.map((k, i) => nearest(loop.values[i], q[k]));
    document.querySelectorAll("#kinedyn-sliders input").forEach((el, i) => {
      const s = sliderList[i];
      el.value = s.loop === undefined ? q[s.q] : loopAt[s.loop];
      el.nextElementSibling.textContent = label(s);
    });
  }
  function moveLoop(s, k) {
    const at = loop.mode === "sweeps" ? loop.reference.slice() : loopAt.slice();
    at[s.loop] = k;
    const state = loopState(at);
    if (state === null) {  // no closed configuration solved there: the drawing stays, and says so
      if (loopNote) loopNote.textContent = s.name + " = " + fmt(loop.values[s.loop][k]) + ": no closed configuration was reached there; the drawing stays at the last one.";
      syncSliders();
      return;
    }
    if (loopNote) loopNote.textContent = "";
    q = state.slice();
    loopAt = at;
    syncSliders();
    draw();
  }
  if (sliders) {
    for (const s of sliderList) {
      const row = document.createElement("label");
      const span = s.revolute ? Math.PI : model.reach;
      const finite = (x) => typeof x === "number" && Number.isFinite(x);
      // a position without limits (a floating base's x, y, z): one reach either side of where it is
      const lo = finite(s.lower) ? s.lower : (s.revolute ? -span : Math.min(-span, q[s.q] - span));
      const hi = finite(s.upper) ? s.upper : (s.revolute ? span : Math.max(span, q[s.q] + span));
      row.innerHTML = "<span class='jn'></span><input type='range'><output></output>";
      row.querySelector(".jn").textContent = s.name;
      row.title = s.name;
      const input = row.querySelector("input");
      if (s.loop === undefined) {
        input.min = lo; input.max = hi; input.step = (hi - lo) / 1000; input.value = q[s.q];
      } else {  // the index of the slider's solved position
        input.min = 0; input.max = loop.values[s.loop].length - 1; input.step = 1; input.value = loopAt[s.loop];
      }
      input.setAttribute("aria-label", s.name);
      const out = row.querySelector("output");
      out.textContent = label(s);
      input.addEventListener("input", () => {
        stop();
        if (s.loop !== undefined) { moveLoop(s, parseInt(input.value, 10)); return; }
        q[s.q] = parseFloat(input.value); out.textContent = label(s); draw();
      });
      sliders.appendChild(row);
    }
    if (loop) {
      const note = document.createElement("p");
      note.className = "note";
      note.id = "kinedyn-loop-sliders";
      note.textContent = loop.note;
      loopNote = document.createElement("p");
      loopNote.className = "bad";
      loopNote.id = "kinedyn-loop-unreached";
      sliders.appendChild(note);
      sliders.appendChild(loopNote);
    }
  }
  const reset = document.getElementById("kinedyn-reset");
  if (reset) reset.addEventListener("click", () => { stop(); q = model.q.slice(); syncSliders(); if (loopNote) loopNote.textContent = ""; if (view && window.Plotly) window.Plotly.relayout(view, { "scene.camera": layout.scene.camera }); draw(); });

  const sim = data.simulation && data.simulation.q && data.simulation.q.length > 1 ? data.simulation : null;
  const play = document.getElementById("kinedyn-play"), time = document.getElementById("kinedyn-time"), clock = document.getElementById("kinedyn-clock");
  let playing = null;
  function showSample(k) {
    q = sim.q[k].slice();
    if (time) time.value = k;
    if (clock) clock.textContent = "t = " + sim.t[k].toFixed(2) + " s";
    syncSliders();
    schedule();
  }
  function stop() {
    if (playing !== null) { cancelAnimationFrame(playing); playing = null; if (play) play.textContent = "\u25b6 play"; }
  }
  if (sim && play) {
    const controls = document.getElementById("kinedyn-playback");
    if (controls) controls.hidden = false;
    if (time) { time.min = 0; time.max = sim.q.length - 1; time.step = 1; time.value = 0; time.addEventListener("input", () => { stop(); showSample(parseInt(time.value, 10)); }); }
    play.addEventListener("click", () => {
      if (playing !== null) { stop(); return; }
      play.textContent = "\u275a\u275a pause";
      const t0 = performance.now(), k0 = time && parseInt(time.value, 10) < sim.q.length - 1 ? parseInt(time.value, 10) : 0;
      const start = sim.t[k0];
      function tick(now) {
        const target = start + (now - t0) / 1000;
        let k = k0;
        while (k < sim.t.length - 1 && sim.t[k + 1] <= target) k++;
        showSample(k);
        playing = k < sim.t.length - 1 ? requestAnimationFrame(tick) : null;
        if (playing === null && play) play.textContent = "\u25b6 play";
      }
      playing = requestAnimationFrame(tick);
    });
  }

  window.kinedyn = {
    model: model, fk: fk, draw: draw,
    setQ: (v) => { stop(); q = v.slice(); syncSliders(); return draw(); },
    loop: loop,  // the solved configurations of a robot with closed loops (null for a tree)
    q: () => q.slice(),
    meshes: meshes.length,
    drawnVisuals: () => Array.from(drawnVisuals).sort((a, b) => a - b),
    ready: () => ready,
  };
  draw();
})();
