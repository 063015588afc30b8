"""PCM blocks from other software → 16 kHz mono float32: channel mixing, any rate, block-size invariance,
rate changes without lost samples, and one-line errors for malformed blocks."""

from __future__ import annotations

import numpy as np
import pytest

from gesturecast.errors import UserError
from gesturecast.models.audio.files import SAMPLE_RATE
from gesturecast.realtime.audio.pcm import PCM16_FULL_SCALE, AudioConverter, pcm16_to_mono

RATE = 44100
TONE_HZ = 440.0
BLOCKS = (441, 1000, 7, 2048, 882)  # uneven block sizes, in frames


def stereo_tone(frames: int) -> np.ndarray:
    """(n, 2) int16: a tone on the left, its negative half on the right."""
    left = 0.5 * np.sin(2 * np.pi * TONE_HZ * np.arange(frames) / RATE)  # (n,)
    return np.round(np.stack([left, -0.5 * left], axis=1) * PCM16_FULL_SCALE).astype("<i2")  # (n, 2)


def test_channels_are_averaged_and_scaled():
    pcm = np.array([[16384, 0], [-32768, -32768]], "<i2")  # (2, 2)
    assert pcm16_to_mono(pcm.tobytes(), 2).tolist() == [0.25, -1.0]


def test_any_block_sizes_give_the_samples_of_one_block():
    pcm = stereo_tone(sum(BLOCKS))
    whole = AudioConverter()
    expected = np.concatenate([whole.convert(pcm.tobytes(), RATE, 2), whole.flush()])
    pieces, start, converter = [], 0, AudioConverter()
    for size in BLOCKS:
        pieces.append(converter.convert(pcm[start : start + size].tobytes(), RATE, 2))
        start += size
    pieces.append(converter.flush())
    streamed = np.concatenate(pieces)
    assert streamed.dtype == np.float32 and streamed.shape == expected.shape
    assert abs(streamed.shape[0] - sum(BLOCKS) * SAMPLE_RATE / RATE) <= 1
    np.testing.assert_allclose(streamed, expected, atol=1e-5)


def test_a_rate_change_flushes_the_old_resampler_and_16k_passes_through():
    converter = AudioConverter()
    first = converter.convert(stereo_tone(RATE // 10).tobytes(), RATE, 2)  # 100 ms at 44.1 kHz
    native = np.arange(-800, 800, dtype="<i2")  # (1600,) mono at 16 kHz: 100 ms
    second = converter.convert(native.tobytes(), SAMPLE_RATE, 1)
    assert abs(first.shape[0] + second.shape[0] - 2 * SAMPLE_RATE // 10) <= 1  # nothing lost at the switch
    np.testing.assert_array_equal(second[-native.shape[0]:], native / np.float32(PCM16_FULL_SCALE))


@pytest.mark.parametrize(("size", "channels"), [(3, 1), (6, 2), (4, 0)])
def test_a_block_of_partial_frames_is_one_clear_error(size, channels):
    with pytest.raises(UserError, match="does not hold whole 16-bit frames"):
        pcm16_to_mono(bytes(size), channels)


def test_floats_at_int16_scale_are_refused_in_the_files_words(tmp_path):
    """``push(samples * 32767)`` (float32) was taken silently and gave other motion than ``push(samples)``; a float
    file at that scale only warned about clipping."""
    import soundfile

    from gesturecast.models.audio.files import load_audio

    loud = (stereo_tone(RATE // 10) / PCM16_FULL_SCALE * 32767).astype(np.float32)  # (n, 2) floats at int16 scale
    with pytest.raises(UserError, match=r"^audio samples reach \d+(\.\d+)?, far beyond full scale: float audio is in"):
        AudioConverter().convert_samples(loud, RATE)
    path = tmp_path / "loud.wav"
    soundfile.write(path, loud, RATE, subtype="FLOAT")
    with pytest.raises(UserError, match=r"the samples reach \d+(\.\d+)?, far beyond full scale: float audio is in"):
        load_audio(path)
    AudioConverter().convert_samples(loud / 32767 * 1.5, RATE)  # a mild over is audio (clipped), not refused


def test_bytes_pushed_as_samples_name_the_pcm16_call():
    """``push(bytes)`` failed with "…got shape ()"."""
    with pytest.raises(UserError, match=r"^audio samples must be an array, not bytes; .*push_pcm16"):
        AudioConverter().convert_samples(stereo_tone(10).tobytes(), RATE)
