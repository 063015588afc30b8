"""ONNX export of the denoiser as two graphs: the per-frame condition, and the incremental step.

The condition (audio window token + every layer's style modulation) does not change during the K
sampler steps of a latent frame, so it is its own graph, run once per frame; the step graph runs K
times. Both are written next to each other: ``denoiser.onnx`` and ``denoiser_condition.onnx``.

Condition graph (dynamic B = batch, M = frames)::

    inputs   audio_windows (B, M, A, F), audio_present (B, M), style (B, M, S), style_present (B, M),
             and for a look-ahead truncation model also lookahead (B, M) float32 (δ per frame)
    outputs  condition (B, M, condition_dim)

Step graph (KV cache and history as explicit inputs/outputs; W, L, H, Dh fixed by the config)::

    inputs   x_t (B, M, C) float32, t (B, M) int64 (CLEAN_TIMESTEP = -1 for a clean history frame),
             condition (B, M, condition_dim),
             cache_keys / cache_values (L, B, H, W, Dh), cache_length (B,) int64 (valid = last slots)
    outputs  x0 (B, M, C), new_keys / new_values (L, B, H, M, Dh) of the M new frames

The caller rolls the cache (:func:`gesturecast.models.runtime.denoiser_runtime.roll_cache`), which lets one
step call both commit the previous clean latent and take the first denoising step of the next one
(M = 2). The config travels in both models' metadata (key ``gesturecast.denoiser_config``).
"""

from __future__ import annotations

import json
from pathlib import Path

import onnx
import torch
from torch import nn

from gesturecast.models.generator.denoiser_config import DenoiserConfig
from gesturecast.models.networks.denoiser_network import CausalDenoiser
from gesturecast.models.runtime.denoiser_runtime import (
    CACHE_INPUT_NAMES,
    CONDITION_OUTPUT_NAME,
    CONFIG_METADATA_KEY,
    FRAME_INPUT_NAMES,
    OUTPUT_NAMES,
    condition_input_names,
    condition_path,
)

OPSET_VERSION = 17
FRAME_AXES = {0: "batch", 1: "new_frames"}
CACHE_AXES = {1: "batch"}
NEW_CACHE_AXES = {1: "batch", 3: "new_frames"}
STEP_DYNAMIC_AXES = {
    **dict.fromkeys(FRAME_INPUT_NAMES, FRAME_AXES),
    "cache_keys": CACHE_AXES,
    "cache_values": CACHE_AXES,
    "cache_length": {0: "batch"},
    "x0": FRAME_AXES,
    "new_keys": NEW_CACHE_AXES,
    "new_values": NEW_CACHE_AXES,
}


class DenoiserConditionGraph(nn.Module):
    """``CausalDenoiser.condition``, as exported (``lookahead`` only for truncation models)."""

    def __init__(self, model: CausalDenoiser):
        super().__init__()
        self.model = model

    def forward(self, audio_windows, audio_present, style, style_present, lookahead=None):
        return self.model.condition(audio_windows, audio_present, style, style_present, lookahead)


class DenoiserStepGraph(nn.Module):
    """``CausalDenoiser.forward_conditioned`` with a fixed-size (W-frame) cache, as exported."""

    def __init__(self, model: CausalDenoiser):
        super().__init__()
        self.model = model

    def forward(self, x_t, t, condition, cache_keys, cache_values, length):
        return self.model.forward_conditioned(x_t, t, condition, cache_keys, cache_values, length)


def example_condition_inputs(config: DenoiserConfig, batch: int = 2, new_frames: int = 2) -> tuple[torch.Tensor, ...]:
    """Tracing inputs of the condition graph: audio_windows, audio_present, style, style_present[, lookahead]."""
    inputs = (
        torch.zeros(batch, new_frames, config.audio_window, config.audio_dim),
        torch.ones(batch, new_frames),
        torch.zeros(batch, new_frames, config.style_dim),
        torch.ones(batch, new_frames),
    )
    if config.lookahead_truncation:
        return (*inputs, torch.full((batch, new_frames), float(config.audio_lookahead)))
    return inputs


def example_step_inputs(config: DenoiserConfig, batch: int = 2, new_frames: int = 2) -> tuple[torch.Tensor, ...]:
    """Tracing inputs of the step graph: x_t, t, condition, cache_keys, cache_values, cache_length."""
    cache_shape = (config.num_layers, batch, config.num_heads, config.window, config.head_dim)
    return (
        torch.zeros(batch, new_frames, config.latent_dim),
        torch.zeros(batch, new_frames, dtype=torch.int64),
        torch.zeros(batch, new_frames, config.condition_dim),
        torch.zeros(cache_shape),
        torch.zeros(cache_shape),
        torch.ones(batch, dtype=torch.int64),
    )


def _export(graph: nn.Module, inputs: tuple, path: Path, names: tuple[list, list], axes: dict, config) -> None:
    input_names, output_names = names
    with torch.no_grad():
        torch.onnx.export(graph, inputs, str(path), input_names=input_names, output_names=output_names,
                          dynamic_axes=axes, opset_version=OPSET_VERSION, dynamo=False)
    proto = onnx.load(str(path))
    onnx.helper.set_model_props(proto, {CONFIG_METADATA_KEY: json.dumps(config.to_dict())})
    onnx.save(proto, str(path))


def export_denoiser(model: CausalDenoiser, path: Path | str) -> Path:
    """Write the step graph to ``path`` and the condition graph next to it; returns ``path``."""
    path = Path(path)
    model = model.eval()
    config = model.config
    _export(DenoiserStepGraph(model), example_step_inputs(config), path,
            ([*FRAME_INPUT_NAMES, *CACHE_INPUT_NAMES], list(OUTPUT_NAMES)), STEP_DYNAMIC_AXES, config)
    names = condition_input_names(config)
    axes = dict.fromkeys((*names, CONDITION_OUTPUT_NAME), FRAME_AXES)
    _export(DenoiserConditionGraph(model), example_condition_inputs(config), condition_path(path),
            (list(names), [CONDITION_OUTPUT_NAME]), axes, config)
    return path
