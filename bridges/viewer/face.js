// Drawn eyes and brows for avatars without blink and emotion expressions (the default cryptovoxels.vrm has none):
// two dark ellipses and two flat ones above them on the face, attached to the head bone like the drawn mouth (mouth.js). The
// eyes close with the blink weight (and narrow a little with a smile); the brows lower their inner ends for
// anger, raise them for sadness, and lift for surprise.
import { faceAnchor } from "./mouth.js";

const EYE_COLOR = 0x14161c;
const BROW_COLOR = 0x2b2118;
const EYE_HEIGHT_FRACTION = 0.55;  // of the head (head bone to top of the head), above the head bone
const EYE_SPACING_FRACTION = 0.17;  // each eye's distance from the middle, of the head's height
const EYE_RADIUS_FRACTION = 0.045;
const BROW_RISE_FRACTION = 0.09;  // the brows above the eyes
const BROW_HALF_LENGTH_FRACTION = 0.065;
const BROW_THICKNESS_FRACTION = 0.015;
const OPEN_EYE = 1.0;  // height / width of an open eye
const MAX_BROW_TILT = 0.45;  // radians
const SURPRISE_LIFT_FRACTION = 0.05;

// Eye opening (height / width), brow tilt (radians, inner end up > 0) and lift (fraction of the head) from the
// face weights [blink, blinkLeft, blinkRight, happy, angry, sad, relaxed, surprised].
export function faceShape([blink, , , happy, angry, sad, relaxed, surprised]) {
  const squint = 1 - 0.35 * happy - 0.2 * relaxed;
  const opening = OPEN_EYE * Math.max(0.04, (1 - blink) * Math.min(1.2, squint + 0.2 * surprised));
  const tilt = MAX_BROW_TILT * Math.max(-1, Math.min(1, sad - angry));
  const lift = SURPRISE_LIFT_FRACTION * surprised;
  return { opening, tilt, lift };
}

function disc(THREE, color) {
  return new THREE.Mesh(new THREE.CircleGeometry(1, 32), new THREE.MeshBasicMaterial({ color, side: THREE.DoubleSide }));
}

export class ProceduralFace {
  constructor(THREE, vrm, scene) {
    const { head, headHeight, anchorAt } = faceAnchor(THREE, vrm, scene);
    this.headHeight = headHeight;
    this.radius = EYE_RADIUS_FRACTION * headHeight;
    this.eyes = [-1, 1].map((side) => this.attach(head, disc(THREE, EYE_COLOR), anchorAt(EYE_HEIGHT_FRACTION,
      side * EYE_SPACING_FRACTION), `gesturecast-eye-${side < 0 ? "right" : "left"}`));
    this.brows = [-1, 1].map((side) => {
      const brow = disc(THREE, BROW_COLOR);  // a flat ellipse (the viewer's three.js bundle has discs, no planes)
      brow.userData.side = side;
      return this.attach(head, brow, anchorAt(EYE_HEIGHT_FRACTION + BROW_RISE_FRACTION, side * EYE_SPACING_FRACTION),
        `gesturecast-brow-${side < 0 ? "right" : "left"}`);
    });
    this.rest = this.brows.map((brow) => brow.position.clone());
    this.turn = new THREE.Quaternion();
    this.zAxis = new THREE.Vector3(0, 0, 1);
    this.setWeights([0, 0, 0, 0, 0, 0, 0, 0]);
  }

  attach(head, mesh, anchor, name) {
    mesh.name = name;
    head.add(mesh);
    mesh.position.copy(head.worldToLocal(anchor));
    mesh.quaternion.copy(head.getWorldQuaternion(mesh.quaternion.clone()).invert());  // faces +Z at rest
    mesh.userData.facing = mesh.quaternion.clone();
    return mesh;
  }

  setWeights(weights) {
    const { opening, tilt, lift } = faceShape(weights);
    this.opening = opening;
    this.tilt = tilt;
    for (const eye of this.eyes) eye.scale.set(this.radius, this.radius * opening, 1);
    this.brows.forEach((brow, k) => {
      const side = brow.userData.side;  // the inner end is toward the middle: tilt turns the two brows apart
      brow.scale.set(BROW_HALF_LENGTH_FRACTION * this.headHeight, BROW_THICKNESS_FRACTION * this.headHeight, 1);
      brow.quaternion.copy(brow.userData.facing).multiply(this.turn.setFromAxisAngle(this.zAxis, -side * tilt));
      brow.position.copy(this.rest[k]);
      brow.position.y += lift * this.headHeight;
    });
  }
}
