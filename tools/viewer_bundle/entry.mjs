// What the viewer imports from the bundle (bridges/viewer/vendor/three-vrm.bundle.js): only the three.js classes
// avatar.js and mouth.js use (the rest of three is left out: 0.82 MB instead of 0.98 MB), the glTF loader, and
// the three-vrm / three-vrm-animation loader plugins.
export {
  AmbientLight, AnimationMixer, CircleGeometry, Color, DirectionalLight, DoubleSide, GridHelper, LoopOnce, Mesh,
  MeshBasicMaterial, PerspectiveCamera, Quaternion, Raycaster, Scene, Vector3, WebGLRenderer,
} from "three";
export { GLTFLoader } from "three/examples/jsm/loaders/GLTFLoader.js";
export { VRMLoaderPlugin, VRMUtils } from "@pixiv/three-vrm";
export { VRMAnimationLoaderPlugin, createVRMAnimationClip } from "@pixiv/three-vrm-animation";
