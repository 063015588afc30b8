import subprocess
import sys

import numpy as np
import pytest
import torch
from denoiser_helpers import TINY, TRUNCATING, random_model

from gesturecast.errors import UserError
from gesturecast.models.export.denoiser_onnx import example_condition_inputs, example_step_inputs, export_denoiser
from gesturecast.models.export.motion_prompt import export_motion_prompt
from gesturecast.models.generator.denoiser_config import audio_frames_needed
from gesturecast.models.generator.diffusion import CLEAN_TIMESTEP
from gesturecast.models.networks.denoiser_network import audio_windows
from gesturecast.models.networks.motion_prompt import MotionPromptConfig, MotionPromptEncoder
from gesturecast.models.runtime.denoiser_runtime import (
    LOOKAHEAD_INPUT_NAME,
    DenoiserRuntime,
    FrameInputs,
    condition_path,
)


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    model = random_model()
    path = export_denoiser(model, tmp_path_factory.mktemp("onnx") / "denoiser.onnx")
    return model, DenoiserRuntime(path, threads=1)


def _random(inputs: tuple[torch.Tensor, ...], seed: int) -> list[torch.Tensor]:
    gen = torch.Generator().manual_seed(seed)
    return [torch.randn(x.shape, generator=gen) if x.is_floating_point() else x for x in inputs]


def test_onnx_matches_torch_on_random_inputs_with_partial_cache(exported):
    """Both graphs (condition, then step) against the torch forward on the raw inputs, within 1e-4."""
    model, runtime = exported
    windows, audio_present, style, style_present = _random(example_condition_inputs(TINY, 2, 3), 3)
    audio_present = torch.tensor([[1.0, 1.0, 0.0], [0.0, 1.0, 1.0]])
    style_present = torch.tensor([[1.0, 0.0, 1.0], [1.0, 1.0, 1.0]])
    x_t, _, _, cache_k, cache_v, _ = _random(example_step_inputs(TINY, 2, 3), 4)
    t = torch.tensor([[CLEAN_TIMESTEP, 10, 999], [0, 500, 20]])
    length = torch.tensor([1, TINY.window])
    with torch.no_grad():
        expected = model.forward_chunk(x_t, t, windows, audio_present, style, style_present, cache_k, cache_v, length)
    condition = runtime.condition(windows.numpy(), audio_present.numpy(), style.numpy(), style_present.numpy())
    assert condition.shape == (2, 3, TINY.condition_dim)
    state = type(runtime.state)(cache_k.numpy(), cache_v.numpy(), length.numpy())
    got = runtime.run(FrameInputs(x_t.numpy(), t.numpy(), condition), state)
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
        condition = runtime.frame_condition(windows[:, i], style.numpy(), style_present=style_present.numpy())
        got = runtime.step(noisy[:, i].numpy(), t, condition)
        np.testing.assert_allclose(got, full.numpy(), atol=1e-4)
        runtime.commit(clean[:, i].numpy(), condition)
    assert runtime.state.pending is not None
    runtime.flush()
    assert runtime.state.pending is None and list(runtime.state.length) == [TINY.window] * 2


def test_runtime_does_not_import_torch():
    code = "import sys, gesturecast.models.runtime.denoiser_runtime; sys.exit('torch' in sys.modules)"
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
    condition = runtime.frame_condition(window, styles, style_present=present)  # (3, Dc)
    runtime.commit(x, condition)
    batched = runtime.step(x, 50, condition)
    for row in range(3):
        runtime.reset(1)
        single_condition = runtime.frame_condition(
            window[row : row + 1], styles[row : row + 1], style_present=present[row : row + 1]
        )
        np.testing.assert_allclose(condition[row : row + 1], single_condition, atol=1e-5)
        runtime.commit(x[row : row + 1], single_condition)
        single = runtime.step(x[row : row + 1], 50, single_condition)
        np.testing.assert_allclose(batched[row : row + 1], single, atol=1e-5)
    assert not np.allclose(batched[0], batched[1])  # the style matters


def test_rejects_an_onnx_file_without_denoiser_metadata(tmp_path):
    path = export_motion_prompt(
        MotionPromptEncoder(MotionPromptConfig(feature_dim=4, width=8, embed_dim=4)), tmp_path / "p.onnx"
    )
    with pytest.raises(UserError, match="not a gesturecast denoiser"):
        DenoiserRuntime(path)


def test_a_step_graph_without_its_condition_graph_is_refused(tmp_path):
    path = export_denoiser(random_model(), tmp_path / "denoiser.onnx")
    condition_path(path).unlink()
    with pytest.raises(UserError, match="denoiser_condition.onnx is missing"):
        DenoiserRuntime(path)


@pytest.mark.parametrize("lookahead", [0, 2])
def test_truncation_model_onnx_matches_torch_at_a_truncated_look_ahead(tmp_path, lookahead):
    """The condition graph of a truncation model takes δ; torch and ONNX agree within 1e-4 at δ < δa, and the
    frames past δ do not matter."""
    model = random_model(TRUNCATING)
    runtime = DenoiserRuntime(export_denoiser(model, tmp_path / "denoiser.onnx"), threads=1)
    names = [node.name for node in runtime.condition_session.get_inputs()]
    assert names[-1] == LOOKAHEAD_INPUT_NAME
    inputs = _random(example_condition_inputs(TRUNCATING, 2, 3), 5)[:4]  # the traced δ is replaced below
    windows, present, style, style_present = (x.numpy() for x in inputs)
    with torch.no_grad():
        expected = model.condition(*(torch.as_tensor(x) for x in (windows, present, style, style_present)),
                                   torch.full((2, 3), float(lookahead)))
    got = runtime.condition(windows, present, style, style_present, lookahead)
    np.testing.assert_allclose(got, expected.numpy(), atol=1e-4)
    tail = windows.copy()
    tail[:, :, TRUNCATING.audio_window - (TRUNCATING.audio_lookahead - lookahead):] = 0.0
    np.testing.assert_array_equal(runtime.condition(tail, present, style, style_present, lookahead), got)


def test_a_model_without_truncation_refuses_another_look_ahead(exported):
    _, runtime = exported
    windows, present, style, style_present = (x.numpy() for x in example_condition_inputs(TINY, 1, 1))
    with pytest.raises(ValueError, match="serves only look-ahead 8"):
        runtime.condition(windows, present, style, style_present, 0)
