import numpy as np

from gesturecast.models.audio.vad import EnergyVad, Hangover, VadConfig


def test_hangover_holds_the_flag_for_n_frames():
    flags = Hangover(2).apply(np.array([0, 1, 0, 0, 0, 0, 1, 0], bool))
    assert flags.tolist() == [0, 1, 1, 1, 0, 0, 1, 1]


def test_energy_vad_tracks_the_noise_floor():
    vad = EnergyVad(VadConfig(method="energy", hangover_frames=0))
    noise_floor = np.full(30, -40.0)  # loud room: above the absolute threshold, but steady
    speech = np.full(5, -20.0)
    flags = vad.update(None, None, np.concatenate([noise_floor, speech, noise_floor]))
    assert not flags[:30].any() and flags[30:35].all() and not flags[35:].any()


QUIET_SPEECH_DBFS = -40.0
DC_OFFSET = 0.02  # -34 dBFS: louder than the speech


def test_a_dc_offset_does_not_silence_quiet_speech():
    from gesturecast.models.audio.files import PACKAGED_SAMPLE, load_audio
    from gesturecast.models.audio.streaming import extract_features, speaking_flags

    speech = load_audio(PACKAGED_SAMPLE).astype(np.float64)  # (n,)
    quiet = speech * 10 ** (QUIET_SPEECH_DBFS / 20) / np.sqrt(np.mean(speech**2))
    clean = speaking_flags(extract_features(quiet.astype(np.float32)))
    offset = speaking_flags(extract_features((quiet + DC_OFFSET).astype(np.float32)))
    assert clean.mean() > 0.5  # the clean quiet speech is heard
    assert np.mean(offset != clean) < 0.01  # and the same frames are heard with the offset
