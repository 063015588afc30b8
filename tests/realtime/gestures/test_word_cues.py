"""Transcripts (JSON word lists, SRT, WebVTT) and the trigger vocabulary."""

import json

import pytest

from gesturecast.controls import Word
from gesturecast.errors import UserError
from gesturecast.realtime.gestures.cues import Cue
from gesturecast.realtime.gestures.transcripts import read_transcript, words_from_list
from gesturecast.realtime.gestures.triggers import TriggerVocabulary, WordListener

WORDS = [Word("Hello", 0.4, 0.7), Word("everyone!", 0.7, 1.2), Word("Thank", 2.0, 2.2), Word("you", 2.2, 2.4),
         Word("come", 3.0, 3.2), Word("here,", 3.2, 3.5), Word("look", 4.0, 4.2), Word("here", 4.2, 4.5)]


def test_trigger_phrases_cue_their_gesture_at_the_first_word_longest_first():
    assert TriggerVocabulary().cues(WORDS) == [Cue("wave", 0.4, "Hello"), Cue("bow", 2.0, "Thank you"),
                                               Cue("call", 3.0, "come here,"), Cue("guide", 4.2, "here")]


def test_a_json_word_list_and_subtitles_read_the_same_words(tmp_path):
    (tmp_path / "w.json").write_text(json.dumps({"words": [{"word": "hi", "start": 1.0, "end": 1.5}]}))
    assert read_transcript(tmp_path / "w.json") == (Word("hi", 1.0, 1.5),)
    (tmp_path / "w.srt").write_text("1\n00:00:01,000 --> 00:00:02,000\nhello there\n\n2\n00:01:00,500 --> "
                                    "00:01:01,500\nbye\n")
    assert read_transcript(tmp_path / "w.srt") == (Word("hello", 1.0, 1.5), Word("there", 1.5, 2.0),
                                                   Word("bye", 60.5, 61.5))
    (tmp_path / "w.vtt").write_text("WEBVTT\n\n00:01.000 --> 00:02.000\nhooray\n")
    assert read_transcript(tmp_path / "w.vtt") == (Word("hooray", 1.0, 2.0),)


@pytest.mark.parametrize("items, words", [
    ([{"word": "hi"}], r"^t.json\[0\].start must be a finite number"),
    ([{"word": 3, "start": 1}], r"^t.json\[0\].word must be a string"),
    ([{"word": "hi", "start": 2, "end": 1}], r"^t.json\[0\].end is before its start"),
    ([{"word": "hi", "start": float("nan")}], r"^t.json\[0\].start must be a finite number"),
    ({"text": "hi"}, r"^t.json must be a list of 1..200000"),
])
def test_bad_word_lists_are_one_line(items, words):
    with pytest.raises(UserError, match=words):
        words_from_list(items, "t.json")


def test_a_transcript_that_is_not_json_names_the_suffixes(tmp_path):
    (tmp_path / "t.txt").write_text("hello")
    with pytest.raises(UserError, match=r"not a JSON word list.*\.srt or \.vtt"):
        read_transcript(tmp_path / "t.txt")


def test_words_heard_one_at_a_time_cue_a_phrase_when_its_last_word_arrives():
    listener = WordListener(TriggerVocabulary())
    heard = [listener.hear(Word(text, t, t + 0.3)) for t, text in enumerate(["thank", "you", "come", "here", "hi"])]
    assert [[(cue.gesture, cue.time) for cue in cues] for cues in heard] == [
        [], [("bow", 0.0)], [], [("call", 2.0)], [("wave", 4.0)]]
