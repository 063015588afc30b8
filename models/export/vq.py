"""Export the VQ decoder's streaming step to ONNX, state in and state out as explicit tensors (torch)."""

from __future__ import annotations

import io
from pathlib import Path

import onnx
import torch
from torch import nn

from gesturecast.models.networks.vqvae import MotionVQVAE, VQDecoder
from gesturecast.models.runtime.vq import FRAMES_OUTPUT, LATENT_INPUT, state_input_name, state_output_name

ONNX_OPSET = 18
BATCH_AXIS = "batch"


class _DecoderStepGraph(nn.Module):
    """(latent, *state) → (frames, *new_state): the traceable form of :meth:`VQDecoder.step`."""

    def __init__(self, decoder: VQDecoder):
        super().__init__()
        self.decoder = decoder

    def forward(self, latent: torch.Tensor, *state: torch.Tensor) -> tuple[torch.Tensor, ...]:
        frames, new_state = self.decoder.step(latent, list(state))  # (B, d, D)
        return (frames, *new_state)


def export_vq_decoder_step(model: MotionVQVAE, path: str | Path | None = None) -> bytes:
    """Serialized ONNX model of one decoder step (dynamic batch); also written to ``path`` if given."""
    graph = _DecoderStepGraph(model.decoder).eval()
    latent = torch.zeros(1, model.config.latent_dim)  # (B, C)
    state = model.decoder.initial_state(batch=1)
    input_names = [LATENT_INPUT, *(state_input_name(i) for i in range(len(state)))]
    output_names = [FRAMES_OUTPUT, *(state_output_name(i) for i in range(len(state)))]
    buffer = io.BytesIO()
    with torch.no_grad():
        outputs = graph(latent, *state)  # (frames (1, d, D), *new_state)
        torch.onnx.export(graph, (latent, *state), buffer, input_names=input_names, output_names=output_names,
                          dynamic_axes={name: {0: BATCH_AXIS} for name in input_names + output_names},
                          opset_version=ONNX_OPSET, dynamo=False)
    data = _with_static_dims(buffer.getvalue(), [tuple(output.shape) for output in outputs])
    if path is not None:
        Path(path).write_bytes(data)
    return data


def _with_static_dims(data: bytes, shapes: list[tuple[int, ...]]) -> bytes:
    """The graph with every output's dimensions but the batch written as numbers: the runtime reads d and D from the
    frames output, and the TorchScript exporter leaves the ones computed by a reshape symbolic."""
    proto = onnx.load_from_string(data)
    for output, shape in zip(proto.graph.output, shapes, strict=True):
        for dim, size in zip(list(output.type.tensor_type.shape.dim)[1:], shape[1:], strict=True):
            dim.dim_value = size
    return proto.SerializeToString()
