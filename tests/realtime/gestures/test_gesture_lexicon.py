"""The gesture lexicon at run time: the shipped lexicon read back, a user's folder, damaged files."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from gesturecast.errors import UserError
from gesturecast.models.motion.body_parts import PART_NAMES
from gesturecast.models.motion.motion_features import FEATURE_DIM, features_to_motion
from gesturecast.models.motion.retarget import motion_to_bvh
from gesturecast.realtime.gestures import lexicon as gl
from gesturecast.realtime.gestures.lexicon import current_name
from gesturecast.realtime.gestures.phrases import PhraseCues
from gesturecast.realtime.gestures.strokes import body_frame_positions, pose_distance, stroke_frame
from gesturecast.tools.gestures import build

SHIPPED_MAX_BYTES = 3_000_000
FPS = 30


# ---------------------------------------------------------------------------------------------------------------
# the shipped lexicon (models/weights/gestures): no shared data needed


@pytest.fixture(scope="module")
def shipped() -> gl.Lexicon:
    return gl.load_lexicon()


def test_the_shipped_lexicon_holds_every_gesture_as_small_float16_clips(shipped):
    assert set(build.GESTURE_NAMES) <= set(shipped.entries)
    folder = gl.default_lexicon_dir()
    size = sum(path.stat().st_size for path in folder.iterdir() if path.is_file())
    assert size < SHIPPED_MAX_BYTES, f"{size} bytes"
    for entry in shipped:
        assert entry.variants and entry.styles[0] == gl.DEFAULT_STYLE and len(entry.styles) <= build.MAX_VARIANTS
        assert set(entry.parts) <= set(PART_NAMES)
        assert ("legs" in entry.parts) == (entry.name in ("bow", "call"))  # a bow bends at the hips (legs part)
        for variant in entry.variants:
            assert variant.features.dtype == np.float16 and variant.features.shape[1] == FEATURE_DIM == 136
            assert np.isfinite(variant.features).all()
            assert 0 <= variant.stroke_frame < variant.num_frames and variant.fps == FPS
            assert variant.duration <= 8.0 and variant.source.startswith("dataset-")
    assert shipped["bow"].parts == ("arms", "torso", "legs") and shipped["wave"].parts == ("arms",)
    assert "CC BY-NC 4.0" in shipped.license


def test_a_farewell_plays_the_gesture_its_trigger_words_name_and_the_old_name_still_works(shipped):
    """Named by what a person sees: Bandai's "bye" holds a hand up (``hand-up``); a farewell waves one hand."""
    assert PhraseCues(shipped.entries).gesture_of("farewell") == "wave-right" == shipped.triggers()["goodbye"]
    assert "bye" not in shipped and shipped["hand-up"].description == "holds a hand up at shoulder height"
    assert current_name("bye", shipped.entries) == "hand-up" and current_name("bye", {"bye": 1}) == "bye"


def test_the_shipped_triggers_name_the_gestures(shipped):
    triggers = shipped.triggers()
    expected = {"hello": "wave", "hi": "wave", "hey": "wave", "welcome": "wave", "bye": "wave-right",
                "goodbye": "wave-right", "see you": "wave-right", "thank you": "bow", "thanks": "bow",
                "hooray": "raise-both", "yay": "raise-both", "congratulations": "raise-both", "here": "guide",
                "there": "guide", "look at": "guide", "this": "guide", "come on": "call", "come here": "call"}
    assert {word: triggers.get(word) for word in expected} == expected


def test_a_style_holds_up_to_three_distinct_takes_where_the_data_has_several(shipped):
    for entry in shipped:
        for style in entry.styles:
            takes = entry.takes(style)
            assert 1 <= len(takes) <= build.MAX_TAKES and [t.take for t in takes] == list(range(len(takes)))
            assert takes[0] is entry.variant(style) and len({t.source for t in takes}) == len(takes)
    for name in ("wave", "wave-left", "wave-right", "raise-both", "raise-left", "raise-right"):  # dataset 2
        assert all(len(shipped[name].takes(style)) == 3 for style in shipped[name].styles), name
    assert len(shipped["call"].takes("neutral")) == 2 and len(shipped["bow"].takes("neutral")) == 1  # dataset 1


def test_a_variant_is_found_by_any_spelling_of_its_style_else_neutral(shipped):
    wave = shipped["wave"]
    assert wave.variant("elderly").style == "old" and wave.variant("Exhausted").style == "tired"
    assert wave.variant("normal").style == wave.variant().style == wave.variant("happy").style == "neutral"
    assert wave.variant("a calm speaker").style == "neutral"  # a free-text prompt names no clip


# ---------------------------------------------------------------------------------------------------------------
# a user's folder


@pytest.fixture(scope="module")
def user_clip(shipped, tmp_path_factory) -> tuple[Path, np.ndarray]:
    """A folder holding one canonical BVH (the shipped neutral wave) and that clip's features."""
    folder = tmp_path_factory.mktemp("user_gestures")
    features = shipped["wave"].variant().features.astype(np.float64)
    motion_to_bvh(features_to_motion(features), folder / "my_wave.bvh")
    return folder, features


def write_mapping(folder: Path, mapping: object) -> Path:
    path = folder / gl.USER_MAPPING_FILE
    path.write_text(mapping if isinstance(mapping, str) else json.dumps(mapping))
    return folder


def test_a_user_folder_is_read_with_the_same_retargeting(user_clip):
    folder, features = user_clip
    lexicon = gl.load_lexicon(write_mapping(folder, {
        "hiya": {"clip": "my_wave.bvh", "triggers": ["hiya", "howdy"], "parts": ["torso", "arms"], "stroke": 0.5},
        "wave-again": {"clip": "my_wave.bvh", "triggers": "yo", "style": "happy"}}))
    entry = lexicon["hiya"]
    assert entry.parts == ("arms", "torso") and entry.triggers == ("hiya", "howdy") and entry.styles == ("neutral",)
    assert entry.takes("neutral") == (entry.variant(),)  # one clip per gesture: one take
    variant = entry.variant()
    assert variant.stroke_frame == 15 and variant.features.shape == features.shape
    assert np.abs(variant.features[:, 4:] - features[:, 4:]).max() < 0.01  # rotations come back through the BVH
    other = lexicon["wave-again"]
    assert other.parts == ("arms",) and other.styles == ("happy",) and lexicon.triggers()["yo"] == "wave-again"
    body = body_frame_positions(features_to_motion(features))
    assert other.variant().stroke_frame == stroke_frame(pose_distance(body))  # the default stroke


@pytest.mark.parametrize(("mapping", "field"), [
    ({"x": {"clip": "missing.bvh", "triggers": ["a"]}}, "'clip'"),
    ({"x": {"triggers": ["a"]}}, "'clip'"),
    ({"x": {"clip": "my_wave.bvh", "triggers": ["a"], "parts": ["arms", "tail"]}}, "unknown part 'tail'"),
    ({"x": {"clip": "my_wave.bvh", "triggers": ["a"], "stroke": 60.0}}, "'stroke' 60 s is outside the clip"),
    ({"x": {"clip": "my_wave.bvh", "triggers": ["a"], "stroke": -1}}, "'stroke'"),
    ({"x": {"clip": "my_wave.bvh", "triggers": ["a"], "stroke": "soon"}}, "'stroke'"),
    ({"x": {"clip": "my_wave.bvh", "triggers": []}}, "'triggers'"),
    ({"x": {"clip": "my_wave.bvh", "triggers": ["", " "]}}, "'triggers'"),
    ({"x": {"clip": "my_wave.bvh"}}, "'triggers'"),
    ({"x": {"clip": "my_wave.bvh", "triggers": ["a"], "style": "grumpy"}}, "'style'"),
    ({"x": {"clip": "my_wave.bvh", "triggers": ["a"], "trigger": ["b"]}}, "unknown field 'trigger'"),
    ({"Big Wave": {"clip": "my_wave.bvh", "triggers": ["a"]}}, "name"),
    ({"x": ["my_wave.bvh"]}, "must be an object"),
    ({}, "names no gestures"),
    ([1, 2], "JSON object"),
    ("{not json", "not valid JSON"),
    ({"joint_map": "nope.json", "x": {"clip": "my_wave.bvh", "triggers": ["a"]}}, "'joint_map'"),
])
def test_bad_user_entries_are_one_line_errors_naming_the_file_and_field(user_clip, mapping, field):
    folder, _ = user_clip
    with pytest.raises(UserError) as error:
        gl.load_lexicon(write_mapping(folder, mapping))
    message = str(error.value)
    assert "\n" not in message and str(folder / gl.USER_MAPPING_FILE) in message and field in message, message


def test_a_folder_without_a_lexicon_or_mapping_is_refused(tmp_path):
    with pytest.raises(UserError, match="neither lexicon.json"):
        gl.load_lexicon(tmp_path)
    with pytest.raises(UserError, match="not found"):
        gl.load_lexicon(tmp_path / "absent")


def test_a_damaged_built_lexicon_is_a_one_line_error(shipped, tmp_path):
    build.save_lexicon(shipped, tmp_path)
    (tmp_path / gl.CLIPS_FILE).write_bytes(b"not a zip")
    with pytest.raises(UserError, match="damaged gesture lexicon"):
        gl.load_lexicon(tmp_path)


def test_reading_a_lexicon_loads_neither_torch_nor_the_builder():
    code = ("import sys; from gesturecast.realtime.gestures.lexicon import load_lexicon; load_lexicon(); "
            "loaded = [m for m in sys.modules if m == 'torch' or m.startswith(('gesturecast.tools', "
            "'gesturecast.models.dataset', 'gesturecast.models.training'))]; "
            "assert not loaded, loaded")
    subprocess.run([sys.executable, "-c", code], check=True)
