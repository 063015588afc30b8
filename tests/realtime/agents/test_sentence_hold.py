"""Sentence text without word times in a Pipecat pipeline: a TTS service's sentence after its audio or before it
lands its gesture on the word (the sentence hold), the hold's wall-time bound lets the voice go on, and in
``audio="input"`` mode the STT's transcription cues the user's own gestures, late, and counted."""

from __future__ import annotations

import asyncio

import numpy as np
import pytest

pytest.importorskip("pipecat", reason="Pipecat is not installed (pip install 'gesturecast[pipecat]')")

from pipecat.frames.frames import (  # noqa: E402
    EndFrame,
    Frame,
    InputAudioRawFrame,
    OutputAudioRawFrame,
    StartFrame,
    TranscriptionFrame,
    TTSStartedFrame,
    TTSStoppedFrame,
    TTSTextFrame,
    VADUserStartedSpeakingFrame,
)
from pipecat_frames import Late, Recorder, run_pipeline  # noqa: E402

from gesturecast.models.audio.files import SAMPLE_RATE  # noqa: E402
from gesturecast.realtime.agents.pipecat_processor import GesturecastProcessor  # noqa: E402
from gesturecast.realtime.run.stream import Stream  # noqa: E402
from gesturecast.settings import Settings  # noqa: E402
from gesturecast.tools.bench.speech.espeak_words import spoken  # noqa: E402

GREETING = "Hello everyone, and welcome to the show."
THANKS = "Thank you so much for watching."
LEAD_IN = np.zeros(SAMPLE_RATE // 2, np.float32)  # (8000,) the stream's first half second: silence
STROKE_TOLERANCE_S = 0.3
BOUND_S = 60.0


@pytest.fixture(scope="module")
def sentences(tmp_path_factory) -> dict[str, tuple[np.ndarray, list]]:
    cache = tmp_path_factory.mktemp("espeak")
    return {text: spoken(text, cache) for text in (GREETING, THANKS)}


def frames_of(audio: np.ndarray, frame_type: type = OutputAudioRawFrame) -> list[Frame]:
    """(n,) float audio → 20 ms 16-bit frames at 16 kHz."""
    pcm = np.round(audio * 32767).astype("<i2")
    return [frame_type(audio=pcm[at : at + 320].tobytes(), sample_rate=SAMPLE_RATE, num_channels=1)
            for at in range(0, len(pcm), 320)]


def placed_by_alignment(processor: GesturecastProcessor) -> int:
    """Sentences placed on their own audio: aligned, all or most of their words (espeak-ng's audio of a sentence
    varies a little with what it spoke before, and the decoder may then stop a word short), or by the voiced onset
    when only their first word cues."""
    counts = processor.session.gestures.alignments.to_dict()
    return counts["aligned"] + counts["partly"] + counts["onset"]


def stroke_error(processor: GesturecastProcessor, gesture: str, word_s: float) -> float | None:
    """Stroke − word (s) of the cue of ``gesture`` nearest the word (None: dropped); AssertionError without one."""
    outcomes = [o for o in processor.session.gestures.cues.outcomes if o.cue.gesture == gesture]
    assert outcomes, f"no {gesture} cue"
    nearest = min(outcomes, key=lambda o: abs(o.cue.time - word_s))
    return None if nearest.stroke_time is None else nearest.stroke_time - word_s


@pytest.mark.parametrize("order", ["after", "before"])
def test_a_sentence_with_its_text_after_or_before_its_audio_lands_its_gesture_on_the_word(sentences, order):
    audio, timed = sentences[GREETING]
    text = TTSTextFrame(GREETING, text_type="sentence")
    voice = frames_of(np.concatenate([LEAD_IN, audio]))
    utterance = [TTSStartedFrame(), *([*voice, text] if order == "after" else [text, *voice]), TTSStoppedFrame()]
    processor = GesturecastProcessor(stream=Stream(Settings(), paced=False))
    recorder = Recorder()
    asyncio.run(asyncio.wait_for(run_pipeline([processor, recorder], utterance), BOUND_S))

    error = stroke_error(processor, "wave", 0.5 + timed[0].start)
    assert error is not None and abs(error) <= STROKE_TOLERANCE_S
    assert [id(f) for f in recorder.frames if not isinstance(f, (StartFrame, EndFrame))] == [id(f) for f in utterance]
    assert processor.audio_seconds == pytest.approx(len(voice) * 0.02, abs=0.03)  # every sample pushed once
    assert placed_by_alignment(processor) == 1


def test_without_the_hold_a_sentence_after_its_audio_comes_too_late_for_its_word(sentences):
    audio, timed = sentences[GREETING]
    utterance = [TTSStartedFrame(), *frames_of(np.concatenate([LEAD_IN, audio])),
                 TTSTextFrame(GREETING, text_type="sentence"), TTSStoppedFrame()]
    processor = GesturecastProcessor(stream=Stream(Settings(), paced=False), sentence_hold_s=0.0)
    asyncio.run(asyncio.wait_for(run_pipeline([processor], utterance), BOUND_S))
    error = stroke_error(processor, "wave", 0.5 + timed[0].start)
    assert error is None or error > STROKE_TOLERANCE_S  # its latents were generated before the text came


def test_the_bound_lets_the_voice_go_on_and_the_late_text_is_still_aligned_and_counted(sentences):
    audio, timed = sentences[THANKS]
    voice = frames_of(np.concatenate([LEAD_IN, audio]))
    utterance = [TTSStartedFrame(), *voice, TTSTextFrame(THANKS, text_type="sentence"), TTSStoppedFrame()]
    processor = GesturecastProcessor(stream=Stream(Settings(), paced=False), sentence_hold_s=0.1)
    recorder = Recorder()
    late_text = Late(TTSTextFrame, 1.0)  # the text comes 1 s after the audio
    asyncio.run(asyncio.wait_for(run_pipeline([late_text, processor, recorder], utterance), BOUND_S))

    passed = [f for f in recorder.frames if isinstance(f, OutputAudioRawFrame)]
    assert [id(f) for f in passed] == [id(f) for f in voice]  # the voice went on before its text came
    assert placed_by_alignment(processor) == 1  # aligned on the audio heard
    error = stroke_error(processor, "bow", 0.5 + timed[0].start)
    assert error is None or error > STROKE_TOLERANCE_S  # late or dropped, counted by the cue plan


def test_the_users_transcription_cues_their_gesture_late_and_counted(sentences):
    audio, timed = sentences[THANKS]
    said = [VADUserStartedSpeakingFrame(start_secs=0.2), *frames_of(np.concatenate([LEAD_IN, audio, LEAD_IN]),
                                                                     InputAudioRawFrame)]
    transcription = TranscriptionFrame(THANKS, user_id="user", timestamp="")
    processor = GesturecastProcessor(stream=Stream(Settings(), paced=False), audio="input")
    late = Late(TranscriptionFrame, 1.0)  # after the user's speech, as an STT's final text comes
    asyncio.run(asyncio.wait_for(run_pipeline([late, processor], [*said, transcription]), BOUND_S))

    assert placed_by_alignment(processor) == 1
    error = stroke_error(processor, "bow", 0.5 + timed[0].start)
    assert error is None or error > 0  # decided; after its word, never before
