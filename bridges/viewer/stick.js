// The stick figure: forward kinematics from the hello and a tiny canvas-2D 3D view.
// Positions and rotations are taken back to the internal frame (right-handed, Y-up, facing +Z) first.

const CAMERA_TARGET = [0, 1.0, 0];
const FOCAL_FRACTION = 1.6;
const BODY_LINE_PX = 4;
const FINGER_LINE_PX = 1.5;  // finger bones (hello bones named Left/Right + Thumb/Index/Middle/Ring/Little)
const JOINT_DOT_PX = 3;
const FINGER_DOT_PX = 1;
const FINGER_NAME = /(Thumb|Index|Middle|Ring|Little)(Proximal|Intermediate|Distal)$/;
export const VERTICAL_FOV_DEGREES = 2 * Math.atan(1 / FOCAL_FRACTION) * 180 / Math.PI;  // the avatar view's too

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
export const matVec = (m, v) => [dot(m[0], v), dot(m[1], v), dot(m[2], v)];

// Quaternion of the stream's frame -> internal frame: q' = (det R · R v, w), R = to_internal without its scale.
export function rotationToInternal(toInternal) {
  const rows = toInternal.map((row) => scale(row, 1 / Math.hypot(...toInternal[0])));
  const det = dot(rows[0], cross(rows[1], rows[2]));
  return (q) => [...scale(matVec(rows, [q[0], q[1], q[2]]), Math.sign(det)), q[3]];
}

// Joint positions from local rotations (parents come before children), in the internal frame.
export function forwardKinematics(hello, root, rotations) {
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

// The orbit camera's eye (yaw, pitch, distance around the target), shared with the avatar view.
export function cameraEye(camera) {
  return add(CAMERA_TARGET, scale([
    Math.sin(camera.yaw) * Math.cos(camera.pitch), Math.sin(camera.pitch), Math.cos(camera.yaw) * Math.cos(camera.pitch),
  ], camera.distance));
}
export { CAMERA_TARGET };

function project(point, canvas, camera) {
  const eye = cameraEye(camera);
  const forward = normalize(sub(CAMERA_TARGET, eye));
  const right = normalize(cross(forward, [0, 1, 0]));
  const up = cross(right, forward);
  const d = sub(point, eye);
  const depth = dot(d, forward);
  const focal = FOCAL_FRACTION * canvas.height / 2;
  return [canvas.width / 2 + focal * dot(d, right) / depth, canvas.height / 2 - focal * dot(d, up) / depth];
}

function drawLine(ctx, canvas, camera, a, b) {
  const [pa, pb] = [project(a, canvas, camera), project(b, canvas, camera)];
  ctx.beginPath();
  ctx.moveTo(pa[0], pa[1]);
  ctx.lineTo(pb[0], pb[1]);
  ctx.stroke();
}

function drawFloor(ctx, canvas, camera) {
  ctx.strokeStyle = "#2e333b";
  ctx.lineWidth = 1;
  for (let i = -5; i <= 5; i++) {
    drawLine(ctx, canvas, camera, [i * 0.2, 0, -1], [i * 0.2, 0, 1]);
    drawLine(ctx, canvas, camera, [-1, 0, i * 0.2], [1, 0, i * 0.2]);
  }
}

function drawSkeleton(ctx, canvas, camera, hello, pose) {
  const { parents, bones } = hello;
  ctx.lineCap = "round";
  parents.forEach((parent, j) => {
    if (parent < 0) return;
    const name = bones[j];
    ctx.lineWidth = FINGER_NAME.test(name) ? FINGER_LINE_PX : BODY_LINE_PX;
    ctx.strokeStyle = name.startsWith("Left") ? "#4fc3f7" : name.startsWith("Right") ? "#ff8a65" : "#e4e6ea";
    drawLine(ctx, canvas, camera, pose[parent], pose[j]);
  });
  ctx.fillStyle = "#ffd54f";
  pose.forEach((p, j) => {
    const s = project(p, canvas, camera);
    ctx.beginPath();
    ctx.arc(s[0], s[1], FINGER_NAME.test(bones[j]) ? FINGER_DOT_PX : JOINT_DOT_PX, 0, 2 * Math.PI);
    ctx.fill();
  });
}

// One picture of the stick figure (pose: joint positions from forwardKinematics, or null before the first frame).
export function drawStickFigure(canvas, camera, hello, pose) {
  const ctx = canvas.getContext("2d");
  ctx.clearRect(0, 0, canvas.width, canvas.height);
  drawFloor(ctx, canvas, camera);
  if (pose) drawSkeleton(ctx, canvas, camera, hello, pose);
}
