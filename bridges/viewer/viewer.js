// gesturecast browser viewer: WebSocket client, forward kinematics and a tiny canvas 3D view.
// Binary frame layout: docs/bridges.md (little-endian, 40-byte header, then float32 XYZW per joint).
"use strict";

const HEADER_BYTES = 40;
const MAGIC = "GCPF";
const LATENCY_SMOOTHING = 0.1;
const FPS_WINDOW_S = 1.0;
const CAMERA_TARGET = [0, 1.0, 0];
const DRAG_RADIANS_PER_PIXEL = 0.01;
const MAX_PITCH = 1.4;
const FOCAL_FRACTION = 1.6;
const SLIDERS = ["guidance", "audio_guidance"];
const BODY_LINE_PX = 4;
const FINGER_LINE_PX = 1.5;  // finger bones (hello bones named Left/Right + Thumb/Index/Middle/Ring/Little)
const JOINT_DOT_PX = 3;
const FINGER_DOT_PX = 1;
const FINGER_NAME = /(Thumb|Index|Middle|Ring|Little)(Proximal|Intermediate|Distal)$/;  // numeric control fields (ranges from the hello's control_schema)

const state = {
  hello: null, pose: null, frames: 0, latencyMs: null, arrivals: [],
  camera: { yaw: 0.5, pitch: 0.15, distance: 3.2 }, touchedSliders: new Set(), styleTouched: false,
};
const el = (id) => document.getElementById(id);

// ---- quaternion / vector math (XYZW) ----
function quatMul(a, b) {
  return [
    a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1],
    a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0],
    a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3],
    a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2],
  ];
}
function quatRotate(q, v) {
  const u = [q[0], q[1], q[2]];
  const t = scale(cross(u, v), 2);
  return add(add(v, scale(t, q[3])), cross(u, t));
}
const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const scale = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const normalize = (a) => scale(a, 1 / Math.hypot(a[0], a[1], a[2]));
const matVec = (m, v) => [dot(m[0], v), dot(m[1], v), dot(m[2], v)];

// Joint positions from local rotations (parents come before children), in the internal frame.
function forwardKinematics(hello, root, rotations) {
  const globalRot = [];
  const positions = [];
  hello.parents.forEach((parent, j) => {
    if (parent < 0) {
      globalRot.push(rotations[j]);
      positions.push(root);
    } else {
      globalRot.push(quatMul(globalRot[parent], rotations[j]));
      positions.push(add(positions[parent], quatRotate(globalRot[parent], hello.offsets[j])));
    }
  });
  return positions.map((p) => matVec(hello.to_internal, p));
}

// ---- messages ----
function parseBinaryFrame(buffer, jointCount) {
  const view = new DataView(buffer);
  const magic = String.fromCharCode(...new Uint8Array(buffer, 0, 4));
  if (magic !== MAGIC) throw new Error("bad frame magic " + magic);
  const count = view.getUint16(36, true);
  if (count !== jointCount) throw new Error(`frame has ${count} joints, hello said ${jointCount}`);
  const rotations = [];
  for (let j = 0; j < count; j++) {
    const base = HEADER_BYTES + 16 * j;
    rotations.push([0, 4, 8, 12].map((o) => view.getFloat32(base + o, true)));
  }
  return {
    seq: view.getUint32(4, true),
    captureTime: view.getFloat64(8, true),
    sendTime: view.getFloat64(16, true),
    root: [24, 28, 32].map((o) => view.getFloat32(o, true)),
    speaking: (view.getUint16(38, true) & 1) === 1,
    rotations,
  };
}

function onFrame(frame) {
  const nowS = (performance.timeOrigin + performance.now()) / 1000;
  const latency = (nowS - frame.captureTime) * 1000;
  state.latencyMs = state.latencyMs === null ? latency : state.latencyMs + LATENCY_SMOOTHING * (latency - state.latencyMs);
  state.arrivals.push(nowS);
  while (state.arrivals.length && state.arrivals[0] < nowS - FPS_WINDOW_S) state.arrivals.shift();
  state.frames += 1;
  state.pose = forwardKinematics(state.hello, frame.root, frame.rotations);
  el("frames").textContent = String(state.frames);
  el("latency").textContent = state.latencyMs.toFixed(1) + " ms";
  el("latency").dataset.ms = state.latencyMs.toFixed(3);
  el("fps").textContent = (state.arrivals.length / FPS_WINDOW_S).toFixed(1) + " frames/s";
  el("speaking").textContent = frame.speaking ? "yes" : "no";
}

function onHello(hello) {
  state.hello = hello;
  el("style").textContent = hello.style || "–";
  const select = el("style-select");
  for (const choice of hello.style_choices) select.add(new Option(choice, choice));
  showStyle(hello.style);
  for (const name of SLIDERS) {
    const range = hello.control_schema[name];
    if (range) Object.assign(el(name), { min: range.min, max: range.max });
  }
  const root = hello.control_schema.root;  // bounded (in place), free or locked
  if (root) for (const choice of root.choices) el("root").add(new Option(choice, choice));
}

// The style in effect: shown as text, and picked in the dropdown when it is one of the labels.
function showStyle(style) {
  el("style").textContent = style || "–";
  const select = el("style-select");
  if (!state.styleTouched && [...select.options].some((option) => option.value === style)) select.value = style;
}

function onText(message) {
  if (message.type === "hello") onHello(message);
  else if (message.type === "frame") onFrame({ ...message, captureTime: message.capture_time });
  else if (message.type === "style") showStyle(message.style);
  else if (message.type === "ack") el("message").textContent = "applied " + JSON.stringify(message.applied);
  else if (message.type === "error") el("message").textContent = "error: " + message.message;
}

function connect() {
  const socket = new WebSocket(`ws://${location.host}/`);
  socket.binaryType = "arraybuffer";
  socket.onopen = () => { el("connection").textContent = "connected"; };
  socket.onclose = () => { el("connection").textContent = "disconnected"; };
  socket.onmessage = (event) => {
    if (typeof event.data === "string") onText(JSON.parse(event.data));
    else if (state.hello) onFrame(parseBinaryFrame(event.data, state.hello.bones.length));
  };
  el("controls").addEventListener("submit", (event) => {
    event.preventDefault();
    const control = { type: "control" };
    for (const name of state.touchedSliders) control[name] = Number(el(name).value);  // only what the user moved
    const text = el("style-text").value.trim();  // free text is a prompt, not a label
    if (text) control.prompt = text;
    else if (state.styleTouched && el("style-select").value) control.style = el("style-select").value;
    if (el("root").value) control.root = el("root").value;
    const token = new URLSearchParams(location.search).get("token");
    if (token) control.token = token;
    socket.send(JSON.stringify(control));
  });
}

// ---- drawing ----
function project(point, canvas) {
  const cam = state.camera;
  const eye = add(CAMERA_TARGET, scale([
    Math.sin(cam.yaw) * Math.cos(cam.pitch), Math.sin(cam.pitch), Math.cos(cam.yaw) * Math.cos(cam.pitch),
  ], cam.distance));
  const forward = normalize(sub(CAMERA_TARGET, eye));
  const right = normalize(cross(forward, [0, 1, 0]));
  const up = cross(right, forward);
  const d = sub(point, eye);
  const depth = dot(d, forward);
  const focal = FOCAL_FRACTION * canvas.height / 2;
  return [canvas.width / 2 + focal * dot(d, right) / depth, canvas.height / 2 - focal * dot(d, up) / depth];
}

function drawLine(ctx, canvas, a, b) {
  const [pa, pb] = [project(a, canvas), project(b, canvas)];
  ctx.beginPath();
  ctx.moveTo(pa[0], pa[1]);
  ctx.lineTo(pb[0], pb[1]);
  ctx.stroke();
}

function drawFloor(ctx, canvas) {
  ctx.strokeStyle = "#2e333b";
  ctx.lineWidth = 1;
  for (let i = -5; i <= 5; i++) {
    drawLine(ctx, canvas, [i * 0.2, 0, -1], [i * 0.2, 0, 1]);
    drawLine(ctx, canvas, [-1, 0, i * 0.2], [1, 0, i * 0.2]);
  }
}

function drawSkeleton(ctx, canvas) {
  const { parents, bones } = state.hello;
  ctx.lineCap = "round";
  parents.forEach((parent, j) => {
    if (parent < 0) return;
    const name = bones[j];
    ctx.lineWidth = FINGER_NAME.test(name) ? FINGER_LINE_PX : BODY_LINE_PX;
    ctx.strokeStyle = name.startsWith("Left") ? "#4fc3f7" : name.startsWith("Right") ? "#ff8a65" : "#e4e6ea";
    drawLine(ctx, canvas, state.pose[parent], state.pose[j]);
  });
  ctx.fillStyle = "#ffd54f";
  state.pose.forEach((p, j) => {
    const s = project(p, canvas);
    ctx.beginPath();
    ctx.arc(s[0], s[1], FINGER_NAME.test(bones[j]) ? FINGER_DOT_PX : JOINT_DOT_PX, 0, 2 * Math.PI);
    ctx.fill();
  });
}

function render() {
  const canvas = el("stage");
  const ctx = canvas.getContext("2d");
  ctx.clearRect(0, 0, canvas.width, canvas.height);
  drawFloor(ctx, canvas);
  if (state.pose) drawSkeleton(ctx, canvas);
  requestAnimationFrame(render);
}

function enableOrbit() {
  const canvas = el("stage");
  let last = null;
  canvas.addEventListener("pointerdown", (e) => { last = [e.clientX, e.clientY]; canvas.setPointerCapture(e.pointerId); });
  canvas.addEventListener("pointerup", () => { last = null; });
  canvas.addEventListener("pointermove", (e) => {
    if (!last) return;
    const cam = state.camera;
    cam.yaw -= (e.clientX - last[0]) * DRAG_RADIANS_PER_PIXEL;
    cam.pitch = Math.max(-MAX_PITCH, Math.min(MAX_PITCH, cam.pitch + (e.clientY - last[1]) * DRAG_RADIANS_PER_PIXEL));
    last = [e.clientX, e.clientY];
  });
  canvas.addEventListener("wheel", (e) => {
    e.preventDefault();
    state.camera.distance = Math.max(1, state.camera.distance * Math.exp(e.deltaY * 0.001));
  }, { passive: false });
  el("style-select").addEventListener("change", () => { state.styleTouched = true; });
  for (const name of SLIDERS) {
    el(name).addEventListener("input", () => {
      el(`${name}-value`).textContent = el(name).value;
      state.touchedSliders.add(name);
    });
  }
}

enableOrbit();
connect();
requestAnimationFrame(render);
