import json

import numpy as np
import pytest
import soundfile
from dataset_fixtures import make_zeggs_folder

from gesturecast.errors import UserError
from gesturecast.models.dataset.augment import (
    AugmentConfig,
    audio_samples_for_frames,
    augmented_variants,
    fit_audio,
    slice_audio,
    speed_perturb_pair,
)
from gesturecast.models.dataset.sources import bandai_takes, beat_takes, show_takes, smplx_takes, zeggs_takes
from gesturecast.models.motion.motion import SkeletonMotion
from gesturecast.models.motion.rotations import quat_identity
from gesturecast.models.motion.skeleton import NUM_JOINTS

RATE = 16000


def test_zeggs_discovery_matches_suffixed_files_and_skips_mirror_and_missing(tmp_path, shared_data):
    folder = make_zeggs_folder(tmp_path / "zeggs", shared_data / "zeggs", {"001_Neutral_0": "Neutral"}, 10)
    (take,) = zeggs_takes(folder)
    assert (take.name, take.dataset, take.style) == ("001_Neutral_0", "zeggs", "neutral")
    assert take.motion_path.name == "001_Neutral_0_x_1_0.bvh"
    assert take.audio_path is not None and take.audio_path.name == "001_Neutral_0_x_1_0.wav"


def test_shared_zeggs_folder_has_one_take_with_audio(shared_data):
    (take,) = zeggs_takes(shared_data / "zeggs")
    assert take.style == "speech" and take.audio_path is not None


def test_shared_show_folder_is_arms_only_with_two_speakers_held_out(shared_data):
    takes = show_takes(shared_data / "show")
    assert len(takes) == 12 and {t.dataset for t in takes} == {"show"}
    assert all(t.parts == ("arms",) and not t.full_body and t.root_in_camera_frame for t in takes)
    held_out = {t.name.split("_")[0] for t in takes if t.held_out}
    assert held_out == {"seth", "chemistry"}
    assert {t.name.split("_")[0] for t in takes if not t.held_out} == {"oliver", "conan", "unknown"}


def test_show_folder_without_pairs_is_a_user_error(tmp_path):
    with pytest.raises(UserError, match="not a SHOW folder"):
        show_takes(tmp_path)


def test_bandai_style_comes_from_label_index(tmp_path):
    (tmp_path / "cfg").mkdir()
    (tmp_path / "cfg" / "style_label.txt").write_text("dataset-2_active\ndataset-2_elderly\ndataset-2_youthful")
    (tmp_path / "data").mkdir()
    for stem, label in [("dataset-2_wave-left-hand_elderly_001", 1), ("dataset-2_wave-left-hand_youthful_002", 2)]:
        (tmp_path / "data" / f"{stem}.bvh").write_text("HIERARCHY\n")
        (tmp_path / "data" / f"{stem}.json").write_text(json.dumps({"content": 5, "style": label}))
    takes = bandai_takes(tmp_path)
    assert [(t.dataset, t.style) for t in takes] == [("bandai-2", "old"), ("bandai-2", "childish")]


@pytest.mark.parametrize("discover", [zeggs_takes, beat_takes, smplx_takes, bandai_takes])
def test_unknown_layout_is_one_line_user_error(tmp_path, discover):
    (tmp_path / "notes.txt").write_text("not a dataset")
    with pytest.raises(UserError, match=r"is not an? .* folder") as raised:
        discover(tmp_path)
    assert "\n" not in str(raised.value)


def test_beat_pairs_bvh_with_wav(tmp_path):
    for name in ("1_wayne_0_1_1.bvh", "1_wayne_0_1_1.wav", "1_wayne_0_2_2.bvh"):
        (tmp_path / name).write_text("x")
    (take,) = beat_takes(tmp_path)
    assert take.name == "1_wayne_0_1_1" and take.style == "neutral"


def clip(num_frames: int) -> SkeletonMotion:
    return SkeletonMotion(quat_identity((num_frames, NUM_JOINTS)), np.zeros((num_frames, 3)))


def test_fit_and_slice_audio_follow_frame_boundaries():
    audio = np.arange(2000, dtype=np.float32)
    fitted = fit_audio(audio, 4, 30.0, RATE)
    assert fitted.shape == (audio_samples_for_frames(4, 30.0, RATE),) == (2133,)
    assert np.array_equal(fitted[:2000], audio) and not fitted[2000:].any()
    pieces = [slice_audio(fitted, k, k + 1, 30.0, RATE) for k in range(4)]
    assert np.array_equal(np.concatenate(pieces), fitted)


@pytest.mark.parametrize("factor", [0.9, 1.1])
def test_speed_augmentation_keeps_audio_and_motion_aligned(factor):
    audio = np.sin(np.arange(audio_samples_for_frames(91, 30.0, RATE)) * 0.05).astype(np.float32)
    motion, faster_audio = speed_perturb_pair(clip(91), audio, factor, RATE)
    assert faster_audio.shape == (audio_samples_for_frames(motion.num_frames, 30.0, RATE),)
    assert motion.num_frames == int(np.floor(90 / factor + 1e-9)) + 1


def test_speed_augmentation_resamples_the_audio_in_time(tmp_path):
    tone_hz = 200.0
    audio = np.sin(2 * np.pi * tone_hz * np.arange(RATE) / RATE).astype(np.float32)  # 1 s
    _, faster = speed_perturb_pair(clip(30), audio, 1.1, RATE)
    spectrum = np.abs(np.fft.rfft(faster[:8000]))
    peak_hz = np.argmax(spectrum) * RATE / 8000
    assert abs(peak_hz - tone_hz * 1.1) < 4.0
    soundfile.write(tmp_path / "x.wav", faster, RATE)  # stays a valid float32 signal


def test_augmented_variants_tags_and_audio_sharing():
    audio = np.ones(audio_samples_for_frames(31, 30.0, RATE), np.float32)
    variants = augmented_variants(clip(31), audio, AugmentConfig(True, (0.9, 1.1)), RATE)
    tags = [tag for tag, _, _ in variants]
    assert tags == ["", "speed0.9", "speed1.1", "mirror", "mirror+speed0.9", "mirror+speed1.1"]
    for _, motion, variant_audio in variants:
        assert variant_audio.shape[0] == audio_samples_for_frames(motion.num_frames, 30.0, RATE)


def test_show_clips_are_split_by_the_speaker_prefix(shared_data):
    from gesturecast.models.dataset.sources import SHOW_HELD_OUT_SPEAKERS, show_speaker

    speakers = {show_speaker(path.stem) for path in (shared_data / "show").glob("*.wav")}
    assert {"oliver", "seth", "conan", "chemistry", "unknown"} == speakers
    assert set(SHOW_HELD_OUT_SPEAKERS) < speakers  # held out entirely, others left to train on
