"""The frozen FGD encoder: numpy forward = torch forward, FGD 0 for identical sets, a frozen pose far from real."""

import numpy as np
import pytest
import torch

from gesturecast.models.evaluation.convnet import ConvNetConfig, conv1d
from gesturecast.models.evaluation.fgd_encoder import DEFAULT_FGD_ENCODER, FGD_ENCODER_VERSION, FGDEncoder
from gesturecast.models.evaluation.train_networks import TorchConvNet
from gesturecast.models.evaluation.windows import WindowConfig, motion_windows
from gesturecast.models.motion.retarget import load_motion_file

REAL_FRAMES = 900  # 30 s of the shared ZeroEGGS take


@pytest.fixture(scope="module")
def real_positions(shared_data) -> np.ndarray:
    motion = load_motion_file(shared_data / "zeggs" / "067_Speech_2_x_1_0.bvh")
    return motion.positions()[:REAL_FRAMES]  # (T, J, 3)


@pytest.fixture(scope="module")
def encoder() -> FGDEncoder:
    return FGDEncoder.load()


def test_numpy_conv_matches_torch_conv():
    rng = np.random.default_rng(0)
    x, weight, bias = rng.normal(size=(3, 16, 5)), rng.normal(size=(7, 5, 4)), rng.normal(size=7)
    expected = torch.nn.functional.conv1d(torch.from_numpy(x).transpose(1, 2), torch.from_numpy(weight),
                                          torch.from_numpy(bias), stride=2, padding=1).transpose(1, 2).numpy()
    np.testing.assert_allclose(conv1d(x, weight, bias, 2, 1), expected, atol=1e-12)


def test_exported_network_matches_torch():
    torch.manual_seed(0)
    config = ConvNetConfig(channels=(8, 8), out_dim=5, window=WindowConfig(frames=16))
    module = TorchConvNet(config)
    windows = np.random.default_rng(1).normal(size=(4, 16, config.in_channels)).astype(np.float32)
    mean, std = windows.mean(axis=(0, 1)), windows.std(axis=(0, 1))
    expected = module(torch.from_numpy((windows - mean) / std)).detach().numpy()
    np.testing.assert_allclose(module.export(mean, std).forward(windows), expected, atol=1e-5)


def test_committed_weights_are_stamped_and_small(encoder):
    assert encoder.version == FGD_ENCODER_VERSION
    assert DEFAULT_FGD_ENCODER.name == f"fgd_encoder_v{FGD_ENCODER_VERSION}.npz"
    assert DEFAULT_FGD_ENCODER.stat().st_size < 2 * 1024 * 1024
    assert {"bandai-2", "zeggs", "beat2"} <= set(encoder.stamp["training_data"]["datasets"])


def test_identical_sets_have_zero_fgd(encoder, real_positions):
    clips = [real_positions[:450], real_positions[450:]]
    assert encoder.fgd(clips, clips) == pytest.approx(0.0, abs=1e-6)


def test_frozen_pose_is_far_from_real_motion(encoder, real_positions):
    first, second = real_positions[:450], real_positions[450:]
    frozen = np.repeat(first[:1], 450, axis=0)  # the first pose held for 15 s
    real_vs_real = encoder.fgd([first], [second])
    assert encoder.fgd([first], [frozen]) > 3.0 * real_vs_real  # measured: 101.6 vs 26.7


def test_features_are_one_row_per_window(encoder, real_positions):
    windows = motion_windows(real_positions, encoder.net.config.window)
    assert encoder.features([real_positions]).shape == (len(windows), encoder.net.config.out_dim)
