import torch
from denoiser_helpers import TINY, TRUNCATING

from gesturecast.models.generator.denoiser_config import audio_frames_needed
from gesturecast.models.generator.diffusion import CLEAN_TIMESTEP, get_schedule
from gesturecast.models.networks.denoiser_network import CausalDenoiser
from gesturecast.models.training.denoiser_objective import (
    DenoiserTrainConfig,
    noise_frames,
    sample_lookaheads,
    sample_noise_levels,
    training_loss,
)


def test_noise_levels_have_clean_prefixes_and_independent_levels():
    gen = torch.Generator().manual_seed(0)
    t = sample_noise_levels(2000, 8, 1000, 0.5, gen)
    clean = t == CLEAN_TIMESTEP
    # clean frames only ever form a prefix: once noisy, never clean again
    assert not torch.any(clean[:, 1:] & ~clean[:, :-1])
    assert 0.3 < clean.any(dim=1).float().mean() < 0.5  # ≈ 0.5 · (7/8) of sequences have history
    noisy = t[~clean]
    assert noisy.min() >= 0 and noisy.max() < 1000
    assert len(torch.unique(t[:, -1])) > 500  # levels vary per frame


def test_clean_frames_are_not_noised():
    schedule = get_schedule()
    latents = torch.randn(2, 4, 3)
    t = torch.tensor([[CLEAN_TIMESTEP, CLEAN_TIMESTEP, 999, 999], [CLEAN_TIMESTEP, 0, 500, 999]])
    x_t = noise_frames(schedule, latents, t, torch.Generator().manual_seed(0))
    assert torch.equal(x_t[:, 0], latents[:, 0]) and torch.equal(x_t[0, 1], latents[0, 1])
    assert not torch.allclose(x_t[0, 2], latents[0, 2])


def test_training_loss_decreases_on_a_tiny_problem():
    torch.manual_seed(0)
    model = CausalDenoiser(TINY)
    schedule = get_schedule()
    gen = torch.Generator().manual_seed(0)
    num_latents = 6
    latents = torch.randn(4, num_latents, TINY.latent_dim)
    audio = torch.randn(4, audio_frames_needed(num_latents, TINY), TINY.audio_dim)
    audio_mask = torch.tensor([1.0, 0.0, 1.0, 0.0])
    style = torch.randn(4, TINY.style_dim)
    optimizer = torch.optim.Adam(model.parameters(), lr=3e-3)
    config = DenoiserTrainConfig()
    losses = []
    for _ in range(60):
        loss = training_loss(model, latents, audio, audio_mask, style, schedule, gen, config)
        optimizer.zero_grad()
        loss.backward()
        optimizer.step()
        losses.append(loss.item())
    assert sum(losses[-10:]) / 10 < 0.7 * sum(losses[:10]) / 10
    assert model.style.null_style.abs().sum() > 0  # style dropout trained the null embedding


def test_truncation_training_draws_every_look_ahead_and_other_models_keep_theirs():
    gen = torch.Generator().manual_seed(0)
    drawn = sample_lookaheads(CausalDenoiser(TRUNCATING), 500, gen)
    assert sorted(torch.unique(drawn).tolist()) == list(range(TRUNCATING.audio_lookahead + 1))
    assert sample_lookaheads(CausalDenoiser(TINY), 3, gen).tolist() == [TINY.audio_lookahead] * 3



def test_masked_latent_channels_add_nothing_to_the_loss():
    """The x0 prediction on channels of a part the take lacks gets no gradient; every other channel does."""
    model = CausalDenoiser(TINY)
    prediction = torch.randn(2, 4, TINY.latent_dim, requires_grad=True)
    model.register_forward_hook(lambda module, inputs, output: prediction)  # read the loss's weights off its gradient
    latents = torch.randn(2, 4, TINY.latent_dim, generator=torch.Generator().manual_seed(3))
    audio = torch.randn(2, audio_frames_needed(4, TINY), TINY.audio_dim)
    config = DenoiserTrainConfig(clean_history_prob=0.0)  # every frame noisy: every unmasked element counts
    half = TINY.latent_dim // 2
    mask = torch.ones(2, TINY.latent_dim)
    mask[0, :half] = 0.0  # the first sequence lacks a part
    loss = training_loss(model, latents, audio, torch.ones(2), torch.zeros(2, TINY.style_dim), get_schedule(),
                         torch.Generator().manual_seed(2), config, latent_mask=mask)
    loss.backward()
    assert torch.all(prediction.grad[0, :, :half] == 0)
    assert torch.all(prediction.grad[0, :, half:] != 0) and torch.all(prediction.grad[1] != 0)
    unmasked = training_loss(model, latents, audio, torch.ones(2), torch.zeros(2, TINY.style_dim), get_schedule(),
                             torch.Generator().manual_seed(2), config)
    everything = torch.nn.functional.huber_loss(prediction, latents)
    assert torch.allclose(unmasked, everything)  # no mask = the mean over every element, as before
