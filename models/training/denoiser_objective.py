"""Training objective of the causal denoiser: diffusion forcing with x0 prediction and a Huber loss.

- Every latent frame gets its own noise level (diffusion forcing, Chen et al. 2024 §3.1); with
  probability ``clean_history_prob`` a sequence instead has a clean prefix (``t = CLEAN_TIMESTEP``,
  no noise at all) followed by noisy frames, which is exactly the autoregressive inference
  configuration (clean history in the KV cache, a noisy current frame).
- Frames are noised by q(x_t | x0), Ho et al. 2020 eq. 4; the network predicts x0 and is trained
  with a Huber loss (DiffuseStyleGesture §3.3, eq. 5) on the noisy frames only.
- The style is dropped (replaced by the learned null style) with probability ``style_drop_prob``
  for classifier-free guidance (Ho & Salimans 2022 §3.2; 10% as in DiffuseStyleGesture).
- Body parts a take does not hold (``latent_mask`` 0 on their latent channels) add nothing to the loss:
  the loss is averaged over the noisy frames' present channels only.
- Random look-ahead truncation (models with ``lookahead_truncation``): every sequence draws its
  look-ahead δ uniformly from 0..δa; the network masks the audio past δ and is told δ, so one model
  serves every latency setting (docs/latency.md "Latency settings").
- Optionally GestureDiffuCLIP's style loss (§4.3, Eq. 16), weighted by ``style_loss_weight`` (0.07 in the paper):
  1 − cos(E(x̂0), s) for the sequences whose style was given and whose every body part is present, where x̂0 is
  the prediction on the noisy frames (the given clean history elsewhere), E the frozen :class:`StyleCritic` and
  s the style's embedding. The paper completes the denoising from a random step before encoding; with an x0
  prediction the network's one-call x̂0 is that completion's estimate, which is what is used here.
- Optionally, style swaps on speech (``style_swap_prob``, with a critic and a ``style_pool``): the paired takes
  carry only the styles of their speakers, so the network never sees a style with the audio on and learns to
  drop it whenever speech is heard. A share of the paired, whole-body sequences gets a style drawn from the pool
  instead; their reconstruction counts ``SWAP_CONTENT_WEIGHT`` (the speech's timing and content) and their style
  loss ``style_swap_weight`` (the drawn style), the same Eq. 16 term against the drawn style's embedding.
  ``swap_channels`` may restrict a swap to some body parts' latent channels (the posture: torso and legs): the
  other channels keep their whole reconstruction and the style loss's gradient does not reach them, so the arms
  go on following the speech while the posture takes the drawn style.
"""

from __future__ import annotations

from dataclasses import dataclass

import torch
import torch.nn.functional as F

from gesturecast.models.generator.diffusion import CLEAN_TIMESTEP, DiffusionSchedule, q_sample
from gesturecast.models.networks.denoiser_network import CausalDenoiser
from gesturecast.models.networks.style_critic import StyleCritic


@dataclass(frozen=True)
class DenoiserTrainConfig:
    style_drop_prob: float = 0.1
    clean_history_prob: float = 0.5
    huber_delta: float = 1.0
    style_loss_weight: float = 0.0  # w_style of Eq. 16; 0: no style loss
    style_swap_prob: float = 0.0  # share of paired whole-body sequences trained with a drawn style; 0: none
    style_swap_weight: float = 0.3  # style-loss weight of a style-swapped sequence (w_style for the others)
    swap_channels: tuple[float, ...] = ()  # (C,) 1 on the latent channels a swap restyles; (): all of them


SWAP_CONTENT_WEIGHT = 0.5  # reconstruction weight of a style-swapped sequence (1 for the others)


def sample_noise_levels(batch: int, num_latents: int, num_timesteps: int, clean_history_prob: float, generator):
    """Per-frame timesteps (B, N) int64: independent levels, some sequences with a clean prefix of random length."""
    t = torch.randint(0, num_timesteps, (batch, num_latents), generator=generator)  # (B, N)
    with_history = torch.rand(batch, generator=generator) < clean_history_prob  # (B,)
    history_len = torch.randint(0, num_latents, (batch,), generator=generator)  # (B,) in 0..N-1
    clean = (torch.arange(num_latents)[None, :] < history_len[:, None]) & with_history[:, None]  # (B, N)
    return t.masked_fill(clean, CLEAN_TIMESTEP)


def sample_lookaheads(model: CausalDenoiser, batch: int, generator) -> torch.Tensor:
    """Per-sequence look-ahead δ (B,): uniform over 0..δa with truncation training, else δa."""
    config = model.config
    if not config.lookahead_truncation:
        return torch.full((batch,), config.audio_lookahead)
    return torch.randint(0, config.audio_lookahead + 1, (batch,), generator=generator)


def noise_frames(schedule: DiffusionSchedule, latents: torch.Tensor, t: torch.Tensor, generator) -> torch.Tensor:
    """x_t per frame (eq. 4); clean frames (t = CLEAN_TIMESTEP) stay exactly x0. latents (B, N, C)."""
    noise = torch.randn(latents.shape, generator=generator)  # (B, N, C)
    noisy = q_sample(schedule, latents, t.clamp(min=0), noise)  # (B, N, C)
    return torch.where((t == CLEAN_TIMESTEP)[..., None], latents, noisy)


def training_loss(
    model: CausalDenoiser,
    latents: torch.Tensor,
    audio: torch.Tensor,
    audio_mask: torch.Tensor,
    style: torch.Tensor,
    schedule: DiffusionSchedule,
    generator: torch.Generator,
    config: DenoiserTrainConfig = DenoiserTrainConfig(),  # noqa: B008 (frozen dataclass)
    latent_mask: torch.Tensor | None = None,
    critic: StyleCritic | None = None,
    style_pool: torch.Tensor | None = None,
) -> torch.Tensor:
    """Huber loss of the x0 prediction on noisy frames (plus the weighted style loss with a ``critic``).

    latents (B, N, C) clean VQ-VAE latents; audio (B, N*d + δa, F) features aligned with motion frame 0;
    audio_mask (B,) or (B, N): 1 where real audio accompanies the motion (0 for motion-only data);
    style (B, S) style embeddings; latent_mask (B, C): 1 on the channels that are training targets (default all);
    style_pool (P, S): the styles a swapped sequence draws from (module docstring).
    """
    batch, num_latents, _ = latents.shape
    t = sample_noise_levels(batch, num_latents, schedule.num_timesteps, config.clean_history_prob, generator)
    x_t = noise_frames(schedule, latents, t, generator)  # (B, N, C)
    audio_present = audio_mask.float().reshape(batch, -1).expand(batch, num_latents)  # (B, N)
    style_present = (torch.rand(batch, generator=generator) >= config.style_drop_prob).float()  # (B,)
    lookahead = sample_lookaheads(model, batch, generator)  # (B,)
    channels = torch.ones_like(latents[:, 0]) if latent_mask is None else latent_mask  # (B, C)
    scored = style_present * (channels.min(dim=1).values == 1.0).float()  # (B,) styled, whole body
    swapped = swap_mask(scored * audio_present[:, 0], config, critic, style_pool, generator)  # (B,)
    if swapped.any():
        drawn = style_pool[torch.randint(0, len(style_pool), (batch,), generator=generator)]  # (B, S)
        style = torch.where(swapped[:, None] > 0, drawn, style)
    x0 = model(x_t, t, audio, audio_present, style, style_present, lookahead)  # (B, N, C)
    per_element = F.huber_loss(x0, latents, reduction="none", delta=config.huber_delta)  # (B, N, C)
    restyled = swapped[:, None] * restyled_channels(config, latents)[None, :]  # (B, C)
    content = 1.0 - restyled * (1.0 - SWAP_CONTENT_WEIGHT)  # (B, C)
    weight = (t != CLEAN_TIMESTEP).float()[..., None] * channels[:, None, :]  # (B, N, C)
    loss = (per_element * weight * content[:, None, :]).sum() / weight.sum().clamp(min=1.0)
    if critic is None or (config.style_loss_weight == 0.0 and not swapped.any()):
        return loss
    denoised = torch.where((t == CLEAN_TIMESTEP)[..., None], latents, x0)  # (B, N, C)
    kept = (swapped[:, None] - restyled)[:, None, :] > 0  # (B, 1, C) a swap's channels the style loss leaves alone
    denoised = torch.where(kept, denoised.detach(), denoised)  # (B, N, C)
    distance = style_distance(critic, denoised, style)  # (B,) one critic pass for both terms
    own = config.style_loss_weight * masked_mean(distance, scored * (1.0 - swapped))
    return loss + own + config.style_swap_weight * masked_mean(distance, swapped)


def swap_mask(eligible: torch.Tensor, config: DenoiserTrainConfig, critic: StyleCritic | None,
              style_pool: torch.Tensor | None, generator: torch.Generator) -> torch.Tensor:
    """(B,) 1 for the ``eligible`` (B,) sequences drawn for a style swap (none without a critic and a pool)."""
    if critic is None or style_pool is None or config.style_swap_prob == 0.0:
        return torch.zeros_like(eligible)
    drawn = (torch.rand(eligible.shape, generator=generator) < config.style_swap_prob).float()  # (B,)
    return eligible * drawn


def restyled_channels(config: DenoiserTrainConfig, latents: torch.Tensor) -> torch.Tensor:
    """(C,) 1 on the channels a style swap restyles: ``config.swap_channels``, or all of ``latents`` (B, N, C)."""
    if not config.swap_channels:
        return torch.ones(latents.shape[-1])
    return torch.as_tensor(config.swap_channels, dtype=torch.float32)


def style_distance(critic: StyleCritic, denoised: torch.Tensor, style: torch.Tensor) -> torch.Tensor:
    """1 − cos(E(denoised), s) per sequence (Eq. 16): denoised (B, N, C), s (B, S) → (B,)."""
    return 1.0 - F.cosine_similarity(critic(denoised), style, dim=-1)


def masked_mean(values: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
    """Mean of ``values`` (B,) over the sequences where ``mask`` (B,) is 1 (0 when none is)."""
    return (values * mask).sum() / mask.sum().clamp(min=1.0)


def style_loss(critic: StyleCritic, denoised: torch.Tensor, style: torch.Tensor, scored: torch.Tensor
               ) -> torch.Tensor:
    """Mean 1 − cos(E(denoised), s) over the ``scored`` (B,) sequences (Eq. 16): denoised (B, N, C), s (B, S)."""
    return masked_mean(style_distance(critic, denoised, style), scored)
