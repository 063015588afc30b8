"""load_audio on real speech in many formats, and one-line errors for bad input."""

import logging

import numpy as np
import pytest
import soundfile

from gesturecast.errors import UserError
from gesturecast.models.audio.files import SAMPLE_RATE, AudioFileReader, load_audio
from gesturecast.models.audio.streaming import extract_features

SECONDS = 3


@pytest.fixture(scope="module")
def speech(shared_data):
    return load_audio(shared_data / "zeggs" / "067_Speech_2_x_1_0.wav")[5 * SAMPLE_RATE : (5 + SECONDS) * SAMPLE_RATE]


def resample(audio, rate):
    import soxr

    return soxr.resample(audio, SAMPLE_RATE, rate).astype(np.float32)


def snr_db(reference, test):
    return 10 * np.log10(np.sum(reference**2) / np.sum((reference - test) ** 2))


@pytest.mark.parametrize(("fmt", "subtype"), [("WAV", "PCM_16"), ("WAV", "PCM_32"), ("WAV", "FLOAT"),
                                              ("FLAC", "PCM_16"), ("OGG", "VORBIS")])
def test_formats_decode_to_16k_mono(tmp_path, speech, fmt, subtype):
    path = tmp_path / f"speech.{fmt.lower()}"
    soundfile.write(path, speech, SAMPLE_RATE, format=fmt, subtype=subtype)
    audio = load_audio(path)
    assert audio.dtype == np.float32 and audio.ndim == 1
    assert abs(audio.shape[0] - speech.shape[0]) <= 1
    n = min(audio.shape[0], speech.shape[0])
    if subtype == "VORBIS":
        assert snr_db(speech[:n], audio[:n]) > 10
    else:
        np.testing.assert_allclose(audio[:n], speech[:n], atol=1 / 32768)


def test_telephone_8k_is_upsampled(tmp_path, speech):
    path = tmp_path / "phone.wav"
    soundfile.write(path, resample(speech, 8000), 8000, subtype="PCM_16")
    audio = load_audio(path)
    assert abs(audio.shape[0] - speech.shape[0]) <= 2
    assert np.abs(audio).max() > 0.05


def test_48k_stereo_is_averaged_and_resampled_without_aliasing(tmp_path, speech):
    stereo = np.stack([resample(speech, 48000), 0.5 * resample(speech, 48000)], axis=1)  # (N, 2)
    tone = 0.2 * np.sin(2 * np.pi * 12000 * np.arange(stereo.shape[0]) / 48000)  # above 8 kHz: must vanish
    path = tmp_path / "studio.wav"
    soundfile.write(path, stereo + tone[:, None], 48000, subtype="FLOAT")
    audio = load_audio(path)
    assert abs(audio.shape[0] - speech.shape[0]) <= 2
    n = min(audio.shape[0], speech.shape[0])
    assert snr_db(0.75 * speech[1000 : n - 1000], audio[1000 : n - 1000]) > 30  # 12 kHz tone removed


def test_empty_file(tmp_path):
    path = tmp_path / "empty.wav"
    soundfile.write(path, np.zeros(0, np.float32), SAMPLE_RATE)
    with pytest.raises(UserError, match="empty"):
        load_audio(path)
    (tmp_path / "zero.wav").write_bytes(b"")
    with pytest.raises(UserError, match="empty"):
        load_audio(tmp_path / "zero.wav")


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_samples_are_rejected(tmp_path, speech, bad):
    corrupt = speech.copy()
    corrupt[SAMPLE_RATE] = bad
    path = tmp_path / "corrupt.wav"
    soundfile.write(path, corrupt, SAMPLE_RATE, subtype="FLOAT")
    with pytest.raises(UserError, match=r"NaN/inf samples \(first at 1.00 s\)"):
        load_audio(path)


def test_text_renamed_wav(tmp_path):
    path = tmp_path / "notes.wav"
    path.write_text("this is not audio\n" * 20)
    with pytest.raises(UserError, match="not a readable audio file") as error:
        load_audio(path)
    assert "\n" not in str(error.value)


def test_missing_file(tmp_path):
    with pytest.raises(UserError, match="no such audio file"):
        load_audio(tmp_path / "nope.wav")


def test_clipped_audio_warns_and_still_gives_features(tmp_path, speech, caplog):
    clipped = np.clip(speech * 20, -1, 1)
    path = tmp_path / "loud.wav"
    soundfile.write(path, clipped, SAMPLE_RATE, subtype="PCM_16")
    with caplog.at_level(logging.WARNING):
        audio = load_audio(path)
    assert "clipped" in caplog.text
    features = extract_features(audio)
    assert np.isfinite(features).all() and features.shape[0] == SECONDS * 30


def test_reader_blocks_concatenate_to_load_audio(tmp_path, speech):
    path = tmp_path / "s.wav"
    soundfile.write(path, resample(speech, 44100), 44100, subtype="PCM_16")
    blocks = list(AudioFileReader(path, block_frames=4096))
    assert max(b.shape[0] for b in blocks) < 4096
    np.testing.assert_array_equal(np.concatenate(blocks), load_audio(path))
