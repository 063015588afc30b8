// gesturecast browser viewer: WebSocket client, controls, and the two views (VRM avatar, stick figure).
// Binary frame layout: docs/bridges.md (little-endian, 40-byte header, float32 XYZW per joint, then the
// hello's viseme weights, then its face weights). The avatar view (avatar.js, three.js + three-vrm) is loaded
// only when there is an avatar: the one the server offers at avatar.vrm, or a .vrm file dropped on the page
// (never uploaded).
import { drawStickFigure, forwardKinematics } from "./stick.js";

const HEADER_BYTES = 40;
const MAGIC = "GCPF";
const LATENCY_SMOOTHING = 0.1;
const FPS_WINDOW_S = 1.0;
const DRAG_RADIANS_PER_PIXEL = 0.01;
const MAX_PITCH = 1.4;
const SLIDERS = ["style_strength", "guidance", "audio_guidance"];  // numeric control fields (ranges from the hello's control_schema)
const NOW_SLIDERS = ["intensity"];  // numeric control fields sent as soon as the slider is let go (gesture size)

const state = {
  hello: null, frame: null, pose: null, frames: 0, latencyMs: null, arrivals: [], avatar: null, gesture: "",
  camera: { yaw: 0.5, pitch: 0.15, distance: 3.2 }, touchedSliders: new Set(), styleTouched: false,
  partsTouched: false,
};
const el = (id) => document.getElementById(id);
window.gesturecastViewer = state;  // for the browser tests and the console

// ---- messages ----
function parseBinaryFrame(buffer, jointCount, visemeCount, faceCount) {
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
  const visemeBase = HEADER_BYTES + 16 * count;
  const visemes = Array.from({ length: visemeCount }, (_, k) => view.getFloat32(visemeBase + 4 * k, true));
  const faceBase = visemeBase + 4 * visemeCount;
  const face = Array.from({ length: faceCount }, (_, k) => view.getFloat32(faceBase + 4 * k, true));
  return {
    seq: view.getUint32(4, true),
    captureTime: view.getFloat64(8, true),
    sendTime: view.getFloat64(16, true),
    root: [24, 28, 32].map((o) => view.getFloat32(o, true)),
    speaking: (view.getUint16(38, true) & 1) === 1,
    rotations,
    visemes,
    face,
  };
}

function onFrame(frame) {
  const nowS = (performance.timeOrigin + performance.now()) / 1000;
  const latency = (nowS - frame.captureTime) * 1000;
  state.latencyMs = state.latencyMs === null ? latency : state.latencyMs + LATENCY_SMOOTHING * (latency - state.latencyMs);
  state.arrivals.push(nowS);
  while (state.arrivals.length && state.arrivals[0] < nowS - FPS_WINDOW_S) state.arrivals.shift();
  state.frames += 1;
  state.frame = frame;
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
  for (const name of [...SLIDERS, ...NOW_SLIDERS]) {
    const range = hello.control_schema[name];
    if (range) Object.assign(el(name), { min: range.min, max: range.max });
  }
  const root = hello.control_schema.root;  // bounded (in place), free or locked
  if (root) for (const choice of root.choices) el("root").add(new Option(choice, choice));
  addPartSelectors(hello.body_parts || [], hello.style_choices);
  addGestureButtons(hello.gestures || []);
}

// One style selector per body part (GestureDiffuCLIP §6.3); "(whole-body style)" lets the part follow the style.
function addPartSelectors(parts, choices) {
  const box = el("part-styles");
  for (const part of parts) {
    const select = document.createElement("select");
    select.id = "part-" + part;
    select.add(new Option("(whole-body style)", ""));
    for (const choice of choices) select.add(new Option(choice, choice));
    select.addEventListener("change", () => { state.partsTouched = true; });
    const label = document.createElement("label");
    label.append(part + " ", select);
    box.append(label);
  }
  box.hidden = parts.length === 0;
}

// One button per lexicon gesture: a click sends {"gesture": name}, carried out as soon as the look-ahead allows.
function addGestureButtons(gestures) {
  const box = el("gestures");
  box.hidden = gestures.length === 0;
  for (const name of gestures) {
    const button = document.createElement("button");
    button.type = "button";
    button.textContent = name;
    button.dataset.gesture = name;
    button.addEventListener("click", () => sendControl({ type: "control", gesture: name }));
    box.append(button);
  }
}

// The part_styles control field: every part given its own style ({} sends the whole body back to one style).
function partStyles() {
  const chosen = {};
  for (const part of state.hello.body_parts || []) {
    const value = el("part-" + part).value;
    if (value) chosen[part] = value;
  }
  return chosen;
}

// The style in effect: shown as text, and picked in the dropdown when it is one of the labels.
function showStyle(style) {
  el("style").textContent = style || "–";
  const select = el("style-select");
  if (!state.styleTouched && [...select.options].some((option) => option.value === style)) select.value = style;
}

// The lexicon gesture playing ("wave", "wave+bow" while they cross-fade), from the side message sent on each change.
function showGesture(playing) {
  el("gesture").textContent = playing || "–";
  state.gesture = playing;
}

function onText(message) {
  if (message.type === "hello") onHello(message);
  else if (message.type === "frame") onFrame({ ...message, captureTime: message.capture_time });
  else if (message.type === "style") showStyle(message.style);
  else if (message.type === "gesture") showGesture(message.playing);
  else if (message.type === "ack") el("message").textContent = "applied " + JSON.stringify(message.applied);
  else if (message.type === "error") el("message").textContent = "error: " + message.message;
}

function connect() {
  const socket = new WebSocket(`ws://${location.host}/`);
  state.socket = socket;
  socket.binaryType = "arraybuffer";
  socket.onopen = () => { el("connection").textContent = "connected"; };
  socket.onclose = () => { el("connection").textContent = "disconnected"; };
  socket.onmessage = (event) => {
    if (typeof event.data === "string") onText(JSON.parse(event.data));
    else if (state.hello) {
      const { bones, visemes, face } = state.hello;
      onFrame(parseBinaryFrame(event.data, bones.length, visemes.length, (face ?? []).length));
    }
  };
  el("controls").addEventListener("submit", (event) => {
    event.preventDefault();
    const control = { type: "control" };
    for (const name of state.touchedSliders) control[name] = Number(el(name).value);  // only what the user moved
    const text = el("style-text").value.trim();  // free text is a prompt, not a label
    if (text) control.prompt = text;
    else if (state.styleTouched && el("style-select").value) control.style = el("style-select").value;
    if (el("root").value) control.root = el("root").value;
    if (state.partsTouched) control.part_styles = partStyles();
    sendControl(control);
  });
}

// A control message with the page's ?token= (the port's token, when it has one).
function sendControl(control) {
  const token = new URLSearchParams(location.search).get("token");
  if (token) control.token = token;
  state.socket.send(JSON.stringify(control));
}

// ---- the avatar: served at avatar.vrm, or dropped on the page ----
async function avatarView() {
  if (!state.avatar) {
    const { AvatarView } = await import("./avatar.js");
    state.avatar = new AvatarView(el("avatar"));
  }
  return state.avatar;
}

async function showAvatar(buffer, name) {
  el("avatar-status").textContent = "loading " + name;
  try {
    await (await avatarView()).load(buffer);
  } catch (error) {
    el("avatar-status").textContent = `cannot show ${name}: ${error.message}`;
    return;
  }
  el("avatar-status").textContent = name;
  el("show-stick").checked = false;
  document.body.dataset.avatar = "loaded";
  showView();
}

async function loadServedAvatar() {
  // the avatar is behind the port's token, like the controls: the page's own ?token= goes in a header
  const token = new URLSearchParams(location.search).get("token");
  const response = await fetch("avatar.vrm", token ? { headers: { Authorization: `Bearer ${token}` } } : {});
  if (!response.ok) {
    el("avatar-status").textContent = "none: drop a .vrm file here";
    document.body.dataset.avatar = "none";
    return;
  }
  await showAvatar(await response.arrayBuffer(), "avatar.vrm (from the server)");
}

// A dropped .vrm becomes the avatar; a dropped .vrma plays on it once (then the stream takes over again).
function enableDrop() {
  const stage = el("stage-box");
  stage.addEventListener("dragover", (event) => { event.preventDefault(); stage.classList.add("dragging"); });
  stage.addEventListener("dragleave", () => stage.classList.remove("dragging"));
  stage.addEventListener("drop", async (event) => {
    event.preventDefault();
    stage.classList.remove("dragging");
    const file = event.dataTransfer.files[0];
    if (!file) return;
    if (file.name.toLowerCase().endsWith(".vrma") && state.avatar?.vrm) {
      try {
        const seconds = await state.avatar.playAnimation(await file.arrayBuffer());
        el("avatar-status").textContent = `playing ${file.name} (${seconds.toFixed(1)} s)`;
      } catch (error) {
        el("avatar-status").textContent = `cannot play ${file.name}: ${error.message}`;
      }
    } else {
      await showAvatar(await file.arrayBuffer(), file.name);
    }
  });
}

// ---- drawing ----
// The "stick figure" box picks the view: ticked, the stick figure; unticked, the avatar. Without an avatar an
// unticked box leaves the stage empty (floor only, orbit and the drop target still there), never the figure.
function showView() {
  const hasAvatar = Boolean(state.avatar?.vrm);
  const stick = el("show-stick").checked;
  el("stage").hidden = hasAvatar && !stick;
  el("avatar").hidden = !hasAvatar || stick;
  el("drop-hint").hidden = hasAvatar;
}

let lastRenderMs = performance.now();
function render(nowMs) {
  const seconds = Math.max(0, (nowMs - lastRenderMs) / 1000);
  lastRenderMs = nowMs;
  if (!el("stage").hidden) {
    drawStickFigure(el("stage"), state.camera, state.hello, el("show-stick").checked ? state.pose : null);
  }
  if (!el("avatar").hidden) state.avatar.render(state.camera, state.hello, state.frame, seconds);
  requestAnimationFrame(render);
}

function enableOrbit() {
  for (const canvas of [el("stage"), el("avatar")]) {
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
      state.camera.distance = Math.max(0.5, state.camera.distance * Math.exp(e.deltaY * 0.001));
    }, { passive: false });
  }
}

function enableControls() {
  el("style-select").addEventListener("change", () => { state.styleTouched = true; });
  for (const name of SLIDERS) {
    el(name).addEventListener("input", () => {
      el(`${name}-value`).textContent = el(name).value;
      state.touchedSliders.add(name);
    });
  }
  for (const name of NOW_SLIDERS) {
    el(name).addEventListener("input", () => { el(`${name}-value`).textContent = el(name).value; });
    el(name).addEventListener("change", () => sendControl({ type: "control", [name]: Number(el(name).value) }));
  }
  el("pause").addEventListener("change", () => sendControl({ type: "control", pause: el("pause").checked }));
  el("show-stick").addEventListener("change", showView);
}

enableOrbit();
enableControls();
enableDrop();
showView();
connect();
loadServedAvatar();
requestAnimationFrame(render);
