import subprocess
import sys

import numpy as np
import pytest
import torch

from gesturecast.models.export.vq import export_vq_decoder_step
from gesturecast.models.networks.vqvae import MotionVQVAE, VQVAEConfig
from gesturecast.models.runtime.vq import StreamingVQDecoder


@pytest.fixture(scope="module")
def model_and_onnx():
    torch.manual_seed(0)
    config = VQVAEConfig(feature_dim=10, hidden_dim=16, latent_dim=8, downsample=4, res_blocks_per_stage=2)
    model = MotionVQVAE(config).eval()
    return model, export_vq_decoder_step(model)


def test_onnxruntime_streaming_matches_torch_offline_decoder(model_and_onnx, tmp_path):
    model, data = model_and_onnx
    latents = torch.randn(9, 8)  # (N, C)
    with torch.no_grad():
        offline = model.decode(latents.unsqueeze(0))[0].numpy()  # (N·d, D)
    path = tmp_path / "vq_decoder_step.onnx"
    path.write_bytes(data)
    decoder = StreamingVQDecoder(path, threads=1)
    assert (decoder.latent_dim, decoder.frames_per_latent, decoder.feature_dim) == (8, 4, 10)
    streamed = np.concatenate([decoder.step(latent) for latent in latents.numpy()])
    assert streamed.shape == offline.shape == (36, 10)
    np.testing.assert_allclose(streamed, offline, atol=1e-4)


def test_reset_restarts_the_stream(model_and_onnx):
    _, data = model_and_onnx
    decoder = StreamingVQDecoder(data)
    latents = np.random.default_rng(0).standard_normal((5, 8)).astype(np.float32)
    first = decoder.decode(latents)
    continued = decoder.decode(latents)
    assert not np.allclose(first, continued)  # the state carries the past over
    decoder.reset()
    np.testing.assert_array_equal(decoder.decode(latents), first)


def test_bound_buffers_give_the_bits_of_plain_runs_and_returned_frames_stay_put(model_and_onnx):
    _, data = model_and_onnx
    decoder = StreamingVQDecoder(data)
    names = [node.name for node in decoder.session.get_inputs()][1:]  # the state inputs, in order
    state = [np.zeros((1, *node.shape[1:]), np.float32) for node in decoder.session.get_inputs()[1:]]
    returned, plain = [], []
    for latent in np.random.default_rng(1).standard_normal((6, 1, 8)).astype(np.float32):
        returned.append(decoder.step(latent))
        frames, *state = decoder.session.run(None, {"latent": latent, **dict(zip(names, state, strict=True))})
        plain.append(frames)
    np.testing.assert_array_equal(np.stack(returned), np.stack(plain))  # earlier frames not overwritten later


def test_batched_steps_match_torch_step(model_and_onnx):
    model, data = model_and_onnx
    decoder = StreamingVQDecoder(data, batch=3)
    state = model.decoder.initial_state(batch=3)
    for latent in torch.randn(4, 3, 8):  # 4 steps of (B, C)
        with torch.no_grad():
            expected, state = model.decoder.step(latent, state)  # (B, d, D)
        np.testing.assert_allclose(decoder.step(latent.numpy()), expected.numpy(), atol=1e-4)


def test_runtime_modules_do_not_import_torch():
    code = (
        "import sys; import gesturecast.models.runtime.vq, gesturecast.models.generator.diffusion; "
        "assert 'torch' not in sys.modules, 'torch imported'"
    )
    subprocess.run([sys.executable, "-c", code], check=True)
