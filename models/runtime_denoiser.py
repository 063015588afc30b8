"""onnxruntime wrapper of the exported denoiser step (numpy + onnxruntime only: no torch at run time).

Streaming state is explicit (silero-vad habit): :class:`DenoiserState` holds the fixed-size KV cache
of the last W clean latents and, after :meth:`DenoiserRuntime.commit`, the pending clean latent.
The pending latent is folded into the next :meth:`DenoiserRuntime.step` as an extra frame (M = 2),
so committing history costs no extra call: K DDIM steps per latent are K calls.

Typical use per latent frame (the caller owns the sampler loop, diffusers habit)::

    for t, t_prev in sampling_plan(...):
        x0 = runtime.step(x, t, audio_window, style)          # (B, C), B = 2 for CFG
        x = sampler_step(schedule, sampler, guide(x0), t, t_prev, x, noise)
    runtime.commit(x, audio_window, style)                    # x is now the clean latent
"""

from __future__ import annotations

import json
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from gesturecast.errors import UserError
from gesturecast.models.denoiser_config import DenoiserConfig
from gesturecast.models.diffusion import CLEAN_TIMESTEP
from gesturecast.models.ort_session import DEFAULT_THREADS, make_session

CONFIG_METADATA_KEY = "gesturecast.denoiser_config"  # ONNX metadata entry holding the DenoiserConfig JSON
FRAME_INPUT_NAMES = ("x_t", "t", "audio_windows", "audio_present", "style", "style_present")
CACHE_INPUT_NAMES = ("cache_keys", "cache_values", "cache_length")
OUTPUT_NAMES = ("x0", "new_keys", "new_values")
CACHE_AXIS = 3  # frame axis of (L, B, H, W, Dh)


@dataclass(frozen=True)
class FrameInputs:
    """Per-frame inputs of one or more frames: x (B, M, C), t (B, M), windows (B, M, A, F), ... (B, M[, S])."""

    x: np.ndarray
    t: np.ndarray
    windows: np.ndarray
    audio_present: np.ndarray
    style: np.ndarray
    style_present: np.ndarray

    def concat(self, later: FrameInputs) -> FrameInputs:
        pairs = zip(self.astuple(), later.astuple(), strict=True)
        return FrameInputs(*(np.concatenate([a, b], axis=1) for a, b in pairs))

    def astuple(self) -> tuple[np.ndarray, ...]:
        return (self.x, self.t, self.windows, self.audio_present, self.style, self.style_present)


@dataclass(frozen=True)
class DenoiserState:
    keys: np.ndarray  # (L, B, H, W, Dh)
    values: np.ndarray  # (L, B, H, W, Dh)
    length: np.ndarray  # (B,) int64: valid slots are the last ``length``
    pending: FrameInputs | None = None  # committed clean latent not yet in the cache


def roll_cache(state: DenoiserState, new_keys: np.ndarray, new_values: np.ndarray) -> DenoiserState:
    """Append (L, B, H, M, Dh) frames, evicting the oldest beyond the window."""
    window = state.keys.shape[CACHE_AXIS]
    keys = np.concatenate([state.keys, new_keys], axis=CACHE_AXIS)[:, :, :, -window:]  # (L, B, H, W, Dh)
    values = np.concatenate([state.values, new_values], axis=CACHE_AXIS)[:, :, :, -window:]  # (L, B, H, W, Dh)
    length = np.minimum(state.length + new_keys.shape[CACHE_AXIS], window)
    return DenoiserState(keys, values, length.astype(np.int64), state.pending)


class DenoiserRuntime:
    def __init__(self, path: Path | str | bytes, threads: int = DEFAULT_THREADS):
        self.session = make_session(path, threads)
        metadata = self.session.get_modelmeta().custom_metadata_map
        if CONFIG_METADATA_KEY not in metadata:
            raise UserError(f"{path!s:.200} is not a gesturecast denoiser export (no {CONFIG_METADATA_KEY} metadata)")
        self.config = DenoiserConfig.from_dict(json.loads(metadata[CONFIG_METADATA_KEY]))
        self.state = self.empty_state(1)

    def empty_state(self, batch: int) -> DenoiserState:
        cfg = self.config
        shape = (cfg.num_layers, batch, cfg.num_heads, cfg.window, cfg.head_dim)
        zeros = np.zeros(shape, dtype=np.float32)
        return DenoiserState(zeros, zeros.copy(), np.zeros(batch, dtype=np.int64))

    def reset(self, batch: int = 1) -> None:
        """Forget all history (start of a stream); ``batch`` rows, e.g. 2 for cond + uncond guidance."""
        self.state = self.empty_state(batch)

    def run(self, frames: FrameInputs, state: DenoiserState) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Pure graph call: → x0 (B, M, C), new keys/values (L, B, H, M, Dh)."""
        feeds = dict(zip(FRAME_INPUT_NAMES, frames.astuple(), strict=True))
        feeds.update(cache_keys=state.keys, cache_values=state.values, cache_length=state.length)
        x0, new_keys, new_values = self.session.run(None, feeds)
        return x0, new_keys, new_values

    def frame(self, x, t, audio_window, style, audio_present=None, style_present=None) -> FrameInputs:
        """One frame's inputs as a FrameInputs with M = 1: x (B, C), t int or (B,), audio_window (B, A, F),
        style (B, S), audio_present / style_present (B,) in {0, 1} (default 1)."""
        batch = x.shape[0]
        ones = np.ones(batch, dtype=np.float32)
        return FrameInputs(
            np.asarray(x, np.float32)[:, None],
            np.broadcast_to(np.asarray(t, np.int64), (batch,))[:, None].copy(),
            np.asarray(audio_window, np.float32)[:, None],
            np.asarray(ones if audio_present is None else audio_present, np.float32)[:, None],
            np.asarray(style, np.float32)[:, None],
            np.asarray(ones if style_present is None else style_present, np.float32)[:, None],
        )

    def step(self, x_t, t, audio_window, style, audio_present=None, style_present=None) -> np.ndarray:
        """x0 prediction (B, C) for the current noisy latent given the history; history is unchanged
        except that a pending committed latent is moved into the cache."""
        current = self.frame(x_t, t, audio_window, style, audio_present, style_present)
        pending = self.state.pending
        frames = current if pending is None else pending.concat(current)
        x0, new_keys, new_values = self.run(frames, self.state)
        if pending is not None:
            self.state = replace(roll_cache(self.state, new_keys[:, :, :, :1], new_values[:, :, :, :1]), pending=None)
        return x0[:, -1]

    def commit(self, x0, audio_window, style, audio_present=None, style_present=None) -> None:
        """Make the clean latent x0 (B, C) history (folded into the next :meth:`step`)."""
        if self.state.pending is not None:
            self.flush()
        clean = self.frame(x0, CLEAN_TIMESTEP, audio_window, style, audio_present, style_present)
        self.state = replace(self.state, pending=clean)

    def flush(self) -> None:
        """Move a pending committed latent into the cache now (one call)."""
        pending = self.state.pending
        if pending is None:
            return
        _, new_keys, new_values = self.run(pending, self.state)
        self.state = replace(roll_cache(self.state, new_keys, new_values), pending=None)
