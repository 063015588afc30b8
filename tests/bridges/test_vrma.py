"""The .vrma writer: a GLB whose JSON chunk maps every bone and whose accessors hold the frames written."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from bridge_test_frames import moving_frame

from gesturecast.bridges.gltf_binary import accessor_values, read_glb
from gesturecast.bridges.vrma import EXPRESSION_PRESETS, EXTENSION, VrmaWriter, vrm_bone_name
from gesturecast.errors import UserError
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS as SKELETON

FRAMES = 12


def written(tmp_path, frames) -> tuple[dict, bytes]:
    path = tmp_path / "take.vrma"
    with VrmaWriter(path) as writer:
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


def test_viseme_weights_become_preset_expression_nodes(tmp_path):
    weights = np.linspace(0.0, 1.0, FRAMES * 5).reshape(FRAMES, 5)  # (T, 5)
    frames = [dataclasses.replace(moving_frame(i), visemes=weights[i]) for i in range(FRAMES)]
    frames[3] = moving_frame(3)  # a frame without weights: a closed mouth
    weights[3] = 0.0
    document, binary = written(tmp_path, frames)
    presets = document["extensions"][EXTENSION]["expressions"]["preset"]
    assert list(presets) == list(EXPRESSION_PRESETS)
    channels = channels_by_target(document)
    for k, name in enumerate(EXPRESSION_PRESETS):
        values = accessor_values(document, binary, channels[(presets[name]["node"], "translation")])  # (T, 3)
        np.testing.assert_allclose(values[:, 0], weights[:, k], atol=1e-7)
        assert not values[:, 1:].any()


def test_no_frames_is_an_error_and_no_file(tmp_path):
    with pytest.raises(UserError, match="no frames"), VrmaWriter(tmp_path / "empty.vrma") as writer:
        writer.save()
    assert not (tmp_path / "empty.vrma").exists()
