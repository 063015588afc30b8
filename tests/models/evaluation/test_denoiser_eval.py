"""Held-out denoising error of the tiny trained model: finite, fixed under the seed, three conditions."""

import math

import pytest

from gesturecast.models.evaluation.denoising import HeldOutConfig, held_out_denoising_error

SMALL = HeldOutConfig(num_latents=2, stride=1, draws=2)


def test_held_out_error_scores_every_condition_and_is_reproducible(tiny_model):
    checkpoint, bundle = tiny_model
    cache = bundle.parent / "dataset"
    first = held_out_denoising_error(checkpoint, cache, SMALL)
    assert first["windows"] > 0
    for key in ("with_audio", "without_audio", "mismatched_audio"):
        assert math.isfinite(first[key]) and first[key] > 0.0
    assert first["audio_gain"] == pytest.approx(first["without_audio"] - first["with_audio"])
    assert held_out_denoising_error(checkpoint, cache, SMALL) == first


def test_no_held_out_window_is_an_error(tiny_model):
    checkpoint, bundle = tiny_model
    with pytest.raises(ValueError, match="no held-out paired window"):
        held_out_denoising_error(checkpoint, bundle.parent / "dataset", HeldOutConfig(num_latents=1000))
