"""Solving a source skeleton's T-pose: the per-joint alignment onto the canonical skeleton.

For each canonical joint c driven by source joint d (the last of its chain), retargeting is

    G_c(t) = G_d(t) · T_d⁻¹,        local_c = G_parent(c)⁻¹ · G_c

where G are global rotations and T_d is d's global rotation when the source stands in the
canonical T-pose, so that the source T-pose maps to identity.

* If the source's identity pose already is a T-pose (every mapped bone within
  :data:`TPOSE_TOLERANCE_DEG` of the canonical bone direction: ZeroEGGS, Mixamo, CMU), T = identity.
* Otherwise (e.g. Bandai Namco, whose offsets lie along each bone's local X axis) T_d is
  solved from bone directions: the bone towards the mapped child must point along the
  canonical bone. The twist about the bone comes from a second reference direction:
  - joints with several mapped children (Hips, the chest): the left-minus-right child vector;
  - a bone continuing a chain bone (elbow, wrist, knee, ankle, head): the smallest rotation
    from its parent's T-pose frame (rigs keep one axis convention along a limb);
  - a bone leaving a branching joint (spine, thighs, clavicles, neck), where rigs often switch
    axis conventions: the source local axis that points along a canonical reference axis
    (forward, else up) in the T-pose. The axis is picked by first estimating the twist from the
    motion (the mean twist of the joint's canonical local rotation is taken as zero; these
    joints move little), then the rotation is solved exactly from the bone and that axis.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gesturecast.errors import UserError
from gesturecast.models.motion.joint_maps import JointMap
from gesturecast.models.motion.rotations import (
    quat_between,
    quat_conj,
    quat_from_axis_angle,
    quat_from_matrix,
    quat_identity,
    quat_mul,
    quat_normalize,
    quat_rotate,
)
from gesturecast.models.motion.skeleton import CANONICAL, END_SITES

TPOSE_TOLERANCE_DEG = 35.0
# candidate reference directions for the twist of a single-chain bone, in order of preference:
# forward (+Z), then up (+Y); the first one not close to parallel with the bone is used
TWIST_REFERENCES = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0]])
PARALLEL_COSINE = 0.7
_MIN_LENGTH = 1e-9


@dataclass(frozen=True)
class SourceSkeleton:
    """A source hierarchy at its identity pose: names (namespace stripped), parents, offsets (J, 3), tips (J, 3).

    A tip is the vector from a joint to the end of its bone when it has no mapped child: its
    End Site, or the mean of its children's offsets.
    """

    names: list[str]
    parents: np.ndarray
    offsets: np.ndarray
    tips: np.ndarray

    def index(self, name: str) -> int:
        return self.names.index(name)

    def vector(self, start: int, end: int) -> np.ndarray:
        """From joint ``start`` to its descendant ``end``, in ``start``'s frame at the identity pose."""
        total = np.zeros(3)
        j = end
        while j != start:
            if j < 0:
                raise UserError(f"joint map: source joint '{self.names[end]}' is not below '{self.names[start]}'")
            total += self.offsets[j]
            j = int(self.parents[j])
        return total


def joint_tips(parents: np.ndarray, offsets: np.ndarray, end_sites: dict[int, np.ndarray]) -> np.ndarray:
    """Tip vector per joint: its End Site if that has length, else the mean of its non-zero child
    offsets, else its own offset (the bone goes on straight)."""
    tips = offsets.copy()
    for j in range(len(parents)):
        site = end_sites.get(j)
        children = [offsets[c] for c in np.flatnonzero(parents == j) if np.linalg.norm(offsets[c]) > _MIN_LENGTH]
        if site is not None and np.linalg.norm(site) > _MIN_LENGTH:
            tips[j] = site
        elif children:
            tips[j] = np.mean(children, axis=0)
    return tips


@dataclass(frozen=True)
class MappedSkeleton:
    """A source skeleton with a joint map resolved to indices (-1 where a canonical joint has no source)."""

    source: SourceSkeleton
    first: np.ndarray  # (J_canonical,) source joint giving the position
    driver: np.ndarray  # (J_canonical,) source joint giving the rotation

    @classmethod
    def build(cls, source: SourceSkeleton, joint_map: JointMap) -> MappedSkeleton:
        chains = [joint_map.chain(name) for name in CANONICAL.names]
        first = np.array([source.index(chain[0]) if chain else -1 for chain in chains])
        driver = np.array([source.index(chain[-1]) if chain else -1 for chain in chains])
        return cls(source, first, driver)

    def mapped_parent(self, c: int) -> int:
        """The nearest canonical ancestor of ``c`` that has a source joint (-1 above the root)."""
        p = CANONICAL.parents[c]
        while p >= 0 and self.driver[p] < 0:
            p = CANONICAL.parents[p]
        return p

    def mapped_children(self, c: int) -> list[int]:
        return [k for k in range(CANONICAL.num_joints) if self.driver[k] >= 0 and self.mapped_parent(k) == c]

    def primary_child(self, c: int) -> int:
        """The mapped child closest to the midline (the spine side of a branching joint), -1 if none."""
        children = self.mapped_children(c)
        return min(children, key=lambda k: abs(CANONICAL.offsets[k][0])) if children else -1

    def bone_pairs(self, c: int) -> list[tuple[np.ndarray, np.ndarray, int]]:
        """(source vector in the driver's frame, canonical vector, canonical child or -1 for a tip) per bone."""
        d = self.driver[c]
        pairs = [(self.source.vector(d, self.first[k]), _canonical_vector(c, k), k) for k in self.mapped_children(c)]
        # zero-length bones (CMU puts LowerBack, Neck and the shoulders on their parent) carry no direction
        pairs = [pair for pair in pairs if min(np.linalg.norm(pair[0]), np.linalg.norm(pair[1])) > _MIN_LENGTH]
        name = CANONICAL.names[c]
        if not pairs and name in END_SITES and np.linalg.norm(self.source.tips[d]) > _MIN_LENGTH:
            pairs.append((self.source.tips[d], np.asarray(END_SITES[name]), -1))
        return pairs


def _canonical_vector(c: int, k: int) -> np.ndarray:
    total = np.zeros(3)
    while k != c:
        total += CANONICAL.offsets[k]
        k = CANONICAL.parents[k]
    return total


def _angle_deg(u: np.ndarray, v: np.ndarray) -> float:
    cosine = np.dot(u, v) / max(np.linalg.norm(u) * np.linalg.norm(v), _MIN_LENGTH)
    return float(np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0))))


def rest_is_tpose(mapped: MappedSkeleton) -> bool:
    """Whether every mapped chain bone (limbs, spine, neck) at the source's identity pose points along
    its canonical bone. End Sites (often arbitrary) and branching offsets (hips to thighs, chest to
    shoulders: CMU's thigh offsets point 55 degrees down) vary too much between rigs and are left out."""
    chain_pairs = [pairs[0] for c in range(CANONICAL.num_joints) if mapped.driver[c] >= 0
                   for pairs in [mapped.bone_pairs(c)] if len(pairs) == 1]
    return all(_angle_deg(src, canon) < TPOSE_TOLERANCE_DEG for src, canon, child in chain_pairs if child >= 0)


def align_two_directions(a1: np.ndarray, b1: np.ndarray, a2: np.ndarray, b2: np.ndarray) -> np.ndarray:
    """TRIAD: the rotation taking a1 exactly onto b1's direction and a2 into the half-plane of (b1, b2). -> (4,)"""

    def frame(u: np.ndarray, v: np.ndarray) -> np.ndarray:
        x = u / np.linalg.norm(u)
        z = np.cross(x, v)
        z /= np.linalg.norm(z)
        return np.stack([x, np.cross(z, x), z], axis=-1)  # columns

    return quat_from_matrix(frame(b1, b2) @ frame(a1, a2).T)


def _is_parallel(u: np.ndarray, v: np.ndarray) -> bool:
    return abs(np.dot(u, v)) > PARALLEL_COSINE * np.linalg.norm(u) * np.linalg.norm(v)


def _branch_alignment(pairs: list[tuple[np.ndarray, np.ndarray, int]]) -> np.ndarray | None:
    """Two-direction solve for a joint with several mapped children; None when they give no twist."""
    by_x = sorted(pairs, key=lambda pair: pair[1][0])
    src1, canon1, _ = min(pairs, key=lambda pair: abs(pair[1][0]))  # the midline child, as primary_child
    src2, canon2 = by_x[-1][0] - by_x[0][0], by_x[-1][1] - by_x[0][1]
    if _is_parallel(src2, src1) or _is_parallel(canon2, canon1):
        return None
    return align_two_directions(src1, canon1, src2, canon2)


def _twist_reference(bone: np.ndarray) -> np.ndarray:
    return next(ref for ref in TWIST_REFERENCES if not _is_parallel(ref, bone))


def _chain_alignment(
    src: np.ndarray, canon: np.ndarray, driver_global: np.ndarray, parent_canonical_global: np.ndarray
) -> np.ndarray:
    """Solve T for a single-chain bone: exact bone direction, twist from the motion then snapped to a local axis.

    driver_global: (T, 4) source global rotations of the driver; parent_canonical_global: (T, 4).
    """
    axis = canon / np.linalg.norm(canon)
    reference = _twist_reference(canon)
    helper = next(ref for ref in np.eye(3) if not _is_parallel(ref, src))
    untwisted = align_two_directions(src, canon, helper, reference)
    local = quat_normalize(
        quat_mul(quat_conj(parent_canonical_global), quat_mul(driver_global, quat_conj(untwisted)))
    )  # (T, 4) canonical local rotation before the twist correction
    half = np.arctan2(-np.sum(local[:, :3] @ axis), np.sum(local[:, 3]))
    estimate = quat_mul(quat_from_axis_angle(-2.0 * half * axis), untwisted)
    candidates = np.concatenate([np.eye(3), -np.eye(3)])
    candidates = np.array([a for a in candidates if not _is_parallel(a, src)])
    world = np.array([quat_rotate(estimate, a) for a in candidates])
    local_axis = candidates[np.argmax(world @ reference)]
    return align_two_directions(src, canon, local_axis, reference)


def _inherited_alignment(src: np.ndarray, canon: np.ndarray, parent_tpose: np.ndarray) -> np.ndarray:
    """T for a bone continuing a chain bone: the smallest local rotation from the parent's T-pose frame."""
    target_in_parent = quat_rotate(quat_conj(parent_tpose), canon)
    return quat_mul(parent_tpose, quat_between(src, target_in_parent))


def solve_tpose(mapped: MappedSkeleton, source_global: np.ndarray) -> np.ndarray:
    """Source global rotations T (J_canonical, 4) of each canonical joint's driver in the T-pose.

    source_global: (T, J_source, 4) global rotations of the source motion (used only for twist
    when the rest pose is not a T-pose). Rows of unmapped canonical joints are identity.
    """
    tpose = quat_identity((CANONICAL.num_joints,))
    if rest_is_tpose(mapped):
        return tpose
    canonical_global = quat_identity((source_global.shape[0], CANONICAL.num_joints))  # (T, J, 4)
    for c in range(CANONICAL.num_joints):
        d = mapped.driver[c]
        if d < 0:
            continue
        pairs = mapped.bone_pairs(c)
        if not pairs:
            raise UserError(f"cannot solve the rest pose of source joint '{mapped.source.names[d]}': "
                            "it has no mapped child and no End Site")
        solved = _branch_alignment(pairs) if len(pairs) > 1 else None
        p = mapped.mapped_parent(c)
        if solved is None and p >= 0 and len(mapped.bone_pairs(p)) == 1:
            solved = _inherited_alignment(pairs[0][0], pairs[0][1], tpose[p])
        if solved is None:
            parent_global = canonical_global[:, p] if p >= 0 else quat_identity((source_global.shape[0],))
            solved = _chain_alignment(pairs[0][0], pairs[0][1], source_global[:, d], parent_global)
        tpose[c] = solved
        canonical_global[:, c] = quat_mul(source_global[:, d], quat_conj(solved))
    return tpose


def tpose_positions(mapped: MappedSkeleton, tpose: np.ndarray) -> np.ndarray:
    """Canonical joint positions (J, 3) of the source standing in its T-pose, source units, Hips at 0.

    Unmapped canonical joints sit on their parent.
    """
    positions = np.zeros((CANONICAL.num_joints, 3))
    for c in range(1, CANONICAL.num_joints):
        p = CANONICAL.parents[c]
        if mapped.driver[c] < 0:
            positions[c] = positions[p]
            continue
        q = mapped.mapped_parent(c)
        bone = mapped.source.vector(mapped.first[q], mapped.first[c])
        positions[c] = positions[q] + quat_rotate(tpose[q], bone)
    return positions


def hip_height(positions: np.ndarray) -> float:
    """Height of the Hips (canonical joint 0) above the lowest joint, for joint positions (J, 3)."""
    return float(positions[0, 1] - positions[:, 1].min())


def tpose_hip_height(mapped: MappedSkeleton, tpose: np.ndarray) -> float:
    """Hip height of the source standing in its T-pose (source units): the leg length that scales the root."""
    return hip_height(tpose_positions(mapped, tpose))
