"""A gesture's imposed joints kept in the body's frame when the joints they hang from are generated.

A clip imposes the local rotations of the parts it moves; the parts above them stay generated. When the generated
parent leans another way than the recorded one, the same local rotations point the imposed limbs elsewhere:

- an arms-only clip (a wave, a cheer) on a generated chest: a wave's hands came out 8 cm lower than recorded and
  crept up instead of arriving;
- a clip of the arms and torso (a guide) on generated hips: the generator's hips lean about 28° further back than
  the proud guide take's, so the whole upper body leaned back, the arm came out 23 cm higher against the shoulder
  than recorded and reached its held-out pose 200 to 270 ms before the clip's stroke.

So the first imposed joint of each chain (a :data:`ROOTS` joint whose parents are generated) is re-attached: the
clip's rotation of it in the body frame (hips, facing removed, through the joints above it) is kept, and its local
rotation recomputed under the parents as blended (generated, or another playing clip's), ``local = parents⁻¹ ·
parents_clip · local_clip``, in proportion to the clip's share of the pose target (two clips cross-fading hand the
joint over smoothly). The joints below it keep the clip's local rotations. A clip that imposes the hips too (a bow)
keeps its own.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gesturecast.models.motion.body_parts import joint_columns
from gesturecast.models.motion.motion_features import FEATURE_DIM, ROOT_DIM, ROTATION_6D_DIM
from gesturecast.models.motion.rotations import matrix_from_6d, matrix_to_6d

CHAIN = ("Spine", "Chest", "UpperChest")  # under the shoulders, after the hips
HIPS_COLUMNS = np.arange(ROOT_DIM, ROOT_DIM + ROTATION_6D_DIM)  # the hips' rotation, facing removed
ROOTS = {"Spine": (), "LeftShoulder": CHAIN, "RightShoulder": CHAIN}  # joint -> the joints between it and the hips


def parent_rotation(features: np.ndarray, above: tuple[str, ...] = CHAIN) -> np.ndarray:
    """(n, D) motion features → (n, 3, 3) the rotation in the body frame of the last of ``above`` (the hips and the
    joints ``above`` composed; the hips alone when ``above`` is empty)."""
    rotation = matrix_from_6d(features[:, HIPS_COLUMNS].astype(np.float64))  # (n, 3, 3)
    for joint in above:
        rotation = rotation @ matrix_from_6d(features[:, joint_columns(joint)].astype(np.float64))
    return rotation


def body_frame_roots(features: np.ndarray, columns: np.ndarray) -> list[tuple[list[int], tuple[str, ...], np.ndarray]]:
    """The chains' first joints a clip imposes (its ``columns``) under generated parents, each as (its feature
    columns, the joints between it and the hips, (n, 3, 3) its rotation in the body frame) from the clip's (n, D)
    ``features``; [] when the clip imposes the hips too, or its features are not the canonical layout."""
    if columns.shape[0] != FEATURE_DIM or columns[HIPS_COLUMNS].any():
        return []
    found = []
    for joint, above in ROOTS.items():
        cols = joint_columns(joint)
        if columns[cols].all() and not any(columns[joint_columns(parent)].any() for parent in above):
            local = matrix_from_6d(features[:, cols].astype(np.float64))  # (n, 3, 3)
            found.append((cols, above, parent_rotation(features, above) @ local))
    return found


@dataclass(frozen=True)
class PlacedRoot:
    """One playing clip's re-attached joint over one latent's d frames: its feature columns, the joints between it
    and the hips, its (d, 3, 3) rotation in the body frame, its (d, 6) local rotation in the clip, and the clip's
    (d, 1) share of the pose target on those columns (its weight over the summed weights of the clips imposing
    them)."""

    columns: list[int]
    above: tuple[str, ...]
    body_frame: np.ndarray
    local: np.ndarray
    share: np.ndarray


def placed_roots(roots: list[tuple[list[int], tuple[str, ...], np.ndarray]], features: np.ndarray, frames: slice,
                 weight: np.ndarray, total: np.ndarray) -> list[PlacedRoot]:
    """A clip's ``roots`` (:func:`body_frame_roots` of its (N·d, D) ``features``) over its ``frames``, its share of
    the pose target being its (d, 1) ``weight`` over the (d, D) ``total`` of the playing clips' weights."""
    return [PlacedRoot(cols, above, body_frame[frames], features[frames][:, cols],
                       weight / np.maximum(total[:, cols[:1]], 1e-6)) for cols, above, body_frame in roots]


def reattach(features: np.ndarray, target: np.ndarray, weights: np.ndarray, roots: list[PlacedRoot]) -> np.ndarray:
    """(d, D) decoded ``features`` blended toward the (d, D) ``target`` by the (d, D) ``weights``, each root's part
    of the target (its clip's share) recomputed under its parents as blended (generated, or another clip's: a bow's
    torso under a wave's arms), the spine before the shoulders, so that its body-frame rotation is the clip's. Roots
    under the same parents (both shoulders, two clips' shoulder) share one parent rotation."""
    target = target.copy()
    blended = features + weights * (target - features)
    for above in sorted({root.above for root in roots}, key=len):
        inverse = np.swapaxes(parent_rotation(blended, above), -1, -2)  # (d, 3, 3)
        for root in (root for root in roots if root.above == above):
            cols, local = root.columns, inverse @ root.body_frame  # (d, 3, 3)
            target[:, cols] += root.share * (matrix_to_6d(local) - root.local)
            blended[:, cols] = features[:, cols] + weights[:, cols] * (target[:, cols] - features[:, cols])
    return blended
