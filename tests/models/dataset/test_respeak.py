"""Re-spoken copies of a paired take: a transcript from PocketSphinx, each word said by a TTS voice on its own time
and level (models/dataset/respeak.py), and their place in the training clips."""

from __future__ import annotations

import shutil

import numpy as np
import pytest

from gesturecast.errors import UserError
from gesturecast.models.audio.streaming import FeatureConfig
from gesturecast.models.dataset import respeak as rs
from gesturecast.models.dataset import transcripts
from gesturecast.models.dataset.transcripts import RecognisedWord
from gesturecast.models.training.arrays import load_training_clips
from gesturecast.models.training.presets import get_preset
from gesturecast.tools.bench.speech.voice_set import VOICES

pytest.importorskip("librosa")
SR = rs.SAMPLE_RATE
VOICE = rs.TRAINING_VOICES[0]


def spoken(text: str, lead_s: float, tail_s: float) -> np.ndarray:
    """``text`` said by an espeak-ng voice at 16 kHz with silence before and after."""
    words = [rs.synthesize_word(rs.TtsVoice("en-us", 50), word) for word in text.split()]
    gap = np.zeros(int(0.08 * SR), np.float32)
    speech = np.concatenate([part for word in words for part in (word, gap)])
    return np.concatenate([np.zeros(int(lead_s * SR), np.float32), 0.3 * speech,
                           np.zeros(int(tail_s * SR), np.float32)])


def test_a_respoken_copy_speaks_each_word_in_its_span_at_its_level():
    audio = np.zeros(2 * SR, np.float32)
    audio[int(0.2 * SR):int(0.6 * SR)] = 0.2 * np.sin(np.arange(int(0.4 * SR)) * 0.2)
    audio[int(1.0 * SR):int(1.5 * SR)] = 0.05 * np.sin(np.arange(int(0.5 * SR)) * 0.3)
    words = [RecognisedWord("museum", 0.2, 0.6), RecognisedWord("quiet", 1.0, 1.5),
             RecognisedWord("nothing", 1.6, 1.9)]  # the last is silent
    copy = rs.respeak(audio, words, VOICE)
    assert copy.shape == audio.shape
    assert not np.any(copy[:int(0.2 * SR)]) and not np.any(copy[int(0.6 * SR):int(1.0 * SR)])
    assert not np.any(copy[int(1.5 * SR):])
    for start, stop in ((0.2, 0.6), (1.0, 1.5)):
        span = slice(int(start * SR), int(stop * SR))
        assert np.sqrt(np.mean(copy[span] ** 2)) == pytest.approx(np.sqrt(np.mean(audio[span] ** 2)), rel=1e-3)
        assert not np.allclose(copy[span], audio[span])


def test_fit_length_stretches_a_word_to_the_exact_length():
    word = rs.synthesize_word(VOICE, "weekend")
    for length in (len(word) // 2, len(word), 2 * len(word) + 17):
        assert len(rs.fit_length(word, length)) == length


def test_the_training_voices_are_none_of_the_benchmark_voices():
    benchmark = {voice.espeak.voice for voice in VOICES if voice.espeak is not None}
    variants = {name.split("+")[1] for name in benchmark if "+" in name}
    assert not {voice.voice.split("+")[1] for voice in rs.TRAINING_VOICES} & variants


def test_transcribe_times_the_words_where_they_are_said():
    pytest.importorskip("pocketsphinx")
    audio = spoken("the museum opens at ten and closes at six", lead_s=0.8, tail_s=0.6)
    words = transcripts.transcribe(audio)
    assert len(words) >= 4
    starts = [word.start_s for word in words]
    assert starts == sorted(starts) and all(word.end_s > word.start_s for word in words)
    assert words[0].start_s >= 0.6 and words[-1].end_s <= len(audio) / SR - 0.4


def test_respoken_copies_repeat_the_paired_motion_with_a_tts_voice(tiny_model, tmp_path):
    pytest.importorskip("pocketsphinx")
    cache = shutil.copytree(tiny_model[1].parent / "dataset", tmp_path / "dataset")
    features = FeatureConfig()
    plain = load_training_clips(cache, "train", features, progress=False)
    respoken = load_training_clips(cache, "train", features, progress=False, respoken_copies=2)
    paired = [clip for clip in plain if clip.audio is not None]
    assert len(respoken) == len(plain) + 2 * len(paired)
    copies = [clip for clip in respoken if "+tts-" in clip.variant]
    assert {clip.variant.split("+tts-")[1] for clip in copies} == {voice.voice for voice in rs.TRAINING_VOICES[:2]}
    assert all(clip.voice_copy for clip in copies)
    original = next(clip for clip in paired if clip.variant == copies[0].variant.split("+tts-")[0]
                    and clip.name == copies[0].name)
    np.testing.assert_array_equal(copies[0].motion, original.motion)
    assert not np.allclose(copies[0].audio, original.audio)
    assert sorted(cache.rglob("*.words.json")), "the transcripts are cached beside the takes"
    assert all("+tts-" not in clip.variant
               for clip in load_training_clips(cache, "val", features, progress=False, respoken_copies=2))


def test_a_cached_transcript_is_read_not_decoded_again(tmp_path, monkeypatch):
    record = {"file": "takes/zeggs/take.npz"}
    (tmp_path / "takes" / "zeggs").mkdir(parents=True)
    monkeypatch.setattr(transcripts, "transcribe", lambda audio: [RecognisedWord("hello", 0.1, 0.4)])
    first = transcripts.cached_words(tmp_path, record, np.zeros(SR, np.float32))
    monkeypatch.setattr(transcripts, "transcribe", lambda audio: pytest.fail("decoded again"))
    again = transcripts.cached_words(tmp_path, record, np.zeros(SR, np.float32))
    assert again == first == [RecognisedWord("hello", 0.1, 0.4)]


def test_more_respoken_copies_than_voices_is_a_user_error():
    with pytest.raises(UserError, match="training voices"):
        get_preset("default", respoken_copies=len(rs.TRAINING_VOICES) + 1)


def test_feature_statistics_come_from_the_speakers_own_recordings(tiny_model, tmp_path):
    pytest.importorskip("pocketsphinx")
    from gesturecast.models.audio.stats import FeatureStats
    from gesturecast.models.training.pipeline import TrainInputs, data_stage

    cache = shutil.copytree(tiny_model[1].parent / "dataset", tmp_path / "dataset")
    features = FeatureConfig()
    own = load_training_clips(cache, "train", features, progress=False)
    with_copies = load_training_clips(cache, "train", features, progress=False, respoken_copies=1, voice_copies=1)
    stats = data_stage(TrainInputs(with_copies, [], features))["audio_stats"]
    expected = FeatureStats.fit([clip.audio for clip in own if clip.audio is not None], features).to_dict()
    np.testing.assert_allclose(stats["mean"], expected["mean"], rtol=1e-6)
    np.testing.assert_allclose(stats["std"], expected["std"], rtol=1e-6)
