"""The gesture lexicon's builder: trimming and stroke rules on real Bandai takes, a small build, the shipped clips."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from gesturecast.models.dataset.cache import read_take
from gesturecast.models.dataset.sources import TakeSource, bandai_takes, unpack_archive
from gesturecast.models.motion.motion import SkeletonMotion
from gesturecast.models.motion.motion_features import FEATURE_DIM, features_to_motion
from gesturecast.models.motion.skeleton import CANONICAL
from gesturecast.realtime.gestures import lexicon as gl
from gesturecast.realtime.gestures.strokes import body_frame_positions
from gesturecast.tools.gestures import build

RAW_CACHE = Path(__file__).resolve().parents[3] / ".cache" / "raw"  # where `gesturecast data build` unpacks
ARCHIVES = ("dataset-1.tar.xz", "dataset-2-gestures.tar.xz")
FPS = 30


@pytest.fixture(scope="module")
def bandai(shared_data) -> dict[str, TakeSource]:
    """Every Bandai take by name (both archives, unpacked once into .cache/raw as the data build does)."""
    takes = []
    for archive in ARCHIVES:
        takes += bandai_takes(unpack_archive(shared_data / "bandai" / archive, RAW_CACHE / "bandai"))
    return {take.name: take for take in takes}


def motion_of(bandai: dict[str, TakeSource], name: str) -> SkeletonMotion:
    return read_take(bandai[name])[0]


def relative(body: np.ndarray, joint: str, to: str) -> np.ndarray:
    """(T, 3) body-frame offset of ``joint`` from ``to``."""
    return body[:, CANONICAL.index(joint)] - body[:, CANONICAL.index(to)]


def centre_crossings(values: np.ndarray, dead_band: float = 0.02) -> int:
    """How often ``values`` swing from one side of their median to the other (moves inside ±dead_band ignored)."""
    side = np.sign(values - np.median(values))
    side = side[np.abs(values - np.median(values)) > dead_band]
    return int(np.count_nonzero(np.diff(side)))


@pytest.mark.parametrize(("name", "gesture", "sides"), [
    ("dataset-2_wave-both-hands_normal_001", "wave", ("Left", "Right")),
    ("dataset-2_wave-left-hand_elderly_001", "wave-left", ("Left",)),
    ("dataset-2_wave-right-hand_active_001", "wave-right", ("Right",)),
])
def test_a_wave_stroke_has_the_wrist_above_the_shoulder_swinging_sideways(bandai, name, gesture, sides):
    motion = motion_of(bandai, name)
    cut = build.find_gesture(motion, build.gesture_spec(gesture))
    body = body_frame_positions(motion)
    for side in sides:
        wrist = relative(body, f"{side}Hand", f"{side}UpperArm")
        assert wrist[cut.stroke, 1] > 0.05, f"{side} wrist {wrist[cut.stroke, 1]:.2f} m above the shoulder"
        lateral = wrist[cut.stroke:cut.stroke + int(1.5 * FPS), 0]  # the 1.5 s after the stroke
        assert np.ptp(lateral) > 0.1 and centre_crossings(lateral) >= 2
    others = {"Left", "Right"} - set(sides)
    for side in others:  # a one-hand wave leaves the other arm down
        assert relative(body, f"{side}Hand", f"{side}UpperArm")[cut.stroke, 1] < -build.REST_DROP
    assert cut.hand == {"wave": "both", "wave-left": "left", "wave-right": "right"}[gesture]


@pytest.mark.parametrize("name", ["dataset-1_bow_normal_001", "dataset-1_bow_old_001", "dataset-1_bow_sad_001"])
def test_a_bow_stroke_has_the_head_well_forward_of_the_hips(bandai, name):
    motion = motion_of(bandai, name)
    cut = build.find_gesture(motion, build.gesture_spec("bow"))
    head = body_frame_positions(motion)[:, CANONICAL.index("Head")]
    assert head[cut.stroke, 2] > 0.3 and head[cut.stroke, 2] > head[cut.start, 2] + 0.25
    assert head[cut.stroke, 2] >= 0.9 * head[cut.start:cut.stop, 2].max()
    assert head[cut.stroke, 1] < head[cut.start, 1] - 0.1  # bent down, too


def test_a_raise_stroke_has_the_named_hand_up_and_the_other_down(bandai):
    motion = motion_of(bandai, "dataset-2_raise-up-left-hand_normal_001")
    cut = build.find_gesture(motion, build.gesture_spec("raise-left"))
    body = body_frame_positions(motion)
    assert relative(body, "LeftHand", "LeftUpperArm")[cut.stroke, 1] > 0.1
    assert relative(body, "RightHand", "RightUpperArm")[cut.stroke, 1] < -build.REST_DROP
    assert cut.rests and cut.stroke < cut.stop - 10  # it comes back down after the stroke


def test_a_guide_stroke_holds_the_arm_out(bandai):
    motion = motion_of(bandai, "dataset-1_guide_normal_001")
    cut = build.find_gesture(motion, build.gesture_spec("guide"))
    body = body_frame_positions(motion)
    side = cut.hand.capitalize()
    reach = np.linalg.norm(relative(body, f"{side}Hand", f"{side}UpperArm")[:, [0, 2]], axis=-1)
    assert reach[cut.stroke] > 0.3 and reach[cut.stroke] > reach[cut.start] + 0.15


def pad_with_stillness(motion: SkeletonMotion, frames: int) -> SkeletonMotion:
    """The take with its first pose held ``frames`` frames before it and its last pose held after it."""
    rotations = np.concatenate([np.repeat(motion.rotations[:1], frames, 0), motion.rotations,
                                np.repeat(motion.rotations[-1:], frames, 0)])
    root = np.concatenate([np.repeat(motion.root_position[:1], frames, 0), motion.root_position,
                           np.repeat(motion.root_position[-1:], frames, 0)])
    return SkeletonMotion(rotations, root, motion.fps)


@pytest.mark.parametrize(("name", "gesture"), [("dataset-2_raise-up-left-hand_normal_001", "raise-left"),
                                               ("dataset-1_bow_normal_001", "bow")])
def test_trimming_drops_the_stillness_around_the_gesture(bandai, name, gesture):
    motion = motion_of(bandai, name)
    spec = build.gesture_spec(gesture)
    plain = build.find_gesture(motion, spec, max_seconds=None)
    pad = int(1.5 * FPS)
    cut = build.find_gesture(pad_with_stillness(motion, pad), spec, max_seconds=None)
    margin = int(round(build.MARGIN_SECONDS * FPS))
    assert pad - margin - 2 <= cut.start <= pad + plain.start
    assert pad + plain.stop - 2 <= cut.stop <= pad + motion.num_frames + margin
    assert cut.stroke == pad + plain.stroke
    assert cut.rests


def test_a_long_wave_loses_part_of_its_hold_at_a_matching_pose(bandai):
    motion = motion_of(bandai, "dataset-2_wave-both-hands_normal_001")  # 6.7 s of waving
    cut = build.find_gesture(motion, build.gesture_spec("wave"))
    assert cut.removed is not None
    a, b = cut.removed
    assert cut.stroke + build.KEEP_SECONDS * FPS <= a < b < cut.stop
    assert cut.num_frames <= build.MAX_SECONDS * FPS
    joints = [CANONICAL.index(name) for name in build.SPLICE_JOINTS]
    body = body_frame_positions(motion)[:, joints]
    assert np.linalg.norm(body[a] - body[b], axis=-1).max() <= build.SPLICE_TOLERANCE
    variant = build.trimmed_variant(motion, cut, "neutral", "take")
    assert variant.features.shape == (cut.num_frames, FEATURE_DIM) and variant.features.dtype == np.float16
    clip = body_frame_positions(features_to_motion(variant.features.astype(np.float64)))[:, joints]
    step = np.linalg.norm(np.diff(clip, axis=0), axis=-1).max(axis=-1)  # (T-1,) fastest joint per frame
    join = a - cut.start
    assert step[join - 3:join + 3].max() <= np.percentile(step, 99)  # no jump at the join


def test_splice_features_cross_fades_the_join():
    features = np.stack([np.full(FEATURE_DIM, float(t)) for t in range(20)])
    out = build.splice_features(features, 8, 14, blend=4)
    assert len(out) == 14
    assert out[5, 0] == 5 and out[10, 0] == 16  # untouched outside the blend
    assert out[6, 0] == pytest.approx(0.875 * 6 + 0.125 * 12) and out[9, 0] == pytest.approx(0.125 * 9 + 0.875 * 15)


def test_a_small_build_keeps_resting_takes_and_reads_back_the_same(bandai, tmp_path):
    names = ["dataset-2_wave-both-hands_normal_001", "dataset-2_wave-both-hands_normal_002",
             "dataset-2_wave-both-hands_normal_003", "dataset-2_wave-both-hands_elderly_001",
             "dataset-2_wave-both-hands_elderly_002", "dataset-1_bow_normal_001", "dataset-1_bow_happy_001",
             "dataset-1_guide_normal_001"]
    candidates = build.bandai_gesture_takes([bandai[name] for name in names])
    assert {c.gesture for c in candidates} == {"wave", "bow", "guide"}

    def read(path: Path) -> SkeletonMotion:
        return read_take(next(t for t in bandai.values() if t.motion_path == path))[0]

    lexicon = build.build_lexicon(candidates, read)
    assert lexicon["wave"].styles == ("neutral", "old") and lexicon["guide"].styles == ("neutral",)
    assert lexicon["bow"].styles == ("neutral",) and lexicon.metadata["skipped"] == ["bow/happy"]  # ends mid-bow
    assert lexicon["wave"].variant("old").source == "dataset-2_wave-both-hands_elderly_002"  # _001 starts mid-wave
    assert [t.source for t in lexicon["wave"].takes("old")] == ["dataset-2_wave-both-hands_elderly_002"]
    lengths = {name: build.find_gesture(read(bandai[name].motion_path), build.gesture_spec("wave")).num_frames
               for name in names[:3]}
    takes = lexicon["wave"].takes("neutral")
    assert lengths[takes[0].source] == sorted(lengths.values())[1] and {t.source for t in takes} == set(names[:3])
    assert [t.take for t in takes] == [0, 1, 2] and lexicon["wave"].variant() is takes[0]
    assert lexicon["bow"].parts == ("arms", "torso", "legs") and lexicon.triggers()["hello"] == "wave"
    build.save_lexicon(lexicon, tmp_path)
    again = gl.load_lexicon(tmp_path)
    for entry in lexicon:
        for variant, loaded in zip(entry.variants, again[entry.name].variants, strict=True):
            assert (loaded.style, loaded.take) == (variant.style, variant.take)
            assert np.array_equal(loaded.features, variant.features) and loaded.features.dtype == np.float16
            assert (loaded.stroke_frame, loaded.source, loaded.removed) == (variant.stroke_frame, variant.source,
                                                                           variant.removed)
    listed = json.loads((tmp_path / gl.LEXICON_FILE).read_text())
    assert "CC BY-NC 4.0" in listed["license"] and listed["feature_dim"] == FEATURE_DIM


def test_the_shipped_clips_start_and_end_with_the_arms_down():
    for entry in gl.load_lexicon():
        for variant in entry.variants:
            body = body_frame_positions(features_to_motion(variant.features.astype(np.float64)))
            assert build.at_rest(body, 0) and build.at_rest(body, -1), f"{entry.name}/{variant.style}/{variant.take}"


def cuts(*takes: tuple[int, float]) -> list[tuple[build.CandidateTake, build.GestureCut]]:
    """Takes named t0, t1, ... of (clip length in frames, sideways offset of every joint around the stroke, m)."""
    return [(build.CandidateTake("wave", "neutral", f"t{i}", Path(f"t{i}.bvh")),
             build.GestureCut(0, n, n // 2, "both", around_stroke=np.full((60, 13, 3), [x, 0.0, 0.0])))
            for i, (n, x) in enumerate(takes)]


def kept(*takes: tuple[int, float], count: int = build.MAX_TAKES) -> list[str]:
    return [take.name for take, _ in build.spread_takes(cuts(*takes), count)]


def test_the_kept_takes_are_the_median_then_the_typical_ones_that_look_most_different():
    many = ((50, 0.0), (10, 1.0), (90, -1.0), (30, 0.10), (70, -0.08), (20, 0.5), (80, 0.3), (40, 0.02), (60, 0.05))
    # by length t1 t5 t3 t7 t0 t8 t4 t6 t2: t0 the median, t3 to t4 the interquartile range; t1, t2 look most
    # different but are the shortest and the longest
    assert kept(*many) == ["t0", "t3", "t4"]  # t3 is 10 cm from t0; then t4, 8 cm from t0 (t8: 5 cm from both)
    assert kept(*many, count=1) == ["t0"] and kept(*many, count=2) == ["t0", "t3"]
    assert kept((40, 0.0), (20, 0.0), (30, 0.0)) == ["t2", "t1", "t0"]  # no more than three: all, ties the shorter
    assert kept((40, 0.3), (20, 0.0)) == ["t1", "t0"] and kept((40, 0.0),) == ["t0"]


def test_takes_compare_their_poses_around_the_stroke(bandai):
    names = ["dataset-2_wave-both-hands_normal_002", "dataset-2_wave-both-hands_normal_003"]
    first, second = (build.find_gesture(motion_of(bandai, name), build.gesture_spec("wave")) for name in names)
    assert first.around_stroke.shape == (2 * 30, len(build.SPLICE_JOINTS), 3)
    assert build.pose_difference(first, first) == 0.0 < build.pose_difference(first, second) < 0.2
