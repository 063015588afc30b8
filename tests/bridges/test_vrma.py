"""The .vrma writer: a GLB whose JSON chunk maps every bone and whose accessors hold the frames written."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from bridge_test_frames import moving_frame

from gesturecast.bridges.gltf_binary import accessor_values, read_glb
from gesturecast.bridges.vrma import EXTENSION, FACE_PRESETS, FULL, VISEME_PRESETS, VrmaWriter, vrm_bone_name
from gesturecast.errors import UserError
from gesturecast.frames import PoseFrame
from gesturecast.models.motion.rotations import quat_from_axis_angle, quat_mul
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS as SKELETON
from gesturecast.models.motion.skeleton import Skeleton

FRAMES = 12


def written(tmp_path, frames, **options) -> tuple[dict, bytes]:
    path = tmp_path / f"take-{options.get('bones', 'default')}.vrma"
    with VrmaWriter(path, **options) as writer:
        writer.write(frames[: len(frames) // 2])
        writer.write(frames[len(frames) // 2:])
        writer.save()
    return read_glb(path.read_bytes())


def channels_by_target(document: dict) -> dict[tuple[int, str], int]:
    """(node, path) -> output accessor of its sampler."""
    animation = document["animations"][0]
    return {(c["target"]["node"], c["target"]["path"]): animation["samplers"][c["sampler"]]["output"]
            for c in animation["channels"]}


def test_every_bone_is_a_humanoid_node_with_its_rotations(tmp_path):
    frames = [moving_frame(i) for i in range(FRAMES)]
    document, binary = written(tmp_path, frames)
    extension = document["extensions"][EXTENSION]
    assert extension["specVersion"] == "1.0" and document["extensionsUsed"] == [EXTENSION]
    bones = extension["humanoid"]["humanBones"]
    assert len(bones) == SKELETON.num_joints and "expressions" not in extension
    channels = channels_by_target(document)
    for j, name in enumerate(SKELETON.names):
        node = bones[vrm_bone_name(name)]["node"]
        assert document["nodes"][node]["translation"] == pytest.approx(SKELETON.offsets[j].tolist())
        rotations = accessor_values(document, binary, channels[(node, "rotation")])  # (T, 4)
        np.testing.assert_allclose(rotations, [f.rotations[j] for f in frames], atol=1e-7)
    hips = accessor_values(document, binary, channels[(bones["hips"]["node"], "translation")])  # (T, 3)
    np.testing.assert_allclose(hips, [f.root_position for f in frames], atol=1e-6)


def test_times_are_thirty_frames_per_second_and_the_hierarchy_is_the_skeleton(tmp_path):
    document, binary = written(tmp_path, [moving_frame(i) for i in range(FRAMES)])
    sampler = document["animations"][0]["samplers"][0]
    np.testing.assert_allclose(accessor_values(document, binary, sampler["input"]), np.arange(FRAMES) / 30.0)
    assert document["accessors"][sampler["input"]]["max"] == pytest.approx([(FRAMES - 1) / 30.0])
    parents = {child: parent for parent, node in enumerate(document["nodes"]) for child in node.get("children", [])}
    assert [parents.get(j, -1) for j in range(SKELETON.num_joints)] == list(SKELETON.parents)
    assert vrm_bone_name("LeftThumbProximal") == "leftThumbMetacarpal"  # VRM 1.0 thumb names
    assert vrm_bone_name("LeftThumbIntermediate") == "leftThumbProximal"


def test_viseme_and_face_weights_become_preset_expression_nodes(tmp_path):
    weights = np.linspace(0.0, 1.0, FRAMES * 13).reshape(FRAMES, 13)  # (T, 5 visemes + 8 face)
    frames = [dataclasses.replace(moving_frame(i), visemes=weights[i, :5], face=weights[i, 5:]) for i in range(FRAMES)]
    frames[3] = moving_frame(3)  # a frame without weights: a closed mouth, open eyes, a neutral face
    weights[3] = 0.0
    document, binary = written(tmp_path, frames)
    presets = document["extensions"][EXTENSION]["expressions"]["preset"]
    assert list(presets) == [*VISEME_PRESETS, *FACE_PRESETS]
    assert FACE_PRESETS[:4] == ("blink", "blinkLeft", "blinkRight", "happy")  # VRM 1.0 preset names
    channels = channels_by_target(document)
    for k, name in enumerate([*VISEME_PRESETS, *FACE_PRESETS]):
        values = accessor_values(document, binary, channels[(presets[name]["node"], "translation")])  # (T, 3)
        np.testing.assert_allclose(values[:, 0], weights[:, k], atol=1e-7)
        assert not values[:, 1:].any()


def test_no_frames_is_an_error_and_no_file(tmp_path):
    with pytest.raises(UserError, match="no frames"), VrmaWriter(tmp_path / "empty.vrma") as writer:
        writer.save()
    assert not (tmp_path / "empty.vrma").exists()


UPPER_CHEST_DEG = 8.6  # the median UpperChest rotation of a generated take (the bundled sample)
HAND_TOLERANCE_M = 0.001


def bent_frames(count: int = FRAMES) -> list[PoseFrame]:
    """Every bone turned a little (seeded) and the upper chest by about 8.6°, as in a generated take."""
    rng = np.random.default_rng(7)
    frames = []
    for i in range(count):
        rotations = quat_from_axis_angle(rng.normal(0.0, 0.15, (SKELETON.num_joints, 3)))  # (J, 4)
        axis = rng.normal(size=3)
        rotations[SKELETON.index("UpperChest")] = quat_from_axis_angle(np.radians(UPPER_CHEST_DEG) * axis
                                                                        / np.linalg.norm(axis))
        frames.append(PoseFrame(i, 0.0, 0.0, SKELETON.offsets[0] + [0.0, 0.0, 0.01 * i], rotations))
    return frames


def file_rotations(document: dict, binary: bytes) -> dict[str, np.ndarray]:
    """VRM bone name -> its (T, 4) rotation track."""
    bones = document["extensions"][EXTENSION]["humanoid"]["humanBones"]
    channels = channels_by_target(document)
    return {name: accessor_values(document, binary, channels[(bone["node"], "rotation")])
            for name, bone in bones.items()}


def skeleton_rotations(tracks: dict[str, np.ndarray]) -> np.ndarray:
    """(T, J, 4) float64 local rotations of the 52-bone skeleton from a file's tracks."""
    return np.stack([tracks[vrm_bone_name(name)] for name in SKELETON.names], axis=1).astype(np.float64)


def upper_chest_and_above() -> list[int]:
    """UpperChest and every joint below it in the hierarchy (neck, head, shoulders, arms, hands, fingers)."""
    chosen = [SKELETON.index("UpperChest")]
    for j, parent in enumerate(SKELETON.parents):
        if parent in chosen:
            chosen.append(j)
    return chosen


def without_upper_chest() -> Skeleton:
    """The skeleton of an avatar with no upper chest (the bundled one): its children hang off the chest."""
    upper = SKELETON.index("UpperChest")
    keep = [j for j in range(SKELETON.num_joints) if j != upper]
    offsets = SKELETON.offsets.copy()
    parents = list(SKELETON.parents)
    for j in range(SKELETON.num_joints):
        if parents[j] == upper:
            parents[j], offsets[j] = SKELETON.parents[upper], offsets[upper] + offsets[j]
    new_index = {old: new for new, old in enumerate(keep)}
    return Skeleton(tuple(SKELETON.names[j] for j in keep), tuple(new_index.get(parents[j], -1) for j in keep),
                    offsets[keep])


def player_hands(tracks: dict[str, np.ndarray], roots: np.ndarray, avatar: Skeleton,
                 fold_missing: bool) -> np.ndarray:
    """(T, 2, 3) hand positions of ``avatar`` driven by a file's rotation tracks: a stock player skips the track of
    a bone the avatar lacks; ``fold_missing`` composes it into the parent instead, as the project's viewer does."""
    rotations = np.stack([tracks[vrm_bone_name(name)] for name in avatar.names], axis=1)  # (T, J', 4)
    if fold_missing:
        chest = avatar.index("Chest")
        rotations[:, chest] = quat_mul(rotations[:, chest], tracks["upperChest"])
    positions = avatar.forward_kinematics(rotations.astype(np.float64), roots)[1]  # (T, J', 3)
    return positions[:, [avatar.index("LeftHand"), avatar.index("RightHand")]]


def test_upper_chest_is_folded_into_the_chest_by_default(tmp_path):
    """A stock VRMA player on an avatar without an upper chest skips that track: the folded file (the default) puts
    the rotation into the chest, so the hands land within 1 mm of where the full file puts them with the upper
    chest folded in by the viewer, and every bone from the upper chest up keeps its world rotation."""
    frames = bent_frames()
    full = file_rotations(*written(tmp_path, frames, bones=FULL))
    folded = file_rotations(*written(tmp_path, frames))
    np.testing.assert_allclose(np.abs((folded["chest"] * quat_mul(full["chest"], full["upperChest"])).sum(-1)), 1.0,
                               atol=1e-6)  # Chest' = Chest · UpperChest
    np.testing.assert_allclose(folded["upperChest"], np.tile([0.0, 0.0, 0.0, 1.0], (FRAMES, 1)), atol=1e-7)
    roots = np.stack([f.root_position for f in frames])  # (T, 3)
    avatar = without_upper_chest()
    intended = player_hands(full, roots, avatar, fold_missing=True)
    stock_folded = player_hands(folded, roots, avatar, fold_missing=False)
    stock_full = player_hands(full, roots, avatar, fold_missing=False)  # what stock players did with every file
    assert np.linalg.norm(stock_folded - intended, axis=-1).max() < HAND_TOLERANCE_M
    assert np.linalg.norm(stock_full - intended, axis=-1).max() > 0.02
    world_full = SKELETON.forward_kinematics(skeleton_rotations(full))[0]  # (T, J, 4)
    world_folded = SKELETON.forward_kinematics(skeleton_rotations(folded))[0]
    above = upper_chest_and_above()
    assert len(above) == 1 + 2 + 2 * (4 + 15)  # upper chest, neck, head, per side shoulder to hand and 15 fingers
    np.testing.assert_allclose(np.abs((world_full[:, above] * world_folded[:, above]).sum(-1)), 1.0, atol=1e-6)


def test_full_keeps_every_bone_as_generated_and_a_wrong_choice_is_refused(tmp_path):
    frames = bent_frames()
    full = file_rotations(*written(tmp_path, frames, bones=FULL))
    for j, name in enumerate(SKELETON.names):
        np.testing.assert_allclose(full[vrm_bone_name(name)], [f.rotations[j] for f in frames], atol=1e-7)
    with pytest.raises(UserError, match="--vrma-bones"):
        VrmaWriter(tmp_path / "x.vrma", bones="half")
