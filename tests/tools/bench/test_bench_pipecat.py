"""`gesturecast bench pipecat`'s parts: the frames a TTS service pushes in each order, and how an intended cue is
matched to what the stream's cue plan made of it."""

import numpy as np
import pytest

pytest.importorskip("pipecat", reason="Pipecat is not installed (pip install 'gesturecast[pipecat]')")

from pipecat.frames.frames import OutputAudioRawFrame, TTSTextFrame  # noqa: E402

from gesturecast.realtime.gestures.cues import Cue, CueOutcome  # noqa: E402
from gesturecast.tools.bench.agents.pipecat_orders import cue_rows  # noqa: E402
from gesturecast.tools.bench.agents.tts_feed import IntendedCue, Sentence, sentence_frames  # noqa: E402

SENTENCE = Sentence("Hello there friend.", np.zeros(16000, np.float32), (0.0, 0.4, 0.7))  # 1 s: 50 frames of 20 ms


def kinds(frames) -> list[str]:
    return ["text:" + f.text if isinstance(f, TTSTextFrame) else "audio" for f in frames
            if isinstance(f, (TTSTextFrame, OutputAudioRawFrame))]


def test_each_order_reports_the_text_where_its_service_does():
    after, before, words = (kinds(sentence_frames(SENTENCE, order)) for order in ("after", "before", "words"))
    assert after == ["audio"] * 50 + ["text:Hello there friend."]
    assert before == ["text:Hello there friend."] + ["audio"] * 50
    assert [k for k in words if k != "audio"] == ["text:Hello", "text:there", "text:friend."]
    assert words.index("text:there") == 21 and words.index("text:friend.") == 37  # before 0.4 s's and 0.7 s's frame
    assert sum(k == "audio" for k in words) == 50


def test_a_cue_is_a_hit_only_with_its_gesture_stroke_within_half_a_second_of_the_word():
    intended = [IntendedCue("r", "greeting", "Hello", 2.0), IntendedCue("r", "thanks", "Thanks", 6.0),
                IntendedCue("r", "farewell", "Bye", 9.0)]
    outcomes = [CueOutcome(Cue("wave", 2.0, "Hello"), "late", 2.45),
                CueOutcome(Cue("bow", 6.1, "Thanks"), "dropped", None),
                CueOutcome(Cue("wave", 9.0, "Bye"), "on time", 9.0)]  # the wrong gesture for a farewell
    rows = cue_rows(intended, outcomes, {"greeting": "wave", "thanks": "bow", "farewell": "wave-right"})
    assert [(r["outcome"], r["stroke_error_ms"], r["hit"]) for r in rows] == [
        ("late", 450, True), ("dropped", None, False), (None, None, False)]
