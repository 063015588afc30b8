// A drawn mouth for avatars without mouth expressions (e.g. the default cryptovoxels.vrm has no blend shapes):
// a dark ellipse on the face, attached to the head bone, whose height and width follow the viseme weights.
// The face is found by casting rays at the head in the rest pose (faceAnchor, also used by face.js): down onto the
// top of the head, then backwards (-Z, the avatar faces +Z) onto the face at a third of the head's height.

const MOUTH_COLOR = 0x3a0c14;
const MOUTH_HEIGHT_FRACTION = 0.3;  // of the head (head bone to top of the head), above the head bone
const MOUTH_HALF_WIDTH_FRACTION = 0.17;  // of the head's height
const SURFACE_GAP_M = 0.004;  // in front of the face, so the depth test never hides it
const CLOSED_OPENING = 0.08;  // a closed mouth is a thin line (height / half-width)
const FALLBACK_HEAD_HEIGHT_M = 0.22;

// Opening (height / half-width) and width factor from the weights of the vowels a i u e o.
export function mouthShape([a, i, u, e, o]) {
  const opening = CLOSED_OPENING + Math.min(1, a + 0.7 * o + 0.5 * e + 0.35 * u + 0.2 * i) * 0.9;
  const width = Math.max(0.45, 1 + 0.25 * i + 0.15 * e - 0.3 * o - 0.45 * u);
  return { opening, width };
}

function firstHit(THREE, meshes, origin, direction) {
  const hits = new THREE.Raycaster(origin, direction).intersectObjects(meshes, false);
  return hits.length ? hits[0].point : null;
}

// The head bone, the head's height and a function giving the point just in front of the face at a height above
// the head bone and a sideways offset (both fractions of the head's height; +x is the avatar's left), found in
// the rest pose: a ray down onto the top of the head, then one backwards (-Z) onto the face.
export function faceAnchor(THREE, vrm, scene) {
  const head = vrm.humanoid.getRawBoneNode("head");
  scene.updateMatrixWorld(true);
  const meshes = [];
  vrm.scene.traverse((object) => { if (object.isMesh) meshes.push(object); });
  const headPoint = head.getWorldPosition(new THREE.Vector3());
  const top = firstHit(THREE, meshes, headPoint.clone().add(new THREE.Vector3(0, 1, 0)), new THREE.Vector3(0, -1, 0));
  const headHeight = top && top.y > headPoint.y ? top.y - headPoint.y : FALLBACK_HEAD_HEIGHT_M;
  const anchorAt = (heightFraction, sideFraction = 0) => {
    const level = headPoint.clone().add(new THREE.Vector3(sideFraction * headHeight, heightFraction * headHeight, 0));
    const face = firstHit(THREE, meshes, level.clone().add(new THREE.Vector3(0, 0, 1)), new THREE.Vector3(0, 0, -1));
    return (face ?? level.clone().add(new THREE.Vector3(0, 0, 0.5 * headHeight))).add(
      new THREE.Vector3(0, 0, SURFACE_GAP_M));
  };
  return { head, headHeight, anchorAt };
}

export class ProceduralMouth {
  constructor(THREE, vrm, scene) {
    const { head, headHeight, anchorAt } = faceAnchor(THREE, vrm, scene);
    this.halfWidth = MOUTH_HALF_WIDTH_FRACTION * headHeight;
    this.mesh = new THREE.Mesh(new THREE.CircleGeometry(1, 40),
      new THREE.MeshBasicMaterial({ color: MOUTH_COLOR, side: THREE.DoubleSide }));
    this.mesh.name = "gesturecast-mouth";
    head.add(this.mesh);
    this.mesh.position.copy(head.worldToLocal(anchorAt(MOUTH_HEIGHT_FRACTION)));
    this.mesh.quaternion.copy(head.getWorldQuaternion(new THREE.Quaternion()).invert());  // faces +Z at rest
    this.setWeights([0, 0, 0, 0, 0]);
  }

  setWeights(weights) {
    const { opening, width } = mouthShape(weights);
    this.opening = opening;
    this.width = width;
    this.mesh.scale.set(this.halfWidth * width, this.halfWidth * opening, 1);
  }
}
