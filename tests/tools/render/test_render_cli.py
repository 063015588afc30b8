"""`gesturecast render` glue: raw BVH forward kinematics, time selection, errors, a real take."""

import argparse

import numpy as np
import pytest
from PIL import Image

from gesturecast.errors import UserError
from gesturecast.models.motion.rotations import quat_from_axis_angle
from gesturecast.models.motion.skeleton import CANONICAL
from gesturecast.tools.render import render_command as render_cli


def parse(argv: list[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser()
    render_cli.register(parser.add_subparsers())
    return parser.parse_args(["render", *argv])


def test_bvh_forward_kinematics_matches_the_skeleton_when_translations_are_the_offsets():
    rng = np.random.default_rng(2)
    rotations = quat_from_axis_angle(rng.normal(size=(4, CANONICAL.num_joints, 3)))  # (T, J, 4)
    translations = np.repeat(CANONICAL.offsets[None], 4, axis=0)  # (T, J, 3)
    translations[:, 0] = rng.normal(size=(4, 3))  # root position channels
    expected = CANONICAL.forward_kinematics(rotations, translations[:, 0])[1]
    got = render_cli.bvh_positions(rotations, translations, np.array(CANONICAL.parents))
    assert np.allclose(got, expected, atol=1e-12)


def test_time_range_and_stride_selection():
    positions = np.zeros((300, 2, 3))
    assert len(render_cli.select_time_range(positions, 30.0, 2.0, 3.0)[1]) == 90
    assert render_cli.select_time_range(positions, 30.0, 9.0, None)[0] == 270
    assert len(render_cli.select_time_range(positions, 30.0, 9.0, None)[1]) == 30
    with pytest.raises(UserError, match="select no frames"):
        render_cli.select_time_range(positions, 30.0, 10.0, None)
    assert render_cli.auto_stride(2065, parse(["x.bvh", "-o", "a.gif"]).output) == 3
    assert render_cli.auto_stride(2065, parse(["x.bvh", "-o", "a.png"]).output) == 1


def test_bad_inputs_are_one_line_user_errors(tmp_path):
    npz = tmp_path / "take.npz"
    npz.write_bytes(b"")
    with pytest.raises(UserError, match="does not exist"):
        render_cli.run_render(parse([str(tmp_path / "missing.bvh"), "-o", str(tmp_path / "a.gif")]))
    with pytest.raises(UserError, match="BVH files only"):
        render_cli.run_render(parse([str(npz), "-o", str(tmp_path / "a.gif"), "--raw"]))


def test_raw_render_of_the_real_zeroeggs_take(shared_data, tmp_path):
    take = shared_data / "zeggs" / "067_Speech_2_x_1_0.bvh"
    out = tmp_path / "zeggs.gif"
    assert render_cli.run_render(parse([str(take), "-o", str(out), "--raw", "--start", "10", "--seconds", "1"])) == 0
    with Image.open(out) as gif:
        assert gif.n_frames == 30


def test_joint_map_file_renders_a_skeleton_that_is_not_detected(tmp_path):
    import json
    import re

    from gesturecast.models.motion.motion import SkeletonMotion
    from gesturecast.models.motion.retarget import motion_to_bvh

    rotations = quat_from_axis_angle(np.random.default_rng(3).normal(0, 0.3, size=(6, CANONICAL.num_joints, 3)))
    canonical = tmp_path / "canonical.bvh"
    motion_to_bvh(SkeletonMotion(rotations, np.tile(CANONICAL.offsets[0], (6, 1))), canonical)
    custom = tmp_path / "custom.bvh"
    custom.write_text(re.sub(r"(ROOT|JOINT) (\w+)", r"\1 rig_\2", canonical.read_text()))
    with pytest.raises(UserError, match="unknown skeleton layout"):
        render_cli.run_render(parse([str(custom), "-o", str(tmp_path / "x.png")]))
    joint_map = tmp_path / "map.json"
    joint_map.write_text(json.dumps({name: [f"rig_{name}"] for name in CANONICAL.names}))
    render_cli.run_render(parse([str(custom), "-o", str(tmp_path / "ok.png"), "--joint-map", str(joint_map)]))
    assert Image.open(tmp_path / "ok.png").size[0] > 0


def test_focus_on_a_hand_of_our_own_bvh_draws_its_fingers_zoomed(tmp_path):
    """A BVH written by gesturecast keeps its 52 joints when drawn; --focus LeftHand draws the hand alone, so it
    fills the panel (the whole figure's hand is a few pixels wide); an unknown joint is a one-line error."""
    from gesturecast.models.motion.motion import SkeletonMotion
    from gesturecast.models.motion.retarget import motion_to_bvh
    from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS

    rng = np.random.default_rng(5)
    rotations = quat_from_axis_angle(rng.normal(0.0, 0.2, size=(6, CANONICAL_WITH_HANDS.num_joints, 3)))
    root = np.tile(CANONICAL_WITH_HANDS.offsets[0], (6, 1))  # (T, 3)
    motion_to_bvh(SkeletonMotion(rotations, root, skeleton=CANONICAL_WITH_HANDS), tmp_path / "hands.bvh")
    ink = {}
    for focus in (None, "LeftHand"):
        out = tmp_path / f"{focus}.png"
        focus_flags = ["--focus", focus] if focus else []
        args = parse([str(tmp_path / "hands.bvh"), "-o", str(out), "--sheet-frames", "1", *focus_flags])
        assert render_cli.run_render(args) == 0
        ink[focus] = (np.asarray(Image.open(out).convert("L")) < 200).sum()  # dark pixels: bones, dots, text
    assert ink["LeftHand"] > ink[None] * 0.5  # 16 joints drawn big vs 52 drawn small: the hand is not a speck
    clip = render_cli.load_canonical(tmp_path / "hands.bvh")
    assert clip.names == CANONICAL_WITH_HANDS.names
    with pytest.raises(UserError, match="--focus LeftPinky: no such joint"):
        render_cli.run_render(parse([str(tmp_path / "hands.bvh"), "-o", str(tmp_path / "x.png"),
                                     "--focus", "LeftPinky"]))


def test_compare_draws_one_row_per_file_at_the_same_times(tmp_path):
    """Two clips → a PNG of two rows of N frames; the still clip's row differs from the moving one's only
    where the arm moves; mismatched labels and non-PNG outputs are one-line errors."""
    from gesturecast.models.motion.motion import SkeletonMotion
    from gesturecast.models.motion.retarget import motion_to_bvh

    frames = 20
    still = quat_from_axis_angle(np.zeros((frames, CANONICAL.num_joints, 3)))
    raised = np.zeros((frames, CANONICAL.num_joints, 3))
    raised[:, CANONICAL.index("LeftUpperArm"), 2] = np.linspace(0.0, 1.2, frames)  # the left arm rises
    root = np.tile(CANONICAL.offsets[0], (frames, 1))
    motion_to_bvh(SkeletonMotion(still, root), tmp_path / "still.bvh")
    motion_to_bvh(SkeletonMotion(quat_from_axis_angle(raised), root), tmp_path / "raise.bvh")
    out = tmp_path / "compare.png"
    inputs = [str(tmp_path / "still.bvh"), str(tmp_path / "raise.bvh")]
    args = parse([*inputs, "-o", str(out), "--compare", "--sheet-frames", "3", "--labels", "still,raise"])
    assert render_cli.run_render(args) == 0
    sheet = np.asarray(Image.open(out).convert("L")).astype(int)  # (H, W)
    height, width = sheet.shape
    top, bottom = sheet[: height // 2], sheet[height // 2 : height // 2 * 2]
    first_column = slice(0, width // 3)
    last_column = slice(2 * width // 3, width)
    assert np.abs(top[:, first_column] - bottom[:, first_column]).sum() < np.abs(
        top[:, last_column] - bottom[:, last_column]).sum()  # same pose at the start, different at the end
    with pytest.raises(UserError, match="--labels has 1 names for 2 files"):
        render_cli.run_render(parse([*inputs, "-o", str(out), "--compare", "--labels", "one"]))
    with pytest.raises(UserError, match="--compare writes a .png"):
        render_cli.run_render(parse([*inputs, "-o", str(tmp_path / "x.gif"), "--compare"]))
