"""Fixtures of the session tests: the tiny model's bundle and cuts of real speech."""

import pytest
import soundfile

from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.models.runtime.bundle import ModelBundle

SPEECH_SECONDS = 4.0


@pytest.fixture(scope="module")
def bundle(tiny_model):
    return ModelBundle.load(tiny_model[1])


@pytest.fixture(scope="module")
def speech_cut(tmp_path_factory, shared_data):
    """A function: ``seconds`` of real speech (ZeroEGGS 067 from 3 s) as a 16 kHz WAV."""
    audio = load_audio(shared_data / "zeggs" / "067_Speech_2_x_1_0.wav")[3 * SAMPLE_RATE :]

    def cut(seconds: float):
        path = tmp_path_factory.mktemp("speech") / "speech.wav"
        soundfile.write(path, audio[: int(seconds * SAMPLE_RATE)], SAMPLE_RATE, subtype="FLOAT")
        return path

    return cut


@pytest.fixture(scope="module")
def speech(speech_cut):
    """4 s of real speech as a 16 kHz WAV."""
    return speech_cut(SPEECH_SECONDS)
