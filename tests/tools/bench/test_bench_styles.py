"""`gesturecast bench styles --quick` on the tiny model, and the measures it is built on."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "models"))
from dataset_fixtures import FIRST_FRAME, TAKE, cut_bvh, make_zeggs_folder  # noqa: E402

from gesturecast.cli import main  # noqa: E402
from gesturecast.models.dataset.cache import build_dataset  # noqa: E402
from gesturecast.models.dataset.sources import TakeSource, zeggs_takes  # noqa: E402
from gesturecast.models.motion.body_parts import PART_NAMES  # noqa: E402
from gesturecast.models.motion.bvh import read_bvh  # noqa: E402
from gesturecast.models.motion.retarget import retarget_bvh  # noqa: E402
from gesturecast.models.motion.rotations import quat_from_axis_angle, quat_identity  # noqa: E402
from gesturecast.models.motion.skeleton import CANONICAL  # noqa: E402
from gesturecast.tools.bench.styles.cmu_bvh import CMU_NAMES  # noqa: E402
from gesturecast.tools.bench.styles.measures import (  # noqa: E402
    border_joints,
    mean_pose_difference_deg,
    seam_roughness,
)

pytest.importorskip("matplotlib")
PAIRED_FRAMES = 600  # 20 s: the held-out final 15 % is 3 s, enough for one 64-frame classifier window at 2.5 s
MOTION_ONLY_FRAMES = 150
MOTION_ONLY = {"old": "dataset-2_wave-both-hands_old_001", "angry": "dataset-1_bye_angry_001"}


@pytest.fixture(scope="module")
def styles_cache(tmp_path_factory, shared_data) -> Path:
    """A paired neutral take (3 s held out) and one motion-only take per prompt style, cut from ZeroEGGS."""
    root = tmp_path_factory.mktemp("styles")
    folder = make_zeggs_folder(root / "zeggs", shared_data / "zeggs", {"001_Neutral_0": "Neutral"}, PAIRED_FRAMES)
    takes = list(zeggs_takes(folder))
    for offset, (style, name) in enumerate(MOTION_ONLY.items()):
        path = root / f"{name}.bvh"
        cut_bvh(shared_data / "zeggs" / f"{TAKE}.bvh", path, MOTION_ONLY_FRAMES, FIRST_FRAME + 700 + 200 * offset)
        takes.append(TakeSource("bandai-1", name, path, None, style))
    build_dataset(takes, root / "dataset", progress=False)
    return root / "dataset"


@pytest.fixture(scope="module")
def quick_study(tiny_model, styles_cache, tmp_path_factory, shared_data) -> tuple[dict, Path]:
    _, bundle = tiny_model
    out = tmp_path_factory.mktemp("study")
    code = main(["bench", "styles", "--quick", "--model", str(bundle), "--cache", str(styles_cache),
                 "--data", str(shared_data), "--grid", str(out / "grid.png"),
                 "--json", str(out / "styles.json"), "--plot", str(out / "styles.png"),
                 "--prompt-dir", str(out / "prompts"), "--sheet", str(out / "sheet.png")])
    assert code == 0
    return json.loads((out / "styles.json").read_text()), out


def test_confusion_rows_count_every_window(quick_study):
    report, _ = quick_study
    assert list(report["guidance"]) == ["1.5"]
    entry = report["guidance"]["1.5"]
    confusion = entry["confusion"]
    assert confusion["requested"] == report["styles"] and len(report["styles"]) == 2
    assert confusion["predicted"] == report["classifier"]["labels"]
    counts = np.array(confusion["counts"])
    assert counts.shape == (2, len(confusion["predicted"]))
    windows = entry["style_accuracy"]["windows_per_style"]
    assert windows >= 1
    assert (counts.sum(axis=1) == windows).all()
    for style, accuracy in entry["style_accuracy"]["per_style"].items():
        assert 0.0 <= accuracy <= 1.0
        assert accuracy == counts[report["styles"].index(style), confusion["predicted"].index(style)] / windows
    assert entry["style_accuracy"]["chance"] == 1.0 / len(confusion["predicted"])
    assert entry["neutral_metrics"]["jerk"] > 0.0
    following = entry["following"]
    assert set(following["per_style"]) == {"neutral", *report["styles"]}
    for style, ratio in following["ratio_to_neutral"].items():
        assert ratio == following["per_style"][style] / following["per_style"]["neutral"]


def test_motion_prompts_are_120_fps_cmu_clips_of_the_chosen_takes(quick_study):
    report, out = quick_study
    clips = report["motion_prompts"]["clips"]
    assert [(c["style"], c["take"]) for c in clips] == list(MOTION_ONLY.items())
    for clip in clips:
        data = read_bvh(out / "prompts" / clip["path"])
        assert data.fps == pytest.approx(120.0, abs=1e-3)
        assert tuple(data.names) == CMU_NAMES and {"LowerBack", "LHipJoint", "Neck1"} <= set(data.names)
        assert retarget_bvh(data).joint_map.name == "CMU"
        assert data.num_frames == pytest.approx(clip["seconds"] * 120.0, abs=4)
    degrees = report["motion_prompts"]["by_guidance"]["1.5"]
    assert degrees["motion_prompts_deg"] >= 0.0 and degrees["label_prompts_deg"] > 0.0


def test_part_styles_report_every_part_seam_and_cost(quick_study):
    report, out = quick_study
    study = report["part_styles"]
    assert [p["pair"] for p in study["pairs"]] == ["arms=happy, rest=old", "arms=old, rest=happy",
                                                   "torso=old, rest=angry", "legs=old, rest=happy"]
    for pair in study["pairs"]:
        assert set(pair["signatures"]) == set(PART_NAMES)
        for signature in pair["signatures"].values():
            assert 0.0 <= signature["share"] <= 1.0
            assert signature["closer_to_own"] == (signature["to_own"] < signature["to_other"])
        assert pair["seams"]["per_part"]["border"] >= 0.0
        rows = pair["compute"]["denoiser_rows"]
        assert rows["per_part"] == 2 * rows["single_style"]  # one more trajectory: its style, null and audio rows
    assert study["closer_to_own"]["parts"] == 12
    assert set(study["prompted_part_progress"]) == {p["pair"] for p in study["pairs"]}
    assert study["rtf"]["single_style"] > 0.0 and study["rtf"]["per_part"] > 0.0
    assert (out / "styles.png").stat().st_size > 0 and (out / "styles_parts.png").stat().st_size > 0


def test_the_sheet_has_a_row_per_style_of_body_frames_and_a_face_panel(quick_study):
    from PIL import Image

    from gesturecast.tools.bench.styles.sheet import SHEET_STYLES
    from gesturecast.tools.render.stick_figure import FigureConfig

    report, out = quick_study
    assert report["sheet"] == str(out / "sheet.png")
    width, height = FigureConfig().image_size
    with Image.open(out / "sheet.png") as sheet:
        assert sheet.height >= len(SHEET_STYLES) * height and sheet.width >= 5 * width  # 4 frames + the face


def test_the_stylizer_part_reports_fk_distances_judges_following_jerk_face_and_cost(quick_study):
    report, out = quick_study
    stylizer = report["stylizer"]
    styles = stylizer["styles"]
    assert len(styles) == 7 and stylizer["speech"]["seeds"] == [0, 1, 2]
    for variant in ("generator", "styled"):
        section = stylizer[variant]
        fk = section["fk"]
        assert len(fk["pairs"]) == 21 and fk["closest"] == min(fk["pairs"].values())
        rounding = 0.0005  # the closest pair and the floor are reported to 3 decimals, their ratio from the full values
        assert fk["seed_floor"] > rounding
        assert ((fk["closest"] - rounding) / (fk["seed_floor"] + rounding) <= fk["min_over_floor"]
                <= (fk["closest"] + rounding) / (fk["seed_floor"] - rounding))
        for judged in (section["judge"], section["classifier"]):
            assert set(judged["per_style"]) == set(styles)
            assert all(0.0 <= value <= 1.0 for value in judged["per_style"].values())
        following = section["following"]
        assert following["baseline"]["settings"] == "Settings()"
        speech = following["baseline"]["following"]
        for style, ratio in following["ratio_to_default"].items():  # within what the 3-decimal rounding allows
            value = following["per_style"][style]
            low, high = sorted([(value - rounding) / (speech + rounding), (value + rounding) / (speech - rounding)])
            assert low - rounding <= ratio <= high + rounding
        assert section["jerk"]["real"] > 0.0
    assert stylizer["styled"]["fk"]["pairs"] != stylizer["generator"]["fk"]["pairs"]
    assert set(stylizer["face"]) == set(styles) and stylizer["cost"]["ms_per_motion_second"] > 0.0
    assert [Path(path).name for path in stylizer["grid"]] == ["grid_generator.png", "grid.png"]
    assert (out / "grid.png").stat().st_size > 0


def test_border_joints_are_where_parts_meet():
    assert border_joints() == ("Spine", "LeftShoulder", "RightShoulder")


def test_seam_roughness_sees_a_kink_only_at_its_joint():
    frames = 40
    rotations = quat_identity((frames, CANONICAL.num_joints))
    angle = np.radians(np.where(np.arange(frames) < 20, 0.0, 30.0))  # a 30° step at frame 20
    rotations[:, CANONICAL.index("LeftShoulder")] = quat_from_axis_angle(angle[:, None] * np.array([0.0, 0.0, 1.0]))
    seams = seam_roughness(rotations)
    assert seams["per_joint"]["LeftShoulder"] == pytest.approx(2 * 30.0 / (frames - 2))  # +30 then −30 °/frame²
    assert seams["per_joint"]["Spine"] == 0.0 and seams["inner"] == 0.0


def test_mean_pose_difference_measures_a_constant_offset():
    rotations = quat_identity((10, CANONICAL.num_joints))
    turned = rotations.copy()
    turned[:, CANONICAL.index("Head")] = quat_from_axis_angle(np.array([np.radians(26.0), 0.0, 0.0]))
    assert mean_pose_difference_deg(rotations, rotations) == pytest.approx(0.0, abs=1e-6)
    assert mean_pose_difference_deg(rotations, turned) == pytest.approx(26.0 / 13, abs=1e-6)  # 1 of 13 joints
