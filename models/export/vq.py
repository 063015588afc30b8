"""Export the VQ decoder's streaming step to ONNX, state in and state out as explicit tensors (torch)."""

from __future__ import annotations

from pathlib import Path

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
    batch = torch.export.Dim(BATCH_AXIS)
    with torch.no_grad():
        program = torch.onnx.export(
            graph,
            (latent, *state),
            input_names=input_names,
            output_names=output_names,
            dynamic_shapes=({0: batch}, tuple({0: batch} for _ in state)),  # (latent, *state) as export sees it
            opset_version=ONNX_OPSET,
            dynamo=True,
            verbose=False,
        )
    data = program.model_proto.SerializeToString()
    if path is not None:
        Path(path).write_bytes(data)
    return data
