import numpy as np
import pytest
import torch
from denoiser_helpers import TINY, TRUNCATING, random_model

from gesturecast.models.generator.denoiser_config import audio_frames_needed, audio_window_from_features
from gesturecast.models.generator.diffusion import CLEAN_TIMESTEP
from gesturecast.models.networks.denoiser_network import CausalDenoiser, KVCache, audio_windows


def random_inputs(batch, num_latents, config=TINY, seed=1):
    gen = torch.Generator().manual_seed(seed)
    x = torch.randn(batch, num_latents, config.latent_dim, generator=gen)
    t = torch.randint(0, config.num_timesteps, (batch, num_latents), generator=gen)
    t[:, : num_latents // 2] = CLEAN_TIMESTEP
    audio = torch.randn(batch, audio_frames_needed(num_latents, config), config.audio_dim, generator=gen)
    audio_present = torch.tensor([[1.0] * num_latents, [0.0] * num_latents])[:batch]
    style = torch.randn(batch, config.style_dim, generator=gen)
    style_present = torch.tensor([1.0, 0.0])[:batch]
    return x, t, audio, audio_present, style, style_present


def test_full_sequence_equals_frame_by_frame_with_cache_beyond_window():
    model = random_model()
    num_latents = 10  # > 3 × window: eviction happens
    x, t, audio, audio_present, style, style_present = random_inputs(2, num_latents)
    with torch.no_grad():
        full = model(x, t, audio, audio_present, style, style_present)  # (B, N, C)
        windows = audio_windows(audio, num_latents, TINY)  # (B, N, A, F)
        cache = KVCache.empty(TINY, 2)
        for i in range(num_latents):
            x0, cache = model.step(x[:, i], t[:, i], windows[:, i], style, cache, audio_present[:, i], style_present)
            assert (x0 - full[:, i]).abs().max() <= 1e-5
    assert int(cache.length[0]) == TINY.window


def test_output_is_causal_and_local():
    model = random_model()
    x, t, audio, audio_present, style, style_present = random_inputs(1, 12)
    with torch.no_grad():
        base = model(x, t, audio, audio_present, style, style_present)
        changed = x.clone()
        changed[:, 4] += 1.0
        moved = model(changed, t, audio, audio_present, style, style_present)
    diff = (moved - base).abs().amax(dim=-1)[0]  # (N,)
    reach = 4 + TINY.num_layers * TINY.window  # receptive field grows by one window per layer
    assert torch.all(diff[:4] == 0)  # the past does not see the future
    assert torch.all(diff[4 : reach + 1] > 0)
    assert torch.all(diff[reach + 1 :] == 0)  # local attention: bounded reach


def test_audio_look_ahead_is_respected():
    model = random_model()
    num_latents = 4
    x, t, audio, audio_present, style, style_present = random_inputs(1, num_latents)
    audio_present[:] = 1
    last_visible = (1 + 1) * TINY.frames_per_latent + TINY.audio_lookahead - 1  # latent 1 sees up to here
    with torch.no_grad():
        base = model(x, t, audio, audio_present, style, style_present)
        later = audio.clone()
        later[:, last_visible + 1] += 5.0
        out_later = model(x, t, later, audio_present, style, style_present)
        at_edge = audio.clone()
        at_edge[:, last_visible] += 5.0
        out_edge = model(x, t, at_edge, audio_present, style, style_present)
    assert torch.equal(out_later[:, :2], base[:, :2])
    assert (out_edge[:, 1] - base[:, 1]).abs().max() > 0


def test_style_modulation_starts_as_identity():
    torch.manual_seed(0)
    model = CausalDenoiser(TINY).eval()
    x, t, audio, audio_present, style, _ = random_inputs(2, 5)
    with torch.no_grad():
        with_style = model(x, t, audio, audio_present, style, torch.ones(2))
        without = model(x, t, audio, audio_present, style, torch.zeros(2))
    assert torch.allclose(with_style, without)


def test_audio_windows_match_numpy_slicing():
    num_latents = 5
    audio = torch.randn(1, audio_frames_needed(num_latents, TINY), TINY.audio_dim)
    windows = audio_windows(audio, num_latents, TINY)
    for i in range(num_latents):
        expected = audio_window_from_features(audio[0].numpy(), i, TINY)
        np.testing.assert_array_equal(windows[0, i].numpy(), expected)
    with pytest.raises(ValueError):
        audio_windows(audio[:, :-1], num_latents, TINY)


def test_truncated_look_ahead_ignores_the_masked_frames_and_is_told_its_look_ahead():
    """At look-ahead δ the window's last δa − δ frames do not matter at all; δ itself changes the output."""
    model = random_model(TRUNCATING)
    gen = torch.Generator().manual_seed(2)
    windows = torch.randn(1, 3, TRUNCATING.audio_window, TRUNCATING.audio_dim, generator=gen)  # (B, M, A, F)
    present, style = torch.ones(1, 3), torch.randn(1, 3, TRUNCATING.style_dim, generator=gen)
    lookahead = 1
    changed = windows.clone()
    changed[:, :, TRUNCATING.audio_window - (TRUNCATING.audio_lookahead - lookahead):] = 7.0  # only masked frames
    heard_change = windows.clone()
    heard_change[:, :, 0] += 1.0  # a heard frame
    with torch.no_grad():
        def condition(w, delta):
            return model.condition(w, present, style, present, torch.full((1, 3), float(delta)))

        torch.testing.assert_close(condition(windows, lookahead), condition(changed, lookahead), rtol=0, atol=0)
        assert not torch.allclose(condition(windows, lookahead), condition(heard_change, lookahead))
        assert not torch.allclose(condition(windows, lookahead), condition(windows, lookahead + 1))


def test_a_truncation_model_without_its_look_ahead_falls_back_to_the_full_one():
    """forward / step default δ to δa: the same as passing δa explicitly."""
    model = random_model(TRUNCATING)
    x, t, audio, audio_present, style, style_present = random_inputs(2, 5, TRUNCATING)
    with torch.no_grad():
        default = model(x, t, audio, audio_present, style, style_present)
        explicit = model(x, t, audio, audio_present, style, style_present, torch.full((2,), TRUNCATING.audio_lookahead))
    torch.testing.assert_close(default, explicit, rtol=0, atol=0)
