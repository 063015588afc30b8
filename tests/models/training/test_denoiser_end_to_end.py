"""Train a tiny denoiser on a synthetic audio → latent mapping, then generate autoregressively with the
KV cache and few-step DDIM: the diffusion-forcing objective must transfer to streaming inference."""

import torch

from gesturecast.models.generator.denoiser_config import DenoiserConfig, audio_frames_needed
from gesturecast.models.generator.diffusion import (
    CLEAN_TIMESTEP,
    SamplerConfig,
    get_schedule,
    sampler_step,
    sampling_plan,
)
from gesturecast.models.networks.denoiser_network import CausalDenoiser, KVCache, audio_windows
from gesturecast.models.training.denoiser_objective import training_loss

CONFIG = DenoiserConfig(
    latent_dim=3, audio_dim=2, style_dim=4, width=32, num_layers=2, num_heads=2, window=4, audio_window=8
)
TRAIN_STEPS = 120
BATCH = 16


def synthetic_pairs(batch, num_latents, generator):
    """Audio = a sinusoid of random phase and frequency; latent i = functions of the audio at frame i·d."""
    length = audio_frames_needed(num_latents, CONFIG)
    phase = 2 * torch.pi * torch.rand(batch, 1, generator=generator)
    freq = 0.1 + 0.2 * torch.rand(batch, 1, generator=generator)
    angle = freq * torch.arange(length)[None] + phase  # (B, T)
    audio = torch.stack([torch.sin(angle), torch.cos(angle)], dim=-1)  # (B, T, 2)
    at_latent = torch.sin(angle[:, torch.arange(num_latents) * CONFIG.frames_per_latent])  # (B, N)
    latents = torch.stack([at_latent, -at_latent, at_latent**2], dim=-1)  # (B, N, 3)
    return latents, audio


def generate(model, audio, audio_present, num_latents, steps, generator):
    """Autoregressive K-step DDIM, one latent at a time, history through the KV cache."""
    schedule, sampler = get_schedule(), SamplerConfig("ddim", steps)
    batch = audio.shape[0]
    windows = audio_windows(audio, num_latents, CONFIG)  # (B, N, A, F)
    style, present = torch.zeros(batch, CONFIG.style_dim), torch.full((batch,), float(audio_present))
    cache, latents = KVCache.empty(CONFIG, batch), []
    for i in range(num_latents):
        x = torch.randn(batch, CONFIG.latent_dim, generator=generator)
        for t, t_prev in sampling_plan(schedule.num_timesteps, sampler):
            x0, _ = model.step(x, torch.full((batch,), t), windows[:, i], style, cache, present)
            x = sampler_step(schedule, sampler, x0, t, t_prev, x)
        _, cache = model.step(x, torch.full((batch,), CLEAN_TIMESTEP), windows[:, i], style, cache, present)
        latents.append(x)
    return torch.stack(latents, dim=1)  # (B, N, C)


def test_streaming_generation_follows_the_audio_it_was_trained_on():
    torch.manual_seed(0)
    model = CausalDenoiser(CONFIG)
    optimizer = torch.optim.AdamW(model.parameters(), lr=3e-3)
    gen = torch.Generator().manual_seed(0)
    for _ in range(TRAIN_STEPS):
        latents, audio = synthetic_pairs(BATCH, 8, gen)
        loss = training_loss(model, latents, audio, torch.ones(BATCH), torch.zeros(BATCH, 4), get_schedule(), gen)
        optimizer.zero_grad()
        loss.backward()
        optimizer.step()
    model.eval()
    target, audio = synthetic_pairs(4, 12, gen)
    with torch.no_grad():
        heard = generate(model, audio, 1, 12, steps=2, generator=gen)
        deaf = generate(model, audio, 0, 12, steps=2, generator=gen)
    heard_error = (heard - target).pow(2).mean().sqrt()
    deaf_error = (deaf - target).pow(2).mean().sqrt()
    assert heard_error < 0.25 * target.std()
    assert heard_error < 0.5 * deaf_error  # the audio condition, not the prior, explains the result
