// The VRM avatar view: three.js + three-vrm (vendor/three-vrm.bundle.js, built by tools/viewer_bundle).
// Stream rotations are local, in the hello's coordinate frame, on Unity HumanBodyBones names; identity is the
// T-pose, as for three-vrm's normalized humanoid bones, so a rotation goes to the normalized bone unchanged once
// it is back in the internal frame (right-handed, Y-up, facing +Z = VRM 1.0). VRM 0.x models face -Z: the scene
// is turned (VRMUtils.rotateVRM0) and their normalized rotations are (-x, y, -z, w), as three-vrm-animation does.
import * as THREE from "./vendor/three-vrm.bundle.js";
import {
  GLTFLoader, VRMLoaderPlugin, VRMUtils, VRMAnimationLoaderPlugin, createVRMAnimationClip,
} from "./vendor/three-vrm.bundle.js";
import { CAMERA_TARGET, VERTICAL_FOV_DEGREES, cameraEye, matVec, rotationToInternal } from "./stick.js";
import { ProceduralFace } from "./face.js";
import { ProceduralMouth } from "./mouth.js";

const BACKGROUND = 0x1d2026;
const VRM1_EXPRESSIONS = ["aa", "ih", "ou", "ee", "oh"];  // the stream's weight order: vowels a i u e o
// the face weights' order (hello "face"), as three-vrm names the presets of VRM 1.0 and 0.x avatars alike
const FACE_EXPRESSIONS = ["blink", "blinkLeft", "blinkRight", "happy", "angry", "sad", "relaxed", "surprised"];
const FOLDED = new THREE.Quaternion();
const THUMB_RENAMES = [["ThumbProximal", "ThumbMetacarpal"], ["ThumbIntermediate", "ThumbProximal"]];

// Unity HumanBodyBones name -> VRM 1.0 humanoid name (as bridges/vrma.py: lower camel case, thumbs renamed).
export function vrmBoneName(unityName) {
  for (const [unity, vrm] of THUMB_RENAMES) {
    if (unityName.endsWith(unity)) { unityName = unityName.slice(0, -unity.length) + vrm; break; }
  }
  return unityName[0].toLowerCase() + unityName.slice(1);
}

function makeScene() {
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(BACKGROUND);
  scene.add(new THREE.AmbientLight(0xffffff, 1.2));
  const sun = new THREE.DirectionalLight(0xffffff, 1.8);
  sun.position.set(1, 2, 3);
  scene.add(sun);
  const floor = new THREE.GridHelper(2, 10, 0x3a404a, 0x2e333b);
  scene.add(floor);
  return scene;
}

export class AvatarView {
  constructor(canvas) {
    this.renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(1);
    this.renderer.setSize(canvas.width, canvas.height, false);
    this.camera = new THREE.PerspectiveCamera(VERTICAL_FOV_DEGREES, canvas.width / canvas.height, 0.05, 50);
    this.scene = makeScene();
    this.loader = new GLTFLoader();
    this.loader.register((parser) => new VRMLoaderPlugin(parser));
    this.loader.register((parser) => new VRMAnimationLoaderPlugin(parser));
    this.vrm = null;
    this.mouth = null;
    this.face = null;  // drawn eyes and brows, for an avatar without blink expressions
    this.mixer = null;  // a dropped .vrma playing
    this.animationEnd = 0;  // its duration, seconds
    this.bound = null;  // the hello the bone table was built for
  }

  // Replace the avatar by the VRM in `buffer` (an ArrayBuffer of a .vrm file).
  async load(buffer) {
    const gltf = await this.loader.parseAsync(buffer, "");
    const vrm = gltf.userData.vrm;
    if (!vrm) throw new Error("not a VRM file (no VRM extension)");
    VRMUtils.removeUnnecessaryVertices(gltf.scene);
    VRMUtils.combineSkeletons(gltf.scene);
    VRMUtils.rotateVRM0(vrm);
    if (this.vrm) { this.scene.remove(this.vrm.scene); VRMUtils.deepDispose(this.vrm.scene); }
    this.vrm = vrm;
    this.isVrm0 = vrm.meta.metaVersion === "0";
    this.scene.add(vrm.scene);
    vrm.update(0);
    this.mouth = this.hasExpressions(VRM1_EXPRESSIONS) ? null : new ProceduralMouth(THREE, vrm, this.scene);
    this.face = this.hasExpressions(["blink"]) ? null : new ProceduralFace(THREE, vrm, this.scene);
    this.bound = null;
    this.mixer = null;
  }

  hasExpressions(names) {
    const manager = this.vrm.expressionManager;
    return Boolean(manager) && names.every((name) => manager.getExpression(name));
  }

  // The bone table for this hello: per stream joint, its normalized node, or for a bone the avatar lacks
  // (e.g. UpperChest) the index of the nearest ancestor it has when the bone has children the avatar has (its
  // rotation is folded into that ancestor), else nothing (a finger the avatar lacks).
  bind(hello) {
    const toInternal = rotationToInternal(hello.to_internal);
    const restHipsY = matVec(hello.to_internal, hello.offsets[0])[1];
    const avatarHipsY = this.vrm.humanoid.normalizedRestPose.hips.position[1];
    const nodes = hello.bones.map((name) => this.vrm.humanoid.getNormalizedBoneNode(vrmBoneName(name)));
    const hasPresentChild = nodes.map(() => false);
    for (let j = nodes.length - 1; j > 0; j--) {  // children come after parents
      if (nodes[j] || hasPresentChild[j]) hasPresentChild[hello.parents[j]] = true;
    }
    const foldInto = nodes.map(() => -1);
    hello.parents.forEach((parent, j) => {
      if (!nodes[j] && hasPresentChild[j] && parent >= 0) foldInto[j] = nodes[parent] ? parent : foldInto[parent];
    });
    this.bound = { hello, toInternal, rootScale: avatarHipsY / restHipsY, nodes, foldInto };
  }

  // Pose the normalized bones from one stream frame; visemes and face weights drive the expressions, or the drawn
  // mouth, eyes and brows.
  applyFrame(hello, frame) {
    if (this.bound?.hello !== hello) this.bind(hello);
    const { toInternal, rootScale, nodes, foldInto } = this.bound;
    const mirror = this.isVrm0 ? -1 : 1;  // VRM 0.x normalized space faces -Z
    frame.rotations.forEach((q, j) => {
      const [x, y, z, w] = toInternal(q);
      if (nodes[j]) nodes[j].quaternion.set(mirror * x, y, mirror * z, w);
      else if (foldInto[j] >= 0) nodes[foldInto[j]].quaternion.multiply(FOLDED.set(mirror * x, y, mirror * z, w));
    });
    const [x, y, z] = matVec(hello.to_internal, frame.root);
    nodes[0]?.position.set(mirror * x * rootScale, y * rootScale, mirror * z * rootScale);
    this.setVisemes(frame.visemes ?? []);
    this.setFace(frame.face ?? []);
  }

  // Blinks and emotion presets: the avatar's own expressions where it has them, else the drawn eyes and brows.
  setFace(weights) {
    const padded = FACE_EXPRESSIONS.map((_, k) => weights[k] ?? 0);
    if (this.face) this.face.setWeights(padded);
    const manager = this.vrm.expressionManager;
    FACE_EXPRESSIONS.forEach((name, k) => { if (manager?.getExpression(name)) manager.setValue(name, padded[k]); });
  }

  // The face's state for tests and the console: drawn eyes and brows, or the expression weights.
  faceState() {
    if (this.face) return { kind: "procedural", opening: this.face.opening, tilt: this.face.tilt };
    return { kind: "expressions", weights: FACE_EXPRESSIONS.map((name) => this.vrm.expressionManager.getValue(name)) };
  }

  setVisemes(weights) {
    const padded = VRM1_EXPRESSIONS.map((_, k) => weights[k] ?? 0);  // (5,) a i u e o
    if (this.mouth) this.mouth.setWeights(padded);
    else VRM1_EXPRESSIONS.forEach((name, k) => this.vrm.expressionManager.setValue(name, padded[k]));
  }

  // The mouth's state for tests and the console: expression weights, or the procedural mouth's opening.
  mouthState() {
    if (this.mouth) return { kind: "procedural", opening: this.mouth.opening, width: this.mouth.width };
    const manager = this.vrm.expressionManager;
    return { kind: "expressions", weights: VRM1_EXPRESSIONS.map((name) => manager.getValue(name)) };
  }

  // Play a .vrma (ArrayBuffer) on the avatar once; the stream takes over again when it ends.
  async playAnimation(buffer) {
    const gltf = await this.loader.parseAsync(buffer, "");
    const animation = gltf.userData.vrmAnimations?.[0];
    if (!animation) throw new Error("not a VRM Animation file (no VRMC_vrm_animation)");
    this.mixer = new THREE.AnimationMixer(this.vrm.scene);
    this.mixer.clipAction(createVRMAnimationClip(animation, this.vrm)).setLoop(THREE.LoopOnce).play();
    this.animationEnd = animation.duration;
    return animation.duration;
  }

  // Pose the avatar at `seconds` into the playing .vrma; the normalized local rotations of `boneNames` (XYZW,
  // the avatar's normalized space: for VRM 0.x the x and z of the internal frame are negated).
  sampleAnimation(seconds, boneNames) {
    this.mixer.setTime(seconds);
    return boneNames.map((name) => this.vrm.humanoid.getNormalizedBoneNode(name).quaternion.toArray());
  }

  render(camera, hello, frame, seconds) {
    if (!this.vrm) return;
    if (this.mixer) {
      this.mixer.update(seconds);
      if (this.mixer.time >= this.animationEnd) this.mixer = null;
    } else if (hello && frame) {
      this.applyFrame(hello, frame);
    }
    this.vrm.update(seconds);
    this.camera.position.fromArray(cameraEye(camera));
    this.camera.lookAt(...CAMERA_TARGET);
    this.renderer.render(this.scene, this.camera);
  }
}
