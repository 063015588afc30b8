import numpy as np
import pytest
import torch

from gesturecast.models.networks.vqvae import VQVAEConfig
from gesturecast.models.training.vqvae import VQTrainConfig, WindowSampler, reconstruct, train_vqvae

CONFIG = VQVAEConfig(
    feature_dim=6, hidden_dim=16, latent_dim=8, downsample=4, res_blocks_per_stage=1, codebook_size=64, ema_decay=0.9
)
TRAIN = VQTrainConfig(window=32, batch_size=8, learning_rate=3e-3, warmup_steps=5, log_every=10)


def _sinusoid_clips(seed: int, count: int = 4, length: int = 120) -> list[np.ndarray]:
    """Structured motion-like data: six channels of fixed frequencies, a random phase per clip and channel."""
    rng = np.random.default_rng(seed)
    t = np.arange(length)[:, None] / 30.0  # (T, 1) seconds
    frequencies = np.linspace(0.4, 1.2, 6)[None]  # (1, D) Hz
    phases = rng.uniform(0, 2 * np.pi, (count, 1, 6))
    return [np.sin(2 * np.pi * frequencies * t + phase).astype(np.float32) for phase in phases]


def test_training_reduces_loss_and_reports_validation_metrics():
    model, metrics = train_vqvae(
        _sinusoid_clips(0),
        CONFIG,
        steps=80,
        seed=0,
        progress=False,
        val_clips=_sinusoid_clips(1, count=2),
        train_config=TRAIN,
    )
    history = metrics["loss_history"]
    assert len(history) == 8
    assert history[-1] < 0.7 * history[0]
    val = metrics["val"]
    mean_abs = np.mean([np.abs(c).mean() for c in _sinusoid_clips(1, count=2)])  # error of predicting zeros
    assert 0 < val["feature_mae"] < 0.9 * mean_abs
    assert 1.0 <= val["perplexity"] <= CONFIG.codebook_size
    assert 0 < val["used_fraction"] <= 1.0
    assert metrics["parameters"] == sum(p.numel() for p in model.parameters())
    assert not model.training


def test_training_is_deterministic_under_a_seed():
    clips = _sinusoid_clips(2)
    runs = [train_vqvae(clips, CONFIG, steps=6, seed=7, progress=False, train_config=TRAIN) for _ in range(2)]
    for (name, a), b in zip(runs[0][0].state_dict().items(), runs[1][0].state_dict().values(), strict=True):
        assert torch.equal(a, b), name
    assert runs[0][1]["loss_history"] == runs[1][1]["loss_history"]
    assert "train_usage" in runs[0][1]


def test_window_sampler_skips_short_clips_and_rejects_none_usable():
    rng = np.random.default_rng(0)
    clips = [np.zeros((10, 3)), np.arange(40 * 3, dtype=np.float32).reshape(40, 3)]
    sampler = WindowSampler(clips, window=32, rng=rng)
    batch = sampler.sample(5)
    assert batch.shape == (5, 32, 3) and batch.dtype == np.float32
    assert np.all(np.diff(batch[:, :, 0], axis=1) == 3)  # contiguous windows of the long clip
    with pytest.raises(ValueError):
        WindowSampler(clips[:1], window=32, rng=rng)


def test_reconstruct_crops_to_whole_latent_frames():
    model, _ = train_vqvae(_sinusoid_clips(3), CONFIG, steps=1, seed=0, progress=False, train_config=TRAIN)
    reconstruction, codes = reconstruct(model, _sinusoid_clips(4, count=1, length=50)[0])
    assert reconstruction.shape == (48, 6) and codes.shape == (12,)
