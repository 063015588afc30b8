"""Streaming VQ decoder on onnxruntime (numpy + onnxruntime only: no torch at run time).

The ONNX graph is one decoder step (:func:`gesturecast.models.export.vq.export_vq_decoder_step`):
inputs ``latent`` (B, C) and ``state_in_i`` (B, channels_i, context_i); outputs ``frames``
(B, d, D) and ``state_out_i``. The wrapper owns the state between calls, like silero-vad.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gesturecast.models.runtime.ort_session import DEFAULT_THREADS, make_session

LATENT_INPUT = "latent"
FRAMES_OUTPUT = "frames"
STATE_INPUT_PREFIX = "state_in_"
STATE_OUTPUT_PREFIX = "state_out_"


def state_input_name(index: int) -> str:
    return f"{STATE_INPUT_PREFIX}{index}"


def state_output_name(index: int) -> str:
    return f"{STATE_OUTPUT_PREFIX}{index}"


class StreamingVQDecoder:
    """One latent frame in, d normalized pose-feature frames out; state kept between calls."""

    def __init__(self, path_or_bytes: str | Path | bytes, threads: int = DEFAULT_THREADS, batch: int = 1):
        self.session = make_session(path_or_bytes, threads=threads)
        inputs = {node.name: node.shape for node in self.session.get_inputs()}
        self.latent_dim = int(inputs[LATENT_INPUT][1])
        self._state_shapes = [
            (int(inputs[state_input_name(i)][1]), int(inputs[state_input_name(i)][2])) for i in range(len(inputs) - 1)
        ]  # every input but the latent is a state
        frames_shape = next(node.shape for node in self.session.get_outputs() if node.name == FRAMES_OUTPUT)
        self.frames_per_latent = int(frames_shape[1])
        self.feature_dim = int(frames_shape[2])
        self.batch = batch
        self._state: list[np.ndarray] = []
        self.reset()

    def reset(self) -> None:
        """Forget the past: zero state, as at the start of a stream."""
        self._state = [
            np.zeros((self.batch, channels, context), np.float32) for channels, context in self._state_shapes
        ]

    def step(self, latent: np.ndarray) -> np.ndarray:
        """latent (C,) or (B, C) → frames (d, D) or (B, d, D), float32."""
        batched = np.asarray(latent, dtype=np.float32).reshape(self.batch, self.latent_dim)  # (B, C)
        feeds = {LATENT_INPUT: batched}
        feeds.update({state_input_name(i): state for i, state in enumerate(self._state)})
        output_names = [FRAMES_OUTPUT, *(state_output_name(i) for i in range(len(self._state)))]
        frames, *self._state = self.session.run(output_names, feeds)
        return frames[0] if np.ndim(latent) == 1 else frames

    def decode(self, latents: np.ndarray) -> np.ndarray:
        """Convenience for offline use: latents (N, C) stepped from the current state → (N·d, D)."""
        return np.concatenate([self.step(latent) for latent in np.asarray(latents)], axis=0)
