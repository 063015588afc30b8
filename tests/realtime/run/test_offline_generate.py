"""`generate -o FILE` picks its writer by the file name: .vrma → VRM Animation, anything else → BVH; a .vrma
has its upper chest folded into the chest unless `--vrma-bones full`; BVH files alone skip lip sync and face."""

from __future__ import annotations

import numpy as np
import pytest
import soundfile

from gesturecast.bridges.gltf_binary import accessor_values, read_glb
from gesturecast.bridges.vrma import EXTENSION
from gesturecast.cli import build_parser, run_command
from gesturecast.errors import UserError
from gesturecast.frames import PoseFrame
from gesturecast.models.audio.files import PACKAGED_SAMPLE, SAMPLE_RATE, load_audio
from gesturecast.models.motion.bvh import read_bvh
from gesturecast.models.motion.rotations import quat_mul
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS
from gesturecast.realtime.cli_flags import settings_from_args
from gesturecast.realtime.run.offline_generate import BvhFrameWriter, body_only, motion_writer
from gesturecast.settings import FACE_OFF, LIPSYNC_OFF

FRAMES = 5


def t_pose(seq: int) -> PoseFrame:
    rotations = np.tile([0.0, 0.0, 0.0, 1.0], (CANONICAL_WITH_HANDS.num_joints, 1))  # (J, 4)
    return PoseFrame(seq, seq / 30.0, seq / 30.0, CANONICAL_WITH_HANDS.offsets[0].copy(), rotations)


@pytest.mark.parametrize("name", ["take.vrma", "TAKE.VRMA", "take.bvh"])
def test_the_suffix_chooses_the_format(tmp_path, name):
    path = tmp_path / name
    with motion_writer(path) as writer:
        writer.write([t_pose(i) for i in range(FRAMES)])
        writer.save()
    if name.lower().endswith(".vrma"):
        document, _ = read_glb(path.read_bytes())
        assert document["accessors"][0]["count"] == FRAMES
    else:
        assert isinstance(writer, BvhFrameWriter) and read_bvh(path).motion.shape[0] == FRAMES


@pytest.mark.parametrize("name", ["take", "take.glb", "take.txt"])
def test_an_unknown_suffix_is_refused_before_anything_is_written(tmp_path, name):
    with pytest.raises(UserError, match=r"name a \.bvh or \.vrma file"):
        motion_writer(tmp_path / name)
    assert list(tmp_path.iterdir()) == []


def rotation_tracks(path) -> dict[str, np.ndarray]:
    """VRM bone name -> (T, 4) rotation track of a .vrma."""
    document, binary = read_glb(path.read_bytes())
    samplers = document["animations"][0]["samplers"]
    outputs = {(c["target"]["node"], c["target"]["path"]): samplers[c["sampler"]]["output"]
               for c in document["animations"][0]["channels"]}
    bones = document["extensions"][EXTENSION]["humanoid"]["humanBones"]
    return {name: accessor_values(document, binary, outputs[(bone["node"], "rotation")])
            for name, bone in bones.items()}


def test_generate_folds_the_upper_chest_unless_vrma_bones_full(tmp_path):
    speech = tmp_path / "speech.wav"
    soundfile.write(speech, load_audio(PACKAGED_SAMPLE)[: 2 * SAMPLE_RATE], SAMPLE_RATE, subtype="FLOAT")
    for name, extra in (("folded.vrma", []), ("full.vrma", ["--vrma-bones", "full"])):
        args = build_parser().parse_args(["generate", str(speech), "-o", str(tmp_path / name), *extra])
        assert run_command(args) == 0
    folded, full = rotation_tracks(tmp_path / "folded.vrma"), rotation_tracks(tmp_path / "full.vrma")
    assert np.median(np.degrees(2 * np.arccos(np.abs(full["upperChest"][:, 3])))) > 3.0  # a generated upper chest
    product = quat_mul(full["chest"], full["upperChest"])  # (T, 4)
    np.testing.assert_allclose(np.abs((folded["chest"] * product).sum(axis=-1)), 1.0, atol=1e-6)
    np.testing.assert_allclose(folded["upperChest"][:, 3], 1.0, atol=1e-7)
    np.testing.assert_array_equal(folded["leftUpperArm"], full["leftUpperArm"])


def test_vrma_bones_full_is_refused_with_a_batch(tmp_path, capsys):
    args = build_parser().parse_args(["generate", "--batch", str(tmp_path), "-o", str(tmp_path / "out"),
                                      "--vrma-bones", "full"])
    assert run_command(args) == 2
    assert "--vrma-bones full is for one file" in capsys.readouterr().err


def test_a_bvh_alone_skips_lip_sync_and_face_and_is_the_same_file(tmp_path):
    speech = tmp_path / "speech.wav"
    soundfile.write(speech, load_audio(PACKAGED_SAMPLE)[: 3 * SAMPLE_RATE], SAMPLE_RATE, subtype="FLOAT")
    base = build_parser().parse_args(["generate", str(speech), "-o", "x.bvh"])
    settings = settings_from_args(base)
    assert (settings.lipsync, settings.face) != (LIPSYNC_OFF, FACE_OFF)  # the defaults fill visemes and face
    alone = body_only(settings, [tmp_path / "a.bvh"], None)
    assert (alone.lipsync, alone.face) == (LIPSYNC_OFF, FACE_OFF)
    for keeps in (([tmp_path / "a.bvh"], tmp_path / "a.json"), ([tmp_path / "a.bvh", tmp_path / "a.vrma"], None)):
        assert body_only(settings, *keeps) == settings  # a JSON or a .vrma carries visemes and face weights
    for name, extra in (("alone.bvh", []), ("with_json.bvh", ["--json", str(tmp_path / "with.json")])):
        args = build_parser().parse_args(["generate", str(speech), "-o", str(tmp_path / name), *extra])
        assert run_command(args) == 0
    assert (tmp_path / "alone.bvh").read_bytes() == (tmp_path / "with_json.bvh").read_bytes()
