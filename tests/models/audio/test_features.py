"""Streaming features: chunk-size parity with the offline path, causality, definitions vs librosa."""

import numpy as np
import pytest

from gesturecast.models.audio.dsp import frame_boundary, mel_filterbank
from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.models.audio.streaming import (
    FeatureConfig,
    StreamingFeatureExtractor,
    extract_features,
    speaking_flags,
)
from gesturecast.models.audio.vad import VadConfig

SLICE_START_S, SLICE_S, SHORT_SLICE_S = 5, 10, 2
CHUNK_SIZES = (1, 160, 533, 4096, 16000)


@pytest.fixture(scope="module")
def speech(shared_data):
    audio = load_audio(shared_data / "zeggs" / "067_Speech_2_x_1_0.wav")
    return audio[SLICE_START_S * SAMPLE_RATE : (SLICE_START_S + SLICE_S) * SAMPLE_RATE]


@pytest.fixture(scope="module")
def offline(speech):
    return extract_features(speech, FeatureConfig())


def stream(audio, chunk, config=None):
    extractor = StreamingFeatureExtractor(config)
    return np.concatenate([extractor.push(audio[i : i + chunk]) for i in range(0, audio.shape[0], chunk)])


@pytest.mark.parametrize("chunk", CHUNK_SIZES)
def test_streaming_equals_offline_for_every_chunk_size(speech, offline, chunk):
    audio = speech[: SHORT_SLICE_S * SAMPLE_RATE] if chunk == 1 else speech  # size 1: 32k pushes
    streamed = stream(audio, chunk)
    assert streamed.shape[0] == audio.shape[0] * 30 // SAMPLE_RATE
    assert np.abs(streamed - offline[: streamed.shape[0]]).max() <= 1e-5


def test_energy_vad_and_embedding_channels_keep_parity(speech):
    audio = speech[: 4 * SAMPLE_RATE]
    config = FeatureConfig(vad=VadConfig(method="energy"), speech_embedding=True)
    assert np.abs(stream(audio, 533, config) - extract_features(audio, config)).max() <= 1e-5


def test_a_sparser_embedding_keeps_parity_and_steps_every_n_times_80_ms(speech):
    audio = speech[: 4 * SAMPLE_RATE]
    every = FeatureConfig(speech_embedding=True)
    sparse = FeatureConfig(speech_embedding=True, speech_embedding_every=4)
    dense, held = (extract_features(audio, config)[:, config.layout["embedding"]] for config in (every, sparse))
    assert np.abs(stream(audio, 533, sparse)[:, sparse.layout["embedding"]] - held).max() <= 1e-5
    changes = np.flatnonzero(np.abs(np.diff(held, axis=0)).max(axis=1) > 0) + 1  # (k,) frames a new one arrives
    assert len(changes) >= 8 and np.all(np.diff(changes) >= 9)  # 320 ms apart: 9 or 10 frames at 30 fps
    # the same embedding, computed less often (each reuses the mel frames it shares with its previous window, so the
    # two differ by the float rounding of mel frames computed over other spans: ~1e-5 in mel, ~1e-3 of the range)
    np.testing.assert_allclose(held[changes], dense[changes], rtol=0, atol=1e-2 * np.abs(dense).max())


def test_causal_future_audio_does_not_change_past_frames(speech, offline):
    changed = speech.copy()
    cut = frame_boundary(100, SAMPLE_RATE, 30)
    changed[cut:] = np.random.default_rng(0).standard_normal(changed.shape[0] - cut).astype(np.float32)
    features = extract_features(changed)
    np.testing.assert_array_equal(features[:100], offline[:100])
    assert not np.array_equal(features[100], offline[100])


def test_frame_boundaries_are_exact_and_cover_the_stream():
    bounds = frame_boundary(np.arange(31), SAMPLE_RATE, 30)
    assert bounds[30] == SAMPLE_RATE
    assert set(np.diff(bounds)) == {533, 534}


def test_filterbank_matches_librosa():
    librosa = pytest.importorskip("librosa")
    config = FeatureConfig()
    ours = mel_filterbank(SAMPLE_RATE, config.n_fft, config.n_mels, config.fmin_hz, config.fmax_hz)
    theirs = librosa.filters.mel(
        sr=SAMPLE_RATE, n_fft=config.n_fft, n_mels=config.n_mels, fmin=config.fmin_hz, fmax=config.fmax_hz
    )
    np.testing.assert_allclose(ours, theirs, rtol=1e-5, atol=1e-9)


def test_log_mel_matches_librosa_at_frame_ends(speech, offline):
    librosa = pytest.importorskip("librosa")
    config = FeatureConfig()
    frames = np.arange(10, 200)
    ends = frame_boundary(frames + 1, SAMPLE_RATE, 30)
    windows = np.stack([speech[e - config.n_fft : e] for e in ends]).astype(np.float64)  # (T, N)
    power = librosa.feature.melspectrogram(
        y=windows, sr=SAMPLE_RATE, n_fft=config.n_fft, hop_length=config.n_fft, center=False,
        n_mels=config.n_mels, fmin=config.fmin_hz, fmax=config.fmax_hz, window="hann", power=2.0,
    )[:, :, 0]  # (T, M)
    reference = librosa.power_to_db(power, ref=1.0, amin=1e-10, top_db=None)
    np.testing.assert_allclose(offline[frames][:, config.layout["mel"]], reference, atol=1e-3)


def test_energy_is_the_rms_of_each_frame(speech, offline):
    config = FeatureConfig()
    k = 150
    segment = speech[frame_boundary(k, SAMPLE_RATE, 30) : frame_boundary(k + 1, SAMPLE_RATE, 30)].astype(np.float64)
    expected = 20 * np.log10(np.sqrt(np.mean(segment**2)))
    assert offline[k, config.layout["energy"]][0] == pytest.approx(expected, abs=1e-4)


def test_onset_peaks_at_a_tone_burst():
    config = FeatureConfig(vad=VadConfig(method="energy"))
    audio = np.zeros(SAMPLE_RATE, np.float32)
    start = frame_boundary(15, SAMPLE_RATE, 30)
    audio[start:] = 0.3 * np.sin(2 * np.pi * 440 * np.arange(SAMPLE_RATE - start) / SAMPLE_RATE)
    onset = extract_features(audio, config)[:, config.layout["onset"]][:, 0]
    assert int(np.argmax(onset)) == 15
    assert onset[:15].max() == 0.0


def test_speaking_flag_is_off_in_silence_and_on_in_speech(speech, offline):
    silence = extract_features(np.zeros(2 * SAMPLE_RATE, np.float32))
    assert not speaking_flags(silence).any()
    assert speaking_flags(offline).mean() > 0.5


def test_nan_samples_are_refused():
    audio = np.zeros(SAMPLE_RATE, np.float32)
    audio[100] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        extract_features(audio)


def test_reset_restarts_the_stream(speech):
    extractor = StreamingFeatureExtractor()
    first = extractor.push(speech[:SAMPLE_RATE])
    extractor.reset()
    np.testing.assert_array_equal(extractor.push(speech[:SAMPLE_RATE]), first)


def test_config_round_trips_through_a_dict():
    config = FeatureConfig(n_mels=40, vad=VadConfig(method="energy"), speech_embedding=True, speech_embedding_every=2)
    assert FeatureConfig.from_dict(config.to_dict()) == config
    assert config.num_features == 40 + 3 + 96
