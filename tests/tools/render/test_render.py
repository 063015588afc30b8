"""The stick-figure renderer: valid files, the figure is drawn, poses are told apart, sheet layout."""

import numpy as np
import pytest
from PIL import Image

from gesturecast.errors import UserError
from gesturecast.models.motion.motion import SkeletonMotion
from gesturecast.models.motion.rotations import quat_from_axis_angle, quat_identity
from gesturecast.models.motion.skeleton import CANONICAL
from gesturecast.tools.render.animation import RenderConfig, gif_delays_ms, render_positions, sheet_indices
from gesturecast.tools.render.stick_figure import BACKGROUND, LEFT, PALETTE_RGB, RIGHT, FigureConfig, joint_sides

FIGURE = FigureConfig()
WIDTH, HEIGHT = FIGURE.image_size


def waving_positions(num_frames: int, root_path: np.ndarray | None = None) -> np.ndarray:
    """Canonical T-pose whose left arm swings down and up once per second. (T, J, 3)"""
    t = np.arange(num_frames) / 30.0
    rotations = quat_identity((num_frames, CANONICAL.num_joints))
    angle = -1.2 * np.sin(2 * np.pi * t)[:, None]  # (T, 1)
    rotations[:, CANONICAL.index("LeftUpperArm")] = quat_from_axis_angle(angle * np.array([0.0, 0.0, 1.0]))
    root = root_path if root_path is not None else np.tile(CANONICAL.offsets[0], (num_frames, 1))
    return SkeletonMotion(rotations, root).positions()


def render_png_array(positions: np.ndarray, tmp_path, name: str = "one.png") -> np.ndarray:
    path = render_positions(positions, CANONICAL.parents, tmp_path / name, names=CANONICAL.names,
                            config=RenderConfig(sheet_frames=1))
    return np.asarray(Image.open(path).convert("RGB"))[:HEIGHT, :WIDTH]  # (H, W, 3) the single cell


def panel_box(panel: int) -> tuple[slice, slice]:
    """Rows/columns strictly inside one panel, below its label and above the ground line."""
    rows = slice(FIGURE.header_px + 16, FIGURE.header_px + FIGURE.panel_height - FIGURE.margin_px - 2)
    cols = slice(panel * FIGURE.panel_width + 2, (panel + 1) * FIGURE.panel_width - 2)
    return rows, cols


def test_gif_has_one_frame_per_stride_and_the_clip_duration(tmp_path):
    positions = waving_positions(45)
    path = render_positions(positions, CANONICAL.parents, tmp_path / "clip.gif", fps=30.0,
                            config=RenderConfig(stride=2))
    with Image.open(path) as gif:
        assert gif.size == (WIDTH, HEIGHT)
        assert gif.n_frames == 23
        durations = []
        for k in range(gif.n_frames):
            gif.seek(k)
            durations.append(gif.info["duration"])
    assert sum(durations) == pytest.approx(23 * 2 / 30 * 1000, abs=10)


def test_gif_delays_track_the_frame_rate():
    delays = gif_delays_ms(30, 30.0)
    assert sum(delays) == 1000 and set(delays) <= {30, 40}


def test_figure_is_drawn_in_both_panels_with_left_on_the_viewers_right(tmp_path):
    image = render_png_array(waving_positions(1), tmp_path)
    for panel in (0, 1):
        rows, cols = panel_box(panel)
        assert (np.abs(image[rows, cols].astype(int) - PALETTE_RGB[BACKGROUND]).sum(-1) > 0).sum() > 200
    rows, cols = panel_box(0)
    front = image[rows, cols]
    blue_x = np.nonzero((front == PALETTE_RGB[LEFT]).all(-1))[1]
    red_x = np.nonzero((front == PALETTE_RGB[RIGHT]).all(-1))[1]
    centre = FIGURE.panel_width / 2
    assert blue_x.mean() > centre > red_x.mean()  # facing the viewer, the character's left is on the right


def test_different_poses_give_different_pictures_and_planar_root_motion_is_followed(tmp_path):
    clip = waving_positions(16)
    rest, raised = clip[0:1], clip[7:8]
    moved = rest + np.array([3.0, 0.0, -2.0])
    lifted = rest + np.array([0.0, 0.2, 0.0])
    panels = slice(FIGURE.header_px, FIGURE.header_px + FIGURE.panel_height)
    pictures = {name: render_png_array(pos, tmp_path, f"{name}.png")[panels]
                for name, pos in [("rest", rest), ("raised", raised), ("moved", moved), ("lifted", lifted)]}
    assert (pictures["rest"] != pictures["raised"]).any()
    assert (pictures["rest"] == pictures["moved"]).all()  # hips followed in X and Z
    assert (pictures["rest"] != pictures["lifted"]).any()  # vertical motion kept


def test_contact_sheet_tiles_evenly_spaced_frames(tmp_path):
    assert sheet_indices(50, 6) == [0, 10, 20, 29, 39, 49]
    assert sheet_indices(3, 12) == [0, 1, 2]
    path = render_positions(waving_positions(50), CANONICAL.parents, tmp_path / "sheet.png",
                            config=RenderConfig(sheet_frames=6, sheet_columns=4))
    gap = 4
    assert Image.open(path).size == (4 * (WIDTH + gap), 2 * (HEIGHT + gap))


def test_joint_sides_from_common_naming_schemes():
    names = ["Hips", "LeftHand", "RightFoot", "UpperArm_L", "Hand_R", "left_wrist", "right_hip", "LHipJoint",
             "RThumb", "LowerBack", "joint_Root", "Spine1"]
    assert joint_sides(names).tolist() == [0, 1, -1, 1, -1, 1, -1, 1, -1, 0, 0, 0]


def test_bad_outputs_are_user_errors(tmp_path, monkeypatch):
    positions = waving_positions(3)
    with pytest.raises(UserError, match="ending in"):
        render_positions(positions, CANONICAL.parents, tmp_path / "clip.avi")
    monkeypatch.setenv("PATH", str(tmp_path))  # no ffmpeg here
    with pytest.raises(UserError, match="ffmpeg is not on PATH"):
        render_positions(positions, CANONICAL.parents, tmp_path / "clip.mp4")
    with pytest.raises(UserError, match="no frames"):
        render_positions(positions[:0], CANONICAL.parents, tmp_path / "clip.gif")
    with pytest.raises(UserError, match="does not exist"):
        render_positions(positions, CANONICAL.parents, tmp_path / "missing" / "clip.gif")


def test_a_floor_level_root_above_the_hips_is_left_out(tmp_path):
    body = waving_positions(1) + np.array([2.0, 0.0, 1.0])
    with_floor_root = np.concatenate([np.zeros((1, 1, 3)), body], axis=1)  # (1, J + 1, 3) Bandai-style root
    parents = (-1, *(p + 1 for p in CANONICAL.parents))
    names = ("joint_Root", *CANONICAL.names)
    config = RenderConfig(sheet_frames=1)
    plain = render_positions(body, CANONICAL.parents, tmp_path / "plain.png", names=CANONICAL.names, config=config)
    rooted = render_positions(with_floor_root, parents, tmp_path / "rooted.png", names=names, config=config)
    assert (np.asarray(Image.open(plain)) == np.asarray(Image.open(rooted))).all()


def test_captions_show_clip_time_from_the_selected_start():
    """`render --start 10` labels its first drawn frame 10.00 s, not 0.00 s."""
    from gesturecast.tools.render.animation import frame_caption

    assert frame_caption(0, 30, 30.0, start_s=10.0) == "frame 1/30    10.00 s"
    assert frame_caption(15, 30, 30.0, start_s=10.0).endswith("10.50 s")
