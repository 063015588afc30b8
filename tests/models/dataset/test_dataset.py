import json

import numpy as np
import pytest
from dataset_fixtures import make_zeggs_folder

from gesturecast.cli import main
from gesturecast.errors import UserError
from gesturecast.models.dataset.augment import AugmentConfig, audio_samples_for_frames
from gesturecast.models.dataset.cache import (
    DEFAULT_SPLIT,
    INDEX_FILE,
    build_dataset,
    is_full_body,
    load_dataset,
    load_take,
    read_index,
    summary_table,
    take_segments,
)
from gesturecast.models.dataset.sources import TakeSource, show_takes, zeggs_takes
from gesturecast.models.motion.motion_features import FEATURE_DIM, facing_yaw

FRAMES = 60
RATE = 16000


@pytest.fixture(scope="module")
def zeggs_folder(tmp_path_factory, shared_data):
    styles = {"001_Neutral_0": "Neutral", "002_Old_0": "Old"}
    return make_zeggs_folder(tmp_path_factory.mktemp("zeggs"), shared_data / "zeggs", styles, FRAMES)


@pytest.fixture(scope="module")
def built_cache(tmp_path_factory, zeggs_folder):
    cache = tmp_path_factory.mktemp("cache") / "dataset"
    build_dataset(zeggs_takes(zeggs_folder), cache, progress=False)
    return cache


def test_cache_holds_faced_forward_motion_and_aligned_audio(built_cache):
    index = read_index(built_cache)
    assert [t["style"] for t in index["takes"]] == ["neutral", "old"]
    assert "old" in index["styles"] and index["style_synonyms"]["old"] == ["old", "elderly"]
    motion, audio = load_take(built_cache, index["takes"][0])
    assert motion.num_frames == FRAMES
    assert abs(float(facing_yaw(motion.rotations[0, 0]))) < 1e-6
    np.testing.assert_allclose(motion.root_position[0, [0, 2]], 0.0, atol=1e-6)
    assert audio.shape == (audio_samples_for_frames(FRAMES, 30.0, RATE),) and np.abs(audio).max() > 0


def test_split_is_deterministic_and_holds_out_the_tail_of_paired_takes():
    segments = take_segments("zeggs", "067_Speech_2", 2065, True, DEFAULT_SPLIT)
    assert segments == take_segments("zeggs", "067_Speech_2", 2065, True, DEFAULT_SPLIT)
    assert [s["split"] for s in segments] == ["train", "val", "test"]
    assert segments[-1] == {"split": "test", "start": 1755, "stop": 2065}  # final 15 %
    assert segments[0]["stop"] <= segments[1]["start"] and segments[1]["stop"] <= segments[2]["start"]


def test_motion_only_takes_go_whole_to_one_split_by_name():
    names = [f"dataset-2_wave-left-hand_active_{i:03d}" for i in range(400)]
    splits = [take_segments("bandai-2", n, 100, False, DEFAULT_SPLIT)[0]["split"] for n in names]
    assert splits == [take_segments("bandai-2", n, 100, False, DEFAULT_SPLIT)[0]["split"] for n in names]
    counts = {s: splits.count(s) for s in ("train", "val", "test")}
    assert counts["train"] > 300 and counts["val"] > 5 and counts["test"] > 5


def test_load_dataset_augments_train_only_and_keeps_lengths_aligned(built_cache):
    clips = load_dataset(built_cache, augment=AugmentConfig(mirror=True, speeds=(0.9, 1.1)))
    train = [c for c in clips if c.split == "train"]
    held_out = [c for c in clips if c.split != "train"]
    assert len(train) == 2 * 6 and len(held_out) == 2 * 2
    assert {c.variant for c in held_out} == {""}
    for clip in clips:
        assert clip.features.shape[1] == FEATURE_DIM
        assert clip.audio.shape == (audio_samples_for_frames(clip.features.shape[0], 30.0, RATE),)
    test_clip = next(c for c in clips if c.split == "test")
    assert test_clip.start_frame == FRAMES - int(round(FRAMES * 0.15))


def test_failed_build_leaves_previous_cache_untouched(tmp_path, built_cache, zeggs_folder):
    cache = tmp_path / "dataset"
    build_dataset(zeggs_takes(zeggs_folder)[:1], cache, progress=False)
    before = (cache / INDEX_FILE).read_text()
    broken = tmp_path / "broken.bvh"
    broken.write_text("HIERARCHY\nROOT Hips\n{\n")
    takes = [*zeggs_takes(zeggs_folder), TakeSource("zeggs", "broken", broken, None, "neutral")]
    with pytest.raises(UserError, match="broken.bvh"):
        build_dataset(takes, cache, progress=False)
    assert (cache / INDEX_FILE).read_text() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["broken.bvh", "dataset"]


def test_summary_table_lists_minutes_per_dataset_and_style(built_cache):
    table = summary_table(read_index(built_cache))
    assert "zeggs" in table and "neutral" in table and "old" in table and "0.07" in table


def test_cli_builds_from_a_user_folder(tmp_path, zeggs_folder, capsys):
    cache = tmp_path / "out"
    arguments = ["data", "build", "--no-shared", "--zeggs", str(zeggs_folder), "--cache", str(cache), "--limit", "1"]
    assert main(arguments) == 0
    assert len(json.loads((cache / INDEX_FILE).read_text())["takes"]) == 1
    assert '"takes": 1' in capsys.readouterr().out


def test_cli_unknown_layout_is_one_line_error(tmp_path, capsys):
    (tmp_path / "readme.txt").write_text("nothing here")
    assert main(["data", "build", "--no-shared", "--zeggs", str(tmp_path), "--cache", str(tmp_path / "c")]) == 2
    error = capsys.readouterr().err.strip()
    assert "not a ZeroEGGS folder" in error and "\n" not in error
    assert not (tmp_path / "c").exists()


def test_show_takes_are_cached_upright_arms_only_and_held_out_speakers_are_test_whole(tmp_path, shared_data):
    takes = [t for t in show_takes(shared_data / "show") if t.name.startswith(("seth_98201", "unknown_115700"))]
    index = build_dataset(takes, tmp_path / "cache", progress=False)
    records = {record["name"].split("_")[0]: record for record in index["takes"]}
    assert not any(is_full_body(record) for record in records.values())
    assert records["seth"]["parts"] == ["arms"] and records["seth"]["has_audio"]
    assert [s["split"] for s in records["seth"]["segments"]] == ["test"]
    assert [s["split"] for s in records["unknown"]["segments"]] == ["train", "val", "test"]
    motion, audio = load_take(tmp_path / "cache", records["seth"])
    positions = motion.positions()  # (T, J, 3)
    head, hips = motion.skeleton.index("Head"), motion.skeleton.index("Hips")
    # the fit's root is in the camera frame (y down): read as it is, the speaker would hang upside down
    assert np.all(positions[:, head, 1] > positions[:, hips, 1] + 0.3)
    assert audio is not None and len(audio) == audio_samples_for_frames(motion.num_frames, motion.fps, RATE)
    clips = load_dataset(tmp_path / "cache", splits=("train",))
    assert clips and all(clip.parts == ("arms",) for clip in clips)


def test_held_out_take_goes_whole_to_test():
    assert take_segments("show", "seth_1", 300, True, DEFAULT_SPLIT, held_out=True) == [
        {"split": "test", "start": 0, "stop": 300}]
