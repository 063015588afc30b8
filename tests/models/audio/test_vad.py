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
