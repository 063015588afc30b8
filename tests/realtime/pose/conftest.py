"""Fixtures of the session tests: the tiny model's bundle and 4 s of real speech."""

import pytest
import soundfile

from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.models.runtime.bundle import ModelBundle

SPEECH_SECONDS = 4.0


@pytest.fixture(scope="module")
def bundle(tiny_model):
    return ModelBundle.load(tiny_model[1])


@pytest.fixture(scope="module")
def speech(tmp_path_factory, shared_data):
    """4 s of real speech (ZeroEGGS 067 from 3 s) as a 16 kHz WAV."""
    audio = load_audio(shared_data / "zeggs" / "067_Speech_2_x_1_0.wav")
    audio = audio[3 * SAMPLE_RATE :][: int(SPEECH_SECONDS * SAMPLE_RATE)]
    path = tmp_path_factory.mktemp("speech") / "speech.wav"
    soundfile.write(path, audio, SAMPLE_RATE, subtype="FLOAT")
    return path
