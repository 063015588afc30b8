"""Streaming VQ decoder on onnxruntime (numpy + onnxruntime only: no torch at run time).

The ONNX graph is one decoder step (:func:`gesturecast.models.export.vq.export_vq_decoder_step`):
inputs ``latent`` (B, C) and ``state_in_i`` (B, channels_i, context_i); outputs ``frames``
(B, d, D) and ``state_out_i``. The wrapper owns the state between calls, like silero-vad: two sets of state
buffers bound to the graph once (onnxruntime I/O binding), one read and the other written at each step, then the
other way round, so a step copies and allocates none of its 2 × 24 state tensors (a fifth of the decoder's CPU).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import onnxruntime as ort

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
        self._latent = np.zeros((batch, self.latent_dim), np.float32)  # bound input: written before each step
        self._frames = ort.OrtValue.ortvalue_from_numpy(np.zeros((batch, self.frames_per_latent, self.feature_dim),
                                                                 np.float32))
        self._latent_value = ort.OrtValue.ortvalue_from_numpy(self._latent)  # shares the array's memory
        self._run_options = ort.RunOptions()
        self.reset()

    def reset(self) -> None:
        """Forget the past: zero state, as at the start of a stream."""
        self._buffers = [[ort.OrtValue.ortvalue_from_numpy(np.zeros((self.batch, channels, context), np.float32))
                          for channels, context in self._state_shapes] for _ in range(2)]  # kept: bound memory
        self._bindings = [self._binding(self._buffers[read], self._buffers[1 - read]) for read in range(2)]
        self._turn = 0  # the binding whose state buffers hold the current state

    def _binding(self, state_in: list[ort.OrtValue], state_out: list[ort.OrtValue]) -> ort.IOBinding:
        binding = self.session.io_binding()
        binding.bind_ortvalue_input(LATENT_INPUT, self._latent_value)
        binding.bind_ortvalue_output(FRAMES_OUTPUT, self._frames)
        for index, (old, new) in enumerate(zip(state_in, state_out, strict=True)):
            binding.bind_ortvalue_input(state_input_name(index), old)
            binding.bind_ortvalue_output(state_output_name(index), new)
        return binding

    def step(self, latent: np.ndarray) -> np.ndarray:
        """latent (C,) or (B, C) → frames (d, D) or (B, d, D), float32."""
        self._latent[:] = np.asarray(latent, dtype=np.float32).reshape(self.batch, self.latent_dim)  # (B, C)
        self.session.run_with_iobinding(self._bindings[self._turn], self._run_options)
        self._turn = 1 - self._turn
        frames = self._frames.numpy().copy()  # (B, d, D); numpy() is a view of the bound buffer
        return frames[0] if np.ndim(latent) == 1 else frames

    def decode(self, latents: np.ndarray) -> np.ndarray:
        """Convenience for offline use: latents (N, C) stepped from the current state → (N·d, D)."""
        return np.concatenate([self.step(latent) for latent in np.asarray(latents)], axis=0)
