"""ONNX export of the denoiser's incremental step, KV cache and history as explicit inputs/outputs.

Graph (dynamic B = batch, M = new frames; W, L, H, Dh fixed by the config):

    inputs   x_t (B, M, C) float32, t (B, M) int64 (CLEAN_TIMESTEP = -1 for a clean history frame),
             audio_windows (B, M, A, F), audio_present (B, M), style (B, M, S), style_present (B, M),
             cache_keys / cache_values (L, B, H, W, Dh), cache_length (B,) int64 (valid = last slots)
    outputs  x0 (B, M, C), new_keys / new_values (L, B, H, M, Dh) of the M new frames

The caller rolls the cache (:func:`gesturecast.models.runtime_denoiser.roll_cache`), which lets one
call both commit the previous clean latent and take the first denoising step of the next one (M = 2).
The config travels in the model's metadata (key ``gesturecast.denoiser_config``).
"""

from __future__ import annotations

import json
from pathlib import Path

import onnx
import torch
from torch import nn

from gesturecast.models.denoiser import CausalDenoiser
from gesturecast.models.denoiser_config import DenoiserConfig
from gesturecast.models.runtime_denoiser import CACHE_INPUT_NAMES, CONFIG_METADATA_KEY, FRAME_INPUT_NAMES, OUTPUT_NAMES

OPSET_VERSION = 17
INPUT_NAMES = FRAME_INPUT_NAMES + CACHE_INPUT_NAMES
DYNAMIC_AXES = {
    **{name: {0: "batch", 1: "new_frames"} for name in FRAME_INPUT_NAMES},
    "cache_keys": {1: "batch"},
    "cache_values": {1: "batch"},
    "cache_length": {0: "batch"},
    "x0": {0: "batch", 1: "new_frames"},
    "new_keys": {1: "batch", 3: "new_frames"},
    "new_values": {1: "batch", 3: "new_frames"},
}


class DenoiserStepGraph(nn.Module):
    """``CausalDenoiser.forward_chunk`` with a fixed-size (W-frame) cache, as exported."""

    def __init__(self, model: CausalDenoiser):
        super().__init__()
        self.model = model

    def forward(self, x_t, t, audio_windows, audio_present, style, style_present, cache_keys, cache_values, length):
        return self.model.forward_chunk(
            x_t, t, audio_windows, audio_present, style, style_present, cache_keys, cache_values, length
        )


def example_inputs(config: DenoiserConfig, batch: int = 2, new_frames: int = 2) -> tuple[torch.Tensor, ...]:
    """Tracing inputs with the graph's dtypes and shapes."""
    cache_shape = (config.num_layers, batch, config.num_heads, config.window, config.head_dim)
    return (
        torch.zeros(batch, new_frames, config.latent_dim),
        torch.zeros(batch, new_frames, dtype=torch.int64),
        torch.zeros(batch, new_frames, config.audio_window, config.audio_dim),
        torch.ones(batch, new_frames),
        torch.zeros(batch, new_frames, config.style_dim),
        torch.ones(batch, new_frames),
        torch.zeros(cache_shape),
        torch.zeros(cache_shape),
        torch.ones(batch, dtype=torch.int64),
    )


def export_denoiser(model: CausalDenoiser, path: Path | str) -> Path:
    """Write the step graph to ``path`` (a single self-contained .onnx file) and return the path."""
    path = Path(path)
    graph = DenoiserStepGraph(model.eval())
    with torch.no_grad():
        torch.onnx.export(
            graph,
            example_inputs(model.config),
            str(path),
            input_names=list(INPUT_NAMES),
            output_names=list(OUTPUT_NAMES),
            dynamic_axes=DYNAMIC_AXES,
            opset_version=OPSET_VERSION,
            dynamo=False,
        )
    proto = onnx.load(str(path))
    onnx.helper.set_model_props(proto, {CONFIG_METADATA_KEY: json.dumps(model.config.to_dict())})
    onnx.save(proto, str(path))
    return path
