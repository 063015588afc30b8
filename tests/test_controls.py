"""The typed controls: one check for every door, the one-line refusals, the schema generated from the declaration."""

import dataclasses
import json

import pytest

from gesturecast.bridges.control import message_controls
from gesturecast.controls import (
    STYLE_SETTINGS,
    ControlError,
    Gesture,
    StyleChange,
    Word,
    Words,
    control_schema,
    parse_controls,
    wire,
)
from gesturecast.errors import UserError
from gesturecast.models.motion.root_anchor import RootMode
from gesturecast.realtime.gestures.transcripts import read_transcript
from gesturecast.realtime.timing.clock import MonotonicClock
from gesturecast.settings import CHOICES, NUMBER_LIMITS, Settings


def validate_control(message: dict) -> dict:
    """A control message as a WebSocket client sends it, checked, in its wire form."""
    return wire(message_controls(message))


@pytest.mark.parametrize(
    ("message", "expected"),
    [
        ({"type": "control", "style": "happy"}, {"style": "happy"}),
        ({"type": "control", "guidance": 2}, {"guidance": 2.0}),
        ({"type": "control", "style": "a", "style2": "b", "gamma": 1.5, "token": "x"},
         {"style": "a", "style2": "b", "gamma": 1.5}),
        ({"type": "control", "prompt": "sweeping arms", "gamma": -2.0}, {"prompt": "sweeping arms", "gamma": -2.0}),
        ({"type": "control", "root": "locked"}, {"root": "locked"}),
        ({"type": "control", "part_styles": {"arms": "happy", "legs": "text:tired"}},
         {"part_styles": {"arms": "happy", "legs": "text:tired"}}),
        ({"type": "control", "part_styles": {}}, {"part_styles": {}}),
        ({"type": "control", "intensity": 0}, {"intensity": 0.0}),
        ({"type": "control", "pause": True, "intensity": 2}, {"pause": True, "intensity": 2.0}),
    ],
)
def test_valid_controls(message, expected):
    assert validate_control(message) == expected


@pytest.mark.parametrize(
    ("message", "reason"),
    [
        ({"type": "control"}, "at least one"),
        ({"type": "control", "volume": 3}, "unknown control field"),
        ({"type": "control", "guidance": "high"}, "guidance must be a finite number"),
        ({"type": "control", "guidance": True}, "guidance must be a finite number"),
        ({"type": "control", "guidance": float("nan")}, "finite"),
        ({"type": "control", "guidance": 11}, r"within \[0, 10\]"),
        ({"type": "control", "gamma": -2.5}, "gamma must be within"),
        ({"type": "control", "style": 5}, "style must be a string"),
        ({"type": "control", "prompt": "x" * 501}, "longer than 500"),
        ({"type": "control", "prompt": "  "}, "prompt must not be blank"),  # used to reach the session and fail there
        ({"type": "control", "style": "motion:/etc/passwd"}, "style: motion prompts name files on the server"),
        ({"type": "control", "style2": " motion:clip.bvh"}, "style2: motion prompts"),
        ({"type": "control", "root": "pinned"}, "root must be one of bounded, free, locked"),
        ({"type": "control", "root": 1}, "root must be one of"),
        ({"type": "control", "part_styles": ["arms=happy"]}, "part_styles must be an object"),
        ({"type": "control", "part_styles": {"arms": 3}}, "part_styles.arms must be a string"),
        ({"type": "control", "part_styles": {"arms": "motion:/etc/passwd"}}, "part_styles.arms: motion prompts"),
        ({"type": "control", "part_styles": {" ": "happy"}}, "body part name must be"),
        ({"type": "control", "part_styles": {f"p{i}": "happy" for i in range(9)}}, "more than 8 body parts"),
        ({"type": "control", "intensity": 2.5}, r"intensity must be within \[0, 2\], got 2.5"),
        ({"type": "control", "pause": 1}, "pause must be true or false"),
        ({"type": "control", "pause": "yes"}, "pause must be true or false"),
    ],
)
def test_invalid_controls(message, reason):
    with pytest.raises(ControlError, match=reason):
        validate_control(message)


def test_schema_lists_every_field():
    schema = control_schema()
    assert set(schema) == {"style", "style2", "part_styles", "prompt", "style_strength", "guidance", "audio_guidance",
                           "gamma", "root", "intensity", "pause", "gesture", "words", "text", "start", "end"}
    assert schema["intensity"] == {"type": "number", "min": 0.0, "max": 2.0}
    assert schema["pause"] == {"type": "boolean"}
    assert schema["style_strength"] == {"type": "number", "min": 0.0, "max": 2.0}
    assert schema["part_styles"]["type"] == "parts" and schema["part_styles"]["max_parts"] == 8
    assert schema["root"] == {"type": "choice", "choices": ["bounded", "free", "locked"]}
    assert schema["guidance"] == {"type": "number", "min": 0.0, "max": 10.0}


@pytest.mark.parametrize("words, reason", [
    ([], "must be a list of 1..500"),
    ([{"word": "hi", "start": 1.0, "end": 0.5}], r"words\[0\].end is before its start"),
    ([{"word": "hi", "start": float("nan")}], r"words\[0\].start must be a finite number"),
    ([{"word": "hi", "end": 1.0}], r"words\[0\].start must be a finite number"),
    (["hi"], r"words\[0\] must be an object with word, start and end"),
    ([{"word": "", "start": 1.0}], r"words\[0\].word must not be blank"),
])
def test_words_are_checked_before_they_reach_the_engine(words, reason):
    with pytest.raises(ControlError, match=reason):
        validate_control({"type": "control", "words": words})


def test_a_recognisers_other_keys_are_ignored_by_messages_and_transcripts_alike(tmp_path):
    items = [{"word": "hi", "start": 1.0, "end": 1.2, "probability": 0.9, "speaker": 2}]
    (tmp_path / "words.json").write_text(json.dumps(items))
    assert parse_controls({"words": items}) == (Words((Word("hi", 1.0, 1.2),)),)
    assert read_transcript(tmp_path / "words.json") == (Word("hi", 1.0, 1.2),)


def test_a_bad_word_is_refused_in_the_same_words_by_every_door(tmp_path):
    items = [{"word": "hi", "start": 2.0, "end": 1.0}]
    (tmp_path / "words.json").write_text(json.dumps(items))
    with pytest.raises(ControlError, match=r"^words\[0\].end is before its start$"):
        parse_controls({"words": items})
    with pytest.raises(ControlError, match=r"\[0\].end is before its start$"):
        read_transcript(tmp_path / "words.json")


def test_a_word_without_an_end_ends_where_it_starts():
    assert validate_control({"type": "control", "words": [{"word": "hello", "start": 2}]}) == {
        "words": [{"word": "hello", "start": 2.0, "end": 2.0}]}


def test_a_message_becomes_typed_controls_in_the_order_they_are_applied():
    controls = message_controls({"type": "control", "style": "happy", "words": [{"word": "hi", "start": 1}],
                                 "gesture": "wave", "part_styles": {"arms": "old"}, "token": "t"})
    assert controls == (Gesture("wave"), Words((Word("hi", 1.0, 1.0),)),
                        StyleChange(style="happy", part_styles=(("arms", "old"),)))
    with pytest.raises(dataclasses.FrozenInstanceError):
        controls[0].name = "bow"


def test_the_python_door_refuses_what_the_wire_refuses_in_the_same_words():
    for fields in ({"gamma": 50}, {"guidance": float("nan")}, {"audio_guidance": float("inf")}, {"volume": 1},
                   {"root": "flying"}, {"gesture": None}, {"guidance": "x"}):
        with pytest.raises(ControlError) as wire_error:
            message_controls({"type": "control", **fields})
        with pytest.raises(ControlError) as python_error:
            parse_controls(fields)
        assert str(python_error.value) == str(wire_error.value)
    with pytest.raises(ControlError, match=r"^gamma must be within \[-2, 3\], got 50$"):
        parse_controls({"gamma": 50})


def test_settings_and_the_schema_derive_from_the_one_declaration():
    """Every style setting is a Settings field with the same range or choices, and the schema lists exactly the
    declared fields: changing a range in StyleChange changes the flag, Settings, serve and the hello together."""
    settings_fields = {field.name for field in dataclasses.fields(Settings)}
    assert set(STYLE_SETTINGS) <= settings_fields
    for name, rule in STYLE_SETTINGS.items():
        if hasattr(rule, "low"):
            assert (NUMBER_LIMITS[name].minimum, NUMBER_LIMITS[name].maximum) == (rule.low, rule.high)
        if hasattr(rule, "choices"):
            assert tuple(CHOICES[name]) == rule.choices
    assert list(control_schema()) == [*STYLE_SETTINGS, "gesture", "words", "text", "start", "end"]
    assert STYLE_SETTINGS["root"].choices == tuple(mode.value for mode in RootMode)


def test_settings_refuse_a_pause_that_is_not_true_or_false():
    with pytest.raises(UserError, match="pause must be True or False, got 'no'"):
        Settings(pause="no")


def test_a_style_change_applies_to_settings_by_name():
    changed = Settings(prompt="calm").with_style(StyleChange(style="happy", gamma=0.5, part_styles=(("arms", "old"),)))
    assert (changed.style, changed.prompt, changed.gamma) == ("happy", None, 0.5)
    assert [part for part, _ in changed.part_styles] == ["arms"]
    assert Settings(prompt="calm").with_style(StyleChange(guidance=2.0)).prompt == "calm"


def test_every_style_setting_reaches_the_generator_through_settings():
    """StyleChange → Settings → the session's style and the generator's settings (what it hears of that style; and
    the session's root): no field is lost on the way."""
    from gesturecast.models.generator.style_prompt import StylePrompt
    from gesturecast.realtime.pose.style_hearing import StyleState
    from gesturecast.realtime.run.engine_setup import SessionFactory, generator_settings

    change = StyleChange(style="happy", style2="old", part_styles=(("arms", "sad"),), style_strength=0.5,
                         guidance=2.0, audio_guidance=1.5, gamma=0.25, root="locked", intensity=0.5, pause=True)
    settings = Settings().with_style(change)
    factory = SessionFactory(settings.replace(gestures=None))
    session = factory.session(MonotonicClock())
    assert session.controls.style == StyleState(StylePrompt("label", "happy"), StylePrompt("label", "old"), 0.25,
                                                (("arms", StylePrompt("label", "sad")),), 0.5)
    made = generator_settings(settings, factory.bundle, factory.budget())
    assert (made.guidance, made.audio_guidance, made.gamma) == (2.0, 1.5, 0.25)
    assert StyleState.of(made) == factory.config.hearing.heard(session.controls.style)
    assert session.config.root_mode.value == "locked"
    assert (session.controls.intensity, session.controls.paused, session.controls.gesture_size) == (0.5, True, 0.0)
    assert set(STYLE_SETTINGS) - set(change.changed()) == {"prompt"}  # a prompt replaces the style:
    assert Settings().with_style(StyleChange(prompt="calm")).style_prompt() == StylePrompt("text", "calm")


def test_a_refused_number_shows_its_excess():
    """``gamma=3.0000001`` was refused as "…got 3": the number format hid why."""
    with pytest.raises(ControlError, match=r"^gamma must be within \[-2, 3\], got 3.0000001$"):
        parse_controls({"gamma": 3.0000001})
    with pytest.raises(ControlError, match=r"got 1e\+300$"):
        parse_controls({"guidance": 1e300})


def test_an_ack_counts_the_words_instead_of_echoing_them():
    """Each ack repeated all 500 words of a message (about 30 KB)."""
    from gesturecast.bridges.control import ack

    words = [{"word": f"w{i}", "start": i * 0.1} for i in range(500)]
    reply = ack(message_controls({"type": "control", "words": words, "style": "happy"}))
    assert json.loads(reply) == {"type": "ack", "applied": {"words": 500, "style": "happy"}}
    assert len(reply) < 100
