"""GestureDiffuCLIP's style loss (Eq. 16): the frozen critic passes its gradient to the denoiser only, training
on it moves the denoised motion's style embedding toward the prompt, and the training command runs with it."""

import json
import shutil

import numpy as np
import torch

from gesturecast.cli import main
from gesturecast.models.generator.denoiser_config import DenoiserConfig, audio_frames_needed
from gesturecast.models.generator.diffusion import get_schedule
from gesturecast.models.networks.denoiser_network import CausalDenoiser
from gesturecast.models.networks.part_vqvae import load_motion_vq
from gesturecast.models.runtime.bundle import Normalizer, StyleTable
from gesturecast.models.training.denoiser_objective import DenoiserTrainConfig, style_loss, training_loss
from gesturecast.models.training.pipeline import CHECKPOINT_FILE, channel_mask, load_checkpoint, style_critic

BATCH, LATENTS, STEPS = 4, 6, 40


def critic_and_denoiser(checkpoint: dict):
    stages = checkpoint["stages"]
    critic = style_critic(load_motion_vq(stages["vqvae"]["model"]), stages,
                          Normalizer.from_dict(stages["denoiser"]["latent_stats"]))
    denoiser = CausalDenoiser(DenoiserConfig.from_dict(stages["denoiser"]["config"]))
    denoiser.load_state_dict(stages["denoiser"]["state"])
    return critic, denoiser.train()


def test_the_style_loss_trains_the_denoiser_toward_the_prompt_and_leaves_the_critic_frozen(tiny_model):
    checkpoint = tiny_model[0]
    critic, denoiser = critic_and_denoiser(checkpoint)
    frozen = {name: value.clone() for name, value in critic.state_dict().items()}
    config = denoiser.config
    styles = StyleTable.from_dict(checkpoint["stages"]["data"]["styles"])
    style = torch.as_tensor(np.tile(styles.embedding("old"), (BATCH, 1)), dtype=torch.float32)  # (B, S)
    audio = torch.zeros(BATCH, audio_frames_needed(LATENTS, config), config.audio_dim)  # (B, T_a, F)
    generator = torch.Generator().manual_seed(7)
    t = torch.randint(0, get_schedule().num_timesteps, (BATCH, LATENTS), generator=generator)  # (B, N)
    x_t = torch.randn(BATCH, LATENTS, config.latent_dim, generator=generator)  # (B, N, C)
    lookahead = torch.full((BATCH,), config.audio_lookahead)
    optimizer = torch.optim.Adam(denoiser.parameters(), lr=1e-2)

    def distance() -> torch.Tensor:  # Eq. 16 on the denoiser's x̂0 of fixed noisy latents
        x0 = denoiser(x_t, t, audio, torch.zeros(BATCH, LATENTS), style, torch.ones(BATCH), lookahead)
        return style_loss(critic, x0, style, torch.ones(BATCH))

    before = float(distance())
    for _ in range(STEPS):
        optimizer.zero_grad()
        distance().backward()
        optimizer.step()
    # 1 − cos fell: the motion's embedding turned toward "old" (the tiny preset's prompt encoder, trained for five
    # steps, maps every motion near one direction, so the reachable change is small; no gradient would leave it)
    assert float(distance()) < before - 0.005
    assert all(torch.equal(value, frozen[name]) for name, value in critic.state_dict().items())
    assert all(parameter.grad is None for parameter in critic.parameters())


def test_the_training_loss_adds_the_weighted_style_term_on_styled_whole_body_sequences(tiny_model):
    critic, denoiser = critic_and_denoiser(tiny_model[0])
    config = denoiser.config
    latents = torch.randn(BATCH, LATENTS, config.latent_dim, generator=torch.Generator().manual_seed(1))
    audio = torch.zeros(BATCH, audio_frames_needed(LATENTS, config), config.audio_dim)
    style = torch.nn.functional.normalize(torch.randn(BATCH, critic.encoder.config.embed_dim), dim=-1)
    losses = {}
    for weight in (0.0, 0.5):
        objective = DenoiserTrainConfig(style_loss_weight=weight, style_drop_prob=0.0)
        losses[weight] = float(training_loss(denoiser.eval(), latents, audio, torch.zeros(BATCH), style,
                                             get_schedule(), torch.Generator().manual_seed(3), objective,
                                             critic=critic))
    assert losses[0.5] - losses[0.0] > 0.5 * 0.5  # 1 − cos of unrelated directions is about 1


def test_train_with_the_style_loss(tiny_model, tmp_path, capsys):
    work = tmp_path / "work"
    work.mkdir()
    shutil.copy(tiny_model[1].parent / "work" / CHECKPOINT_FILE, tmp_path / CHECKPOINT_FILE)
    cache = tiny_model[1].parent / "dataset"
    args = ["train", "--preset", "tiny", "--data", str(cache), "--work-dir", str(work), "--no-progress",
            "--vq-from", str(tmp_path), "--style-loss-weight", "0.07"]
    assert main(args) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["preset"] == "tiny"
    trained = load_checkpoint(work / CHECKPOINT_FILE)
    assert trained["preset"]["style_loss_weight"] == 0.07
    plain = tiny_model[0]["stages"]["denoiser"]["state"]
    assert any(not torch.equal(value, plain[name]) for name, value in trained["stages"]["denoiser"]["state"].items())


def swap_losses(tiny_model, audio_mask: torch.Tensor) -> dict[float, float]:
    """The training loss with no swap and with every eligible sequence swapped to a one-style pool."""
    critic, denoiser = critic_and_denoiser(tiny_model[0])
    config = denoiser.config
    latents = torch.randn(BATCH, LATENTS, config.latent_dim, generator=torch.Generator().manual_seed(1))
    audio = torch.randn(BATCH, audio_frames_needed(LATENTS, config), config.audio_dim,
                        generator=torch.Generator().manual_seed(2))
    style = torch.nn.functional.normalize(torch.randn(BATCH, critic.encoder.config.embed_dim), dim=-1)
    pool = -style[:1]  # a style far from every sequence's own
    losses = {}
    for swap in (0.0, 1.0):
        objective = DenoiserTrainConfig(style_drop_prob=0.0, style_swap_prob=swap)
        losses[swap] = float(training_loss(denoiser.eval(), latents, audio, audio_mask, style, get_schedule(),
                                           torch.Generator().manual_seed(3), objective, critic=critic,
                                           style_pool=pool))
    return losses


def test_style_swaps_touch_only_sequences_with_speech(tiny_model):
    losses = swap_losses(tiny_model, torch.zeros(BATCH))
    assert losses[1.0] == losses[0.0]  # motion-only sequences keep their own style and full reconstruction


def test_a_swapped_speech_sequence_is_scored_against_the_drawn_style(tiny_model):
    losses = swap_losses(tiny_model, torch.ones(BATCH))
    # half the reconstruction plus 0.3 · (1 − cos) against a style opposite to the sequence's own (about 1 or more)
    assert losses[1.0] > 0.5 * losses[0.0] + 0.3 * 0.5
    assert losses[1.0] != losses[0.0]


def output_gradient(tiny_model, swap_channels: tuple[float, ...], weight: float) -> torch.Tensor:
    """d loss / d x̂0 (B, N, C) of the training loss with every speech sequence swapped, style loss ``weight``."""
    critic, denoiser = critic_and_denoiser(tiny_model[0])
    config = denoiser.config
    outputs = []

    def keep_output(_module, _inputs, output):
        output.retain_grad()
        outputs.append(output)

    denoiser.register_forward_hook(keep_output)
    latents = torch.randn(BATCH, LATENTS, config.latent_dim, generator=torch.Generator().manual_seed(1))
    audio = torch.randn(BATCH, audio_frames_needed(LATENTS, config), config.audio_dim,
                        generator=torch.Generator().manual_seed(2))
    embedding = torch.randn(BATCH, critic.encoder.config.embed_dim, generator=torch.Generator().manual_seed(4))
    style = torch.nn.functional.normalize(embedding, dim=-1)  # (B, S)
    objective = DenoiserTrainConfig(style_drop_prob=0.0, style_swap_prob=1.0, style_swap_weight=weight,
                                    swap_channels=swap_channels)
    training_loss(denoiser.eval(), latents, audio, torch.ones(BATCH), style, get_schedule(),
                  torch.Generator().manual_seed(3), objective, critic=critic, style_pool=-style[:1]).backward()
    return outputs[0].grad


def test_a_posture_swap_leaves_the_arms_to_the_speech(tiny_model):
    posture = channel_mask(load_motion_vq(tiny_model[0]["stages"]["vqvae"]["model"]), ("torso", "legs"))  # (C,)
    swapped = output_gradient(tiny_model, tuple(posture), 1.0)  # (B, N, C)
    plain = output_gradient(tiny_model, tuple(posture), 0.0)  # the same swap, reconstruction only
    arms, rest = posture == 0, posture == 1
    # the arms' channels see only their whole reconstruction; torso and legs also the drawn style's loss
    assert torch.equal(swapped[..., arms], plain[..., arms])
    assert not torch.allclose(swapped[..., rest], plain[..., rest])
    # every channel listed is a whole-body swap, the same as listing none
    everything = output_gradient(tiny_model, tuple(np.ones_like(posture)), 1.0)
    assert torch.equal(everything, output_gradient(tiny_model, (), 1.0))
    assert not torch.equal(everything[..., arms], plain[..., arms])


def test_train_with_style_swaps_on_the_posture_and_a_shallower_denoiser(tiny_model, tmp_path, capsys):
    work = tmp_path / "work"
    work.mkdir()
    shutil.copy(tiny_model[1].parent / "work" / CHECKPOINT_FILE, tmp_path / CHECKPOINT_FILE)
    args = ["train", "--preset", "tiny", "--data", str(tiny_model[1].parent / "dataset"), "--work-dir", str(work),
            "--no-progress", "--vq-from", str(tmp_path), "--style-swap", "0.5", "--style-swap-parts", "torso", "legs",
            "--denoiser-layers", "2"]
    assert main(args) == 0
    capsys.readouterr()
    trained = load_checkpoint(work / CHECKPOINT_FILE)
    assert trained["preset"]["style_swap_prob"] == 0.5
    assert list(trained["preset"]["style_swap_parts"]) == ["torso", "legs"]
    assert trained["stages"]["denoiser"]["config"]["num_layers"] == 2


def test_an_unknown_swap_part_is_a_one_line_error(tiny_model, tmp_path, capsys):
    args = ["train", "--preset", "tiny", "--data", str(tiny_model[1].parent / "dataset"), "--work-dir",
            str(tmp_path), "--no-progress", "--style-swap", "0.5", "--style-swap-parts", "tail"]
    assert main(args) != 0
    assert "unknown body part 'tail' for style swaps; known: arms, torso, legs" in capsys.readouterr().err

