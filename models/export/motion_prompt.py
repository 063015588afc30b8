"""ONNX export of the motion-prompt encoder: features (1, T, D) with dynamic T → embedding (1, S)."""

from __future__ import annotations

from pathlib import Path

import torch

from gesturecast.models.networks.motion_prompt import MotionPromptEncoder

OPSET_VERSION = 17
EXAMPLE_FRAMES = 120


def export_motion_prompt(encoder: MotionPromptEncoder, path: Path | str) -> Path:
    path = Path(path)
    example = torch.zeros(1, EXAMPLE_FRAMES, encoder.config.feature_dim)
    with torch.no_grad():
        torch.onnx.export(
            encoder.eval(),
            (example,),
            str(path),
            input_names=["features"],
            output_names=["embedding"],
            dynamic_axes={"features": {0: "batch", 1: "frames"}, "embedding": {0: "batch"}},
            opset_version=OPSET_VERSION,
            dynamo=False,
        )
    return path
