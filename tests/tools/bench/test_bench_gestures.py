"""The gesture benchmark's parts: espeak-ng word times, the marked stories, the kinematic detector, the distance
between two plays of a gesture."""

from pathlib import Path

import numpy as np
import pytest

from gesturecast.frames import PoseFrame
from gesturecast.models.dataset.cache import read_take
from gesturecast.models.dataset.sources import bandai_takes, unpack_archive
from gesturecast.models.motion.motion_features import face_forward, features_to_motion, motion_to_features
from gesturecast.models.motion.skeleton import CANONICAL, CANONICAL_WITH_HANDS
from gesturecast.realtime.gestures.clips import AMPLITUDE_RANGE, ClipMotion, performance
from gesturecast.realtime.gestures.cues import Cue, CueOutcome
from gesturecast.realtime.gestures.strokes import body_frame_positions
from gesturecast.tools.bench.gesture_set.detector import OVERHEAD_M, Detector
from gesturecast.tools.bench.gesture_set.stories import LEAD_IN_S, make_story
from gesturecast.tools.bench.gestures import Run, play_distances, played_spans
from gesturecast.tools.bench.speech.espeak_words import words_at


def test_word_events_go_to_their_tokens_in_order_and_a_merged_word_is_placed_between():
    text = "Thanks so much for the candles."
    events = [(1, 6, 0), (8, 2, 425), (9, 2, 650), (16, 3, 898), (0, 0, 1000), (24, 8, 1400)]  # "so" drifts
    timed = words_at(text, events, duration=2.0)
    assert [w.text for w in timed] == text.split()
    assert [w.start for w in timed[:4]] == [0.0, 0.425, 0.65, 0.898]
    assert 0.898 < timed[4].start < 1.4 == timed[5].start  # "the": spoken with "for", placed by its characters


def test_a_story_marks_the_intended_cue_on_its_words_start(tmp_path):
    story = make_story("s", ("[wave]Hi, [bow]thanks for calling.",), cache=tmp_path)
    assert [(c.intent, c.word) for c in story.intended] == [("greeting", "Hi,"), ("thanks", "thanks")]
    starts = {w.text: w.start for w in story.words}
    assert story.intended[0].time == starts["Hi,"] == LEAD_IN_S and story.intended[1].time == starts["thanks"]
    assert all(a.start < b.start for a, b in zip(story.words, story.words[1:], strict=False))


def body_with(right_wrist: np.ndarray) -> np.ndarray:
    """(T, J, 3) a standing body (joints at fixed places) whose right wrist follows ``right_wrist`` (T, 3)."""
    names = CANONICAL_WITH_HANDS.names
    body = np.zeros((len(right_wrist), len(names), 3))
    places = {"Head": (0, 1.6, 0), "LeftUpperArm": (0.2, 1.4, 0), "RightUpperArm": (-0.2, 1.4, 0),
              "LeftLowerArm": (0.2, 1.1, 0), "RightLowerArm": (-0.2, 1.1, 0), "LeftHand": (0.2, 0.85, 0)}
    for name, place in places.items():
        body[:, names.index(name)] = place
    body[:, names.index("RightHand")] = right_wrist
    return body


def test_a_farewell_must_wave_and_a_cheer_must_be_overhead():
    t = np.arange(60) / 30
    up = np.stack([-0.2 + 0.05 * np.sin(2 * np.pi * 2 * t), np.full(60, 1.5), np.zeros(60)], axis=1)  # waving
    held = up.copy()
    held[:, 0] = -0.2  # the same height, held still
    names = CANONICAL_WITH_HANDS.names
    assert Detector(body_with(up), names).events("wave-right")
    assert not Detector(body_with(held), names).events("wave-right")
    overhead = held.copy()
    overhead[:, 1] = 1.6 + OVERHEAD_M + 0.05
    assert not Detector(body_with(overhead), names).events("raise-both")  # one hand up is no cheer
    both = body_with(overhead)
    both[:, names.index("LeftHand"), 1] = overhead[:, 1]
    assert Detector(both, names).events("raise-both")


RAW_CACHE = Path(__file__).resolve().parents[3] / ".cache" / "raw"  # where `gesturecast data build` unpacks


@pytest.fixture(scope="module")
def recorded_guides(shared_data) -> list:
    """Every recorded guide take of Bandai dataset 1 (one per style), unpacked once into .cache/raw."""
    takes = bandai_takes(unpack_archive(shared_data / "bandai" / "dataset-1.tar.xz", RAW_CACHE / "bandai"))
    return sorted((t for t in takes if "_guide_" in t.name), key=lambda t: t.name)


@pytest.mark.parametrize("amplitude", [AMPLITUDE_RANGE[0], 1.0, AMPLITUDE_RANGE[1]])
def test_the_detector_finds_the_recorded_guides_at_the_amplitudes_performances_use(recorded_guides, amplitude):
    assert len(recorded_guides) == 15
    missed = []
    for take in recorded_guides:
        features = motion_to_features(face_forward(read_take(take)[0])).astype(np.float32)  # (T, D)
        played = performance(ClipMotion("guide", features, 0, ("arms", "torso")), 1.0, amplitude)
        body = body_frame_positions(features_to_motion(played.features))  # (T, J, 3)
        if not Detector(body, CANONICAL.names).events("guide"):
            missed.append(take.name)
    assert missed == ["dataset-1_guide_tired_001"]  # its arm sweeps while out: not held (the detector's rule)


def test_arms_at_rest_or_bent_in_front_are_no_guide():
    t = np.arange(60) / 30
    names = CANONICAL_WITH_HANDS.names
    at_rest = np.stack([np.full(60, -0.2), np.full(60, 0.85), np.zeros(60)], axis=1)  # hanging below the shoulder
    bent = np.stack([np.full(60, -0.2), np.full(60, 1.2), 0.2 + 0.02 * np.sin(2 * np.pi * t)], axis=1)  # a beat
    held_out = np.stack([np.full(60, -0.2), np.full(60, 1.35), np.full(60, 0.5)], axis=1)  # straight ahead
    assert not Detector(body_with(at_rest), names).events("guide")
    assert not Detector(body_with(bent), names).events("guide")
    straight = body_with(held_out)
    straight[:, names.index("RightLowerArm")] = (straight[:, names.index("RightUpperArm")] + held_out) / 2  # elbow
    assert Detector(straight, names).events("guide-right")


def test_decisions_only_counts_decided_missed_unintended_and_narration_cues():
    from gesturecast.realtime.gestures.phrases import PhraseCues
    from gesturecast.tools.bench.gesture_set.decisions import decisions

    phrases = PhraseCues(("wave", "bow", "wave-right", "guide"))
    stories = {"call": ("[wave]Hi, [bow]thanks for calling.", "[bow]Thanks to the rain, we stayed in.",
                        "Goodbye, everyone.")}
    narration = (("n", ("This is the third day of the trial.", "Hello, everyone, and welcome.")),)
    result = decisions(phrases, stories, narration)
    assert (result["intended"], result["decided"], result["unintended_in_stories"]) == (3, 2, 1)
    assert result["misses"] == [{"mark": "bow", "decided": None, "sentence": "[bow]Thanks to the rain, we stayed in."}]
    assert [row["gesture"] for row in result["narration"]] == ["wave", "wave"]
    assert result["narration_sentences"] == 2


def test_two_plays_are_compared_over_the_frames_both_play():
    names = [set()] * 5 + [{"bow"}] * 20 + [{"bow", "wave"}] * 3 + [{"wave"}] * 10 + [{"bow"}] * 30 + [set()] * 5
    spans = played_spans(names, "bow", [12, 50])
    assert spans == [(12, 5, 28), (50, 38, 68)]  # the second starts where the wave leaves off
    frames = [PoseFrame(t, t / 30, t / 30, np.zeros(3), np.zeros((1, 4)), gesture="+".join(sorted(n)))
              for t, n in enumerate(names)]
    body = np.zeros((len(names), 22, 3))
    body[38:68, :, 0] = 0.1  # the second play 10 cm to the left all along
    run = Run(frames, [CueOutcome(Cue("bow", 0.4), "on time", 0.4), CueOutcome(Cue("bow", 50 / 30), "on time",
                                                                                      50 / 30)], 2, [], 1.0)
    (pair,) = play_distances(run, body)
    assert pair["distance_m"] == pytest.approx(0.1) and pair["seconds"] == pytest.approx((7 + 16) / 30, abs=0.01)
