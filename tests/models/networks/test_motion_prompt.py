import numpy as np
import torch

from gesturecast.models.export.motion_prompt import export_motion_prompt
from gesturecast.models.networks.motion_prompt import (
    MotionPromptConfig,
    MotionPromptEncoder,
    PromptTrainConfig,
    train_motion_prompt,
)
from gesturecast.models.runtime.motion_prompt import MotionPromptRuntime

TINY = MotionPromptConfig(feature_dim=6, width=16, embed_dim=8, kernel=3, num_layers=2)
FRAMES = 24


def synthetic_clips(rng, count_per_label, num_labels):
    """Label k moves at its own frequency with a random phase: the style is in the dynamics."""
    time = np.arange(3 * FRAMES)[:, None]  # (T, 1)
    clips, labels = [], []
    for label in range(num_labels):
        for _ in range(count_per_label):
            phase = rng.uniform(0, 2 * np.pi)
            clip = np.sin(2 * np.pi * (label + 1) * time / FRAMES + phase) + 0.1 * rng.standard_normal(
                (len(time), TINY.feature_dim)
            )
            clips.append(clip.astype(np.float32))
            labels.append(label)
    return clips, labels


def test_contrastive_training_retrieves_the_right_label():
    rng = np.random.default_rng(0)
    num_labels = 3
    texts = rng.standard_normal((num_labels, TINY.embed_dim)).astype(np.float32)
    texts /= np.linalg.norm(texts, axis=1, keepdims=True)
    clips, labels = synthetic_clips(rng, 10, num_labels)
    torch.manual_seed(0)
    encoder = MotionPromptEncoder(TINY)
    config = PromptTrainConfig(clip_frames=FRAMES, batch_size=12, steps=120, learning_rate=3e-3)
    losses = train_motion_prompt(encoder, clips, labels, texts, config)
    assert np.mean(losses[-10:]) < 0.5 * np.mean(losses[:10])
    held_out, held_labels = synthetic_clips(np.random.default_rng(1), 4, num_labels)
    with torch.no_grad():
        embedded = encoder(torch.as_tensor(np.stack([clip[:FRAMES] for clip in held_out])))  # (n, S)
    predicted = (embedded.numpy() @ texts.T).argmax(axis=1)
    assert np.mean(predicted == np.array(held_labels)) >= 0.9
    np.testing.assert_allclose(np.linalg.norm(embedded.numpy(), axis=1), 1.0, atol=1e-5)


def test_onnx_matches_torch_for_any_length(tmp_path):
    torch.manual_seed(0)
    encoder = MotionPromptEncoder(TINY).eval()
    encoder.set_normalization(np.full(TINY.feature_dim, 0.5), np.full(TINY.feature_dim, 2.0))
    runtime = MotionPromptRuntime(export_motion_prompt(encoder, tmp_path / "prompt.onnx"))
    for frames in (17, 90):
        features = np.random.default_rng(frames).standard_normal((frames, TINY.feature_dim)).astype(np.float32)
        with torch.no_grad():
            expected = encoder(torch.as_tensor(features)[None])[0].numpy()
        np.testing.assert_allclose(runtime.embed(features), expected, atol=1e-5)
