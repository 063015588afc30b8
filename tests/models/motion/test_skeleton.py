import numpy as np

from gesturecast.models.motion.rotations import quat_identity, quat_normalize
from gesturecast.models.motion.skeleton import CANONICAL, CANONICAL_JOINTS

UNITY_BODY_BONES = {
    "Hips", "Spine", "Chest", "UpperChest", "Neck", "Head",
    "LeftShoulder", "LeftUpperArm", "LeftLowerArm", "LeftHand",
    "RightShoulder", "RightUpperArm", "RightLowerArm", "RightHand",
    "LeftUpperLeg", "LeftLowerLeg", "LeftFoot", "LeftToes",
    "RightUpperLeg", "RightLowerLeg", "RightFoot", "RightToes",
}


def test_canonical_names_are_unity_humanbodybones():
    assert set(CANONICAL_JOINTS) == UNITY_BODY_BONES
    assert all(p < j for j, p in enumerate(CANONICAL.parents))


def test_rest_pose_is_t_pose_facing_plus_z():
    _, pos = CANONICAL.forward_kinematics(quat_identity((CANONICAL.num_joints,)))
    left_hand, right_hand = pos[CANONICAL.index("LeftHand")], pos[CANONICAL.index("RightHand")]
    assert left_hand[0] > 0.5 and right_hand[0] < -0.5  # arms along ±X, left = +X
    assert abs(left_hand[1] - right_hand[1]) < 1e-9
    toes = pos[CANONICAL.index("LeftToes")] - pos[CANONICAL.index("LeftFoot")]
    assert toes[2] > 0  # feet point forward (+Z)
    assert 1.5 < CANONICAL.height() < 1.9


def test_forward_kinematics_keeps_bone_lengths():
    rotations = quat_normalize(np.random.default_rng(0).normal(size=(50, CANONICAL.num_joints, 4)))
    _, pos = CANONICAL.forward_kinematics(rotations, np.zeros((50, 3)))
    for j, p in enumerate(CANONICAL.parents):
        if p >= 0:
            lengths = np.linalg.norm(pos[:, j] - pos[:, p], axis=-1)
            np.testing.assert_allclose(lengths, np.linalg.norm(CANONICAL.offsets[j]), atol=1e-12)


def test_mirror_indices_are_an_involution():
    m = CANONICAL.mirror_indices()
    np.testing.assert_array_equal(m[m], np.arange(CANONICAL.num_joints))
    assert CANONICAL_JOINTS[m[CANONICAL.index("LeftHand")]] == "RightHand"
