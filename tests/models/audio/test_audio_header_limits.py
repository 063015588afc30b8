"""Crafted audio headers are refused before anything is decoded (tiny files that claim absurd rates)."""

from __future__ import annotations

import numpy as np
import pytest
import soundfile

from gesturecast.errors import UserError
from gesturecast.models.audio.files import MAX_FILE_RATE, MIN_FILE_RATE, AudioFileReader

SHORT_FRAMES = 1000


@pytest.mark.parametrize("rate", [1, MIN_FILE_RATE - 1, MAX_FILE_RATE + 1])
def test_a_sample_rate_outside_the_limits_is_one_line_error(tmp_path, rate):
    """Before: a 232 KB WAV claiming 1 Hz was resampled 16 000-fold and reached 12.6 GB."""
    path = tmp_path / "crafted.wav"
    soundfile.write(path, np.zeros(SHORT_FRAMES, np.float32), rate, subtype="PCM_16")
    with pytest.raises(UserError, match=f"sample rate {rate} Hz is outside the supported"):
        AudioFileReader(path)


@pytest.mark.parametrize("rate", [MIN_FILE_RATE, MAX_FILE_RATE])
def test_the_limits_themselves_are_accepted(tmp_path, rate):
    path = tmp_path / "edge.wav"
    soundfile.write(path, np.zeros(SHORT_FRAMES, np.float32), rate, subtype="PCM_16")
    assert AudioFileReader(path).stats.file_rate == rate
