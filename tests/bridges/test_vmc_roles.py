"""Which bones a VMC sender includes: presets and comma lists, with one-line errors for unknown names."""

import pytest

from gesturecast.bridges.vmc_roles import HEAD_AND_LEGS, BoneSelection
from gesturecast.errors import UserError
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS as SKELETON


def test_presets():
    assert BoneSelection.parse("all", SKELETON).names == SKELETON.names
    assert BoneSelection.parse("none", SKELETON).names == ()
    upper = BoneSelection.parse("upper", SKELETON).names
    assert "Spine" in upper and "LeftHand" in upper and not set(upper) & set(HEAD_AND_LEGS)
    arms = BoneSelection.parse("arms", SKELETON).names
    assert "LeftShoulder" in arms and "RightLittleDistal" in arms and "Spine" not in arms
    assert not [name for name in arms if "Leg" in name or "Foot" in name]


def test_comma_list_keeps_skeleton_order():
    assert BoneSelection.parse("RightHand, Spine", SKELETON).names == ("Spine", "RightHand")


@pytest.mark.parametrize("spec", ["Tail", "Spine,Wing", ","])
def test_unknown_bones_are_a_user_error(spec):
    with pytest.raises(UserError, match="--vmc-bones"):
        BoneSelection.parse(spec, SKELETON)
