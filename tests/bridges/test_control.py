import pytest

from gesturecast.bridges.control import ControlError, control_schema, validate_control


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
    ],
)
def test_invalid_controls(message, reason):
    with pytest.raises(ControlError, match=reason):
        validate_control(message)


def test_schema_lists_every_field():
    schema = control_schema()
    assert set(schema) == {"style", "style2", "part_styles", "prompt", "style_strength", "guidance", "audio_guidance",
                           "gamma", "root", "gesture", "words"}
    assert schema["style_strength"] == {"type": "number", "min": 0.0, "max": 2.0}
    assert schema["part_styles"]["type"] == "parts" and schema["part_styles"]["max_parts"] == 8
    assert schema["root"] == {"type": "choice", "choices": ["bounded", "free", "locked"]}
    assert schema["guidance"] == {"type": "number", "min": 0.0, "max": 10.0}


@pytest.mark.parametrize("words, reason", [
    ([], "must be a list of 1..500"),
    ([{"word": "hi", "start": 1.0, "end": 0.5}], r"words\[0\].end is before its start"),
    ([{"word": "hi", "start": float("nan")}], r"words\[0\].start must be a finite number"),
    ([{"word": "hi", "start": 1.0, "speaker": 2}], "word, start and end only"),
    ([{"word": "", "start": 1.0}], r"words\[0\].word must not be blank"),
])
def test_words_are_checked_before_they_reach_the_engine(words, reason):
    with pytest.raises(ControlError, match=reason):
        validate_control({"type": "control", "words": words})


def test_a_word_without_an_end_ends_where_it_starts():
    assert validate_control({"type": "control", "words": [{"word": "hello", "start": 2}]}) == {
        "words": [{"word": "hello", "start": 2.0, "end": 2.0}]}
