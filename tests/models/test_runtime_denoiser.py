import subprocess
import sys

import numpy as np
import pytest
import torch
from denoiser_helpers import TINY, random_model

from gesturecast.errors import UserError
from gesturecast.models.denoiser import audio_windows
from gesturecast.models.denoiser_config import audio_frames_needed
from gesturecast.models.diffusion import CLEAN_TIMESTEP
from gesturecast.models.export_denoiser import example_inputs, export_denoiser
from gesturecast.models.export_motion_prompt import export_motion_prompt
from gesturecast.models.motion_prompt import MotionPromptConfig, MotionPromptEncoder
from gesturecast.models.runtime_denoiser import DenoiserRuntime, FrameInputs


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    model = random_model()
    path = export_denoiser(model, tmp_path_factory.mktemp("onnx") / "denoiser.onnx")
    return model, DenoiserRuntime(path, threads=1)


def test_onnx_matches_torch_on_random_inputs_with_partial_cache(exported):
    model, runtime = exported
    gen = torch.Generator().manual_seed(3)
    inputs = [torch.randn(x.shape, generator=gen) if x.is_floating_point() else x for x in example_inputs(TINY, 2, 3)]
    inputs[1] = torch.tensor([[CLEAN_TIMESTEP, 10, 999], [0, 500, 20]])
    inputs[3] = torch.tensor([[1.0, 1.0, 0.0], [0.0, 1.0, 1.0]])
    inputs[5] = torch.tensor([[1.0, 0.0, 1.0], [1.0, 1.0, 1.0]])
    inputs[8] = torch.tensor([1, TINY.window])
    with torch.no_grad():
        expected = model.forward_chunk(*inputs)
    state = runtime.empty_state(2)
    state = type(state)(inputs[6].numpy(), inputs[7].numpy(), inputs[8].numpy())
    got = runtime.run(FrameInputs(*(x.numpy() for x in inputs[:6])), state)
    for ort_out, torch_out in zip(got, expected, strict=True):
        np.testing.assert_allclose(ort_out, torch_out.numpy(), atol=1e-4)


def test_streaming_runtime_equals_torch_full_sequence(exported):
    """Each step denoises a noisy frame after clean committed history; beyond W frames the cache evicts."""
    model, runtime = exported
    num_latents = 3 * TINY.window + 2
    gen = torch.Generator().manual_seed(4)
    clean = torch.randn(2, num_latents, TINY.latent_dim, generator=gen)
    noisy = torch.randn(2, num_latents, TINY.latent_dim, generator=gen)
    audio = torch.randn(2, audio_frames_needed(num_latents, TINY), TINY.audio_dim, generator=gen)
    style = torch.randn(2, TINY.style_dim, generator=gen)
    style_present = torch.tensor([1.0, 0.0])  # cond + uncond rows, as for guidance
    windows = audio_windows(audio, num_latents, TINY).numpy()  # (B, N, A, F)
    runtime.reset(2)
    for i in range(num_latents):
        t = 100 * i + 7
        sequence = torch.cat([clean[:, :i], noisy[:, i : i + 1]], dim=1)  # (B, i+1, C)
        steps = torch.full((2, i + 1), CLEAN_TIMESTEP)
        steps[:, -1] = t
        with torch.no_grad():
            full = model(sequence, steps, audio, torch.ones(2, i + 1), style, style_present)[:, -1]
        got = runtime.step(noisy[:, i].numpy(), t, windows[:, i], style.numpy(), style_present=style_present.numpy())
        np.testing.assert_allclose(got, full.numpy(), atol=1e-4)
        runtime.commit(clean[:, i].numpy(), windows[:, i], style.numpy(), style_present=style_present.numpy())
    assert runtime.state.pending is not None
    runtime.flush()
    assert runtime.state.pending is None and list(runtime.state.length) == [TINY.window] * 2


def test_runtime_does_not_import_torch():
    code = "import sys, gesturecast.models.runtime_denoiser; sys.exit('torch' in sys.modules)"
    assert subprocess.run([sys.executable, "-c", code], check=False).returncode == 0


def test_guidance_rows_in_one_batch_equal_separate_calls(exported):
    """Cond (style a), cond (style b) and uncond rows stacked in one call give each row's own result."""
    _, runtime = exported
    rng = np.random.default_rng(5)
    x = rng.standard_normal((3, TINY.latent_dim)).astype(np.float32)
    window = np.repeat(rng.standard_normal((1, TINY.audio_window, TINY.audio_dim)), 3, axis=0).astype(np.float32)
    styles = rng.standard_normal((3, TINY.style_dim)).astype(np.float32)
    present = np.array([1.0, 1.0, 0.0], np.float32)
    runtime.reset(3)
    runtime.commit(x, window, styles, style_present=present)
    batched = runtime.step(x, 50, window, styles, style_present=present)
    for row in range(3):
        runtime.reset(1)
        runtime.commit(
            x[row : row + 1], window[row : row + 1], styles[row : row + 1], style_present=present[row : row + 1]
        )
        single = runtime.step(
            x[row : row + 1], 50, window[row : row + 1], styles[row : row + 1], style_present=present[row : row + 1]
        )
        np.testing.assert_allclose(batched[row : row + 1], single, atol=1e-5)
    assert not np.allclose(batched[0], batched[1])  # the style matters


def test_rejects_an_onnx_file_without_denoiser_metadata(tmp_path):
    path = export_motion_prompt(
        MotionPromptEncoder(MotionPromptConfig(feature_dim=4, width=8, embed_dim=4)), tmp_path / "p.onnx"
    )
    with pytest.raises(UserError, match="not a gesturecast denoiser"):
        DenoiserRuntime(path)
