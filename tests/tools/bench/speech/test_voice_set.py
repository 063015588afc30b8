"""The voice set of `bench voices`: held-out and dev voices never share a recording, a text or a TTS voice."""

from __future__ import annotations

import shutil

import numpy as np
import pytest
import soundfile

from gesturecast.errors import UserError
from gesturecast.models.audio.files import SAMPLE_RATE
from gesturecast.tools.bench.speech.voice_set import (
    DEV,
    HELD_OUT,
    PAUSES_S,
    SPLITS,
    TEXTS,
    VOICES,
    Channel,
    Flite,
    join_with_pauses,
    rerecorded,
    spoken,
    voice_audio,
)


def sources(split: str) -> set[str]:
    voices = [voice for voice in VOICES if voice.split == split]
    engines = [spec for voice in voices for spec in (voice.espeak, voice.flite) if spec is not None]
    return {name for voice in voices for name in voice.files} | {spec.text for spec in engines} | {
        f"{type(spec).__name__} {spec.voice}" for spec in engines}


def test_no_recording_text_or_tts_voice_is_in_both_splits():
    assert {voice.split for voice in VOICES} == set(SPLITS)
    assert len({voice.name for voice in VOICES}) == len(VOICES)
    assert not sources(HELD_OUT) & sources(DEV)
    assert all(spec.text in TEXTS for voice in VOICES for spec in (voice.espeak, voice.flite) if spec is not None)
    by_name = {voice.name: voice for voice in VOICES}
    for voice in (v for v in VOICES if v.channel is not None):
        assert by_name[voice.channel.of].split == voice.split and by_name[voice.channel.of].channel is None


def test_parts_are_joined_with_the_listed_pauses():
    parts = [np.ones(100, np.float32), np.ones(50, np.float32), np.ones(10, np.float32)]
    joined = join_with_pauses(parts)
    gaps = [int(round(p * SAMPLE_RATE)) for p in PAUSES_S[:2]]
    assert joined.shape == (160 + sum(gaps),)
    assert joined[100: 100 + gaps[0]].max() == 0.0 and joined[100 + gaps[0]] == 1.0


def test_a_rerecorded_voice_reads_back_as_the_same_speech(tmp_path):
    t = np.arange(SAMPLE_RATE) / SAMPLE_RATE
    tone = (0.3 * np.sin(2 * np.pi * 440.0 * t)).astype(np.float32)  # (16000,)
    back = rerecorded(tone, Channel("x", 44100, 2, -6.0), tmp_path)
    assert abs(len(back) - len(tone)) <= 2
    assert soundfile.info(str(tmp_path / "channel.wav")).channels == 2
    middle = slice(1000, 15000)
    np.testing.assert_allclose(back[middle], tone[middle] * 10 ** (-6 / 20), atol=3e-3)


@pytest.mark.skipif(shutil.which("espeak-ng") is None, reason="espeak-ng is not installed")
def test_a_missing_recording_or_split_is_a_clear_error(tmp_path):
    with pytest.raises(UserError, match="not found"):
        voice_audio(HELD_OUT, tmp_path)
    with pytest.raises(UserError, match="unknown voice split"):
        voice_audio("test", tmp_path)


@pytest.mark.skipif(shutil.which("flite") is None, reason="flite is not installed")
def test_a_flite_voice_speaks_a_sentence_at_16k_and_slower_when_stretched(tmp_path):
    sentence = "The museum opens at ten and closes at six."
    plain = spoken(Flite("slt", 1.0, "agent_museum"), sentence, tmp_path)  # (N,)
    slower = spoken(Flite("slt", 1.2, "agent_museum"), sentence, tmp_path)
    assert 1.5 < len(plain) / SAMPLE_RATE < 5.0 and np.abs(plain).max() > 0.05
    assert len(slower) > 1.1 * len(plain)
