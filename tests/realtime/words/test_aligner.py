"""The sentence aligner on real espeak-ng speech: words placed near the synthesiser's own word starts, and a sentence
it cannot align still yields every word, in order, inside its audio."""

import subprocess
import sys

import numpy as np
import pytest

from gesturecast.realtime.words.aligner import SentenceAligner, SentenceAudio
from gesturecast.realtime.words.outcomes import AlignmentCounts
from gesturecast.realtime.words.script import script_sentences, sentences
from gesturecast.realtime.words.voicing import SAMPLE_RATE, pauses, voiced_span
from gesturecast.tools.bench.speech.espeak_words import spoken

SENTENCE = "Now let me show you the map of the old city."
SCRIPT = ("Hello everyone, and welcome back to the channel. Today we are going to build a tiny robot. "
          "Then connect the red wire. Hooray, we did it!")
OFFSET_S = 7.0  # the audio's first sample in stream time


@pytest.fixture(scope="module")
def aligner() -> SentenceAligner:
    return SentenceAligner()


def starts_error(words, timed, offset: float = 0.0) -> np.ndarray:
    assert [word.text for word in words] == [word.text for word in timed]
    return np.abs(np.array([word.start - offset for word in words]) - np.array([word.start for word in timed]))


def test_a_sentence_is_placed_on_its_own_speech(aligner, tmp_path):
    audio, timed = spoken(SENTENCE, tmp_path)
    alignment = aligner.align(SentenceAudio(SENTENCE, audio, OFFSET_S))
    assert alignment.method == "aligned" and alignment.confidence == 1.0
    assert np.median(starts_error(alignment.words, timed, OFFSET_S)) < 0.05


def test_a_word_outside_the_dictionary_is_placed_between_its_neighbours(aligner, tmp_path):
    text = "Now let me show you the zorblax of the old city."
    audio, timed = spoken(text, tmp_path)
    alignment = aligner.align(SentenceAudio(text, audio, 0.0))
    assert alignment.method == "partly" and 0.8 < alignment.confidence < 1.0
    unknown = alignment.words[6]
    assert unknown.text == "zorblax" and alignment.words[5].end <= unknown.start < alignment.words[7].start
    assert np.median(starts_error(alignment.words, timed)) < 0.05


def test_words_the_alignment_lays_a_silence_over_are_left_to_the_fallback(tmp_path):
    """The West Midlands voice's "and welcome": the US-English model matches silence over 0.7 s of its speech and
    crams the words after it into the rest; they are spread over the speech instead, and the sentence counts as
    partly aligned. espeak-ng's audio of a sentence varies with what the process spoke before, so it is spoken by a
    fresh process, and aligned by a fresh aligner (whose voice has heard nothing else)."""
    text, voice = "Hello there, and welcome to the museum.", "en-gb-x-gbcwmd+m2"
    subprocess.run([sys.executable, "-c", "import sys; from pathlib import Path; from gesturecast.tools.bench.speech."
                    f"espeak_words import spoken; spoken(sys.argv[1], Path(sys.argv[2]), {voice!r})", text,
                    str(tmp_path)], check=True)
    audio, timed = spoken(text, tmp_path, voice=voice)  # read from that process's cache
    alignment = SentenceAligner().align(SentenceAudio(text, audio, 0.0))
    assert alignment.method == "partly" and alignment.confidence == 2 / 7
    assert starts_error(alignment.words, timed)[3] < 0.3  # "welcome": was 0.69 s late


def test_a_sentence_it_cannot_align_still_yields_its_words(aligner, tmp_path):
    text = "Zorblax quindle fremp!"
    audio, _ = spoken(text, tmp_path)
    alignment = aligner.align(SentenceAudio(text, audio, OFFSET_S))
    assert alignment.method == "spread" and alignment.confidence == 0.0
    first, last = voiced_span(audio)
    starts = [word.start for word in alignment.words]
    assert [word.text for word in alignment.words] == text.split()
    assert starts == sorted(starts) and starts[0] == pytest.approx(OFFSET_S + first)
    assert alignment.words[-1].end == pytest.approx(OFFSET_S + last)


def test_a_sentence_without_its_audio_is_spread_and_counted_as_failed(aligner):
    counts = AlignmentCounts()
    alignment = aligner.align(SentenceAudio("Hello there", np.zeros(SAMPLE_RATE // 2, np.float32), 2.0))
    counts.count(alignment, "Hello there")
    assert alignment.method == "failed" and [word.text for word in alignment.words] == ["Hello", "there"]
    assert alignment.words[0].start == 2.0 and alignment.words[-1].end > 2.0
    assert counts.to_dict()["failed"] == 1 and counts.to_dict()["aligned_words"] == 0


def test_a_script_is_placed_sentence_by_sentence_over_its_recording(aligner, tmp_path):
    audio, timed = spoken(SCRIPT, tmp_path)
    placed = script_sentences(SCRIPT, audio)
    assert [sentence.text for sentence in placed] == sentences(SCRIPT) and len(placed) == 4
    ends = [sentence.start + len(sentence.samples) / SAMPLE_RATE for sentence in placed]
    assert all(end <= later.start + 1e-9 for end, later in zip(ends, placed[1:], strict=False))
    words = [word for sentence in placed for word in aligner.align(sentence).words]
    assert np.median(starts_error(words, timed)) < 0.08
    starts = [word.start for word in words]
    assert starts == sorted(starts)


def test_the_aligner_counts_its_cpu_time(aligner, tmp_path):
    audio, _ = spoken(SENTENCE, tmp_path)
    before = aligner.cpu_s
    aligner.align(SentenceAudio(SENTENCE, audio, 0.0))
    assert aligner.cpu_s > before


def test_pauses_are_the_middles_of_unvoiced_runs():
    tone = 0.3 * np.sin(np.arange(SAMPLE_RATE) * 0.3).astype(np.float32)  # (16000,) 1 s
    audio = np.concatenate([tone, np.zeros(SAMPLE_RATE // 2, np.float32), tone])
    assert pauses(audio) == [pytest.approx(1.25)]
    assert voiced_span(audio) == (0.0, 2.5)


def test_an_alignment_depends_only_on_its_own_aligners_sentences(tmp_path):
    first, _ = spoken(SENTENCE, tmp_path)
    second, _ = spoken("Thank you so much for watching.", tmp_path)
    alone = SentenceAligner().align(SentenceAudio("Thank you so much for watching.", second, 0.0))
    other = SentenceAligner()
    for _ in range(3):  # another stream's sentences on the pooled decoder
        other.align(SentenceAudio(SENTENCE, first, 0.0))
    again = SentenceAligner().align(SentenceAudio("Thank you so much for watching.", second, 0.0))
    assert again == alone
    assert other.cepstral_mean is not None


def test_a_hyphenated_word_is_aligned_by_its_parts(aligner, tmp_path):
    text = "Take care, and bye-bye for now."
    audio, timed = spoken(text, tmp_path)
    alignment = aligner.align(SentenceAudio(text, audio, 0.0))
    assert alignment.method == "aligned"  # "bye-bye" is not in the dictionary; "bye" is
    assert abs(alignment.words[3].start - timed[3].start) < 0.08


def test_a_prefix_keeps_the_audio_up_to_a_gap_after_its_words():
    tone = 0.3 * np.sin(np.arange(SAMPLE_RATE // 2) * 0.3).astype(np.float32)  # (8000,) 0.5 s
    gap = np.zeros(SAMPLE_RATE // 10, np.float32)  # (1600,) 0.1 s
    audio = np.concatenate([tone, gap, tone, gap, tone, gap, tone])  # four "words", 2.3 s
    sentence = SentenceAudio("one two three four.", audio, 5.0)
    prefix = sentence.prefix(2)
    assert prefix.text == "one two" and prefix.start == 5.0
    assert len(prefix.samples) / SAMPLE_RATE == pytest.approx(1.75, abs=0.02)  # the gap after the third word
    assert sentence.prefix(4) is sentence
