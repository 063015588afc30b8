"""onnxruntime wrapper of the exported denoiser (numpy + onnxruntime only: no torch at run time).

Two graphs (see :mod:`gesturecast.models.export.denoiser_onnx`): the per-frame *condition* (audio token and
style modulations, once per latent frame) and the *step* (one denoiser call given x_t, t and the
condition). Streaming state is explicit (silero-vad habit): :class:`DenoiserState` holds the
fixed-size KV cache of the last W clean latents and, after :meth:`DenoiserRuntime.commit`, the
pending clean latent. The pending latent is folded into the next :meth:`DenoiserRuntime.step` as an
extra frame (M = 2), so committing history costs no extra call: K DDIM steps per latent are K step
calls plus one condition call.

Typical use per latent frame (the caller owns the sampler loop, diffusers habit)::

    condition = runtime.frame_condition(audio_window, style)      # (B, Dc), B = 2 for CFG
    for t, t_prev in sampling_plan(...):
        x0 = runtime.step(x, t, condition)                        # (B, C)
        x = sampler_step(schedule, sampler, guide(x0), t, t_prev, x, noise)
    runtime.commit(x, condition)                                  # x is now the clean latent
"""

from __future__ import annotations

import json
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from gesturecast.errors import UserError
from gesturecast.models.generator.denoiser_config import DenoiserConfig
from gesturecast.models.generator.diffusion import CLEAN_TIMESTEP
from gesturecast.models.runtime.ort_session import DEFAULT_THREADS, make_session

CONFIG_METADATA_KEY = "gesturecast.denoiser_config"  # ONNX metadata entry holding the DenoiserConfig JSON
FRAME_INPUT_NAMES = ("x_t", "t", "condition")
CONDITION_INPUT_NAMES = ("audio_windows", "audio_present", "style", "style_present")
LOOKAHEAD_INPUT_NAME = "lookahead"  # condition input of look-ahead truncation models only: δ (B, M)
CONDITION_OUTPUT_NAME = "condition"
CONDITION_FILE_SUFFIX = "_condition"  # denoiser.onnx → denoiser_condition.onnx
CACHE_INPUT_NAMES = ("cache_keys", "cache_values", "cache_length")
OUTPUT_NAMES = ("x0", "new_keys", "new_values")
CACHE_AXIS = 3  # frame axis of (L, B, H, W, Dh)


def condition_input_names(config: DenoiserConfig) -> tuple[str, ...]:
    """The condition graph's inputs: the four of every model, plus ``lookahead`` for truncation models."""
    return (*CONDITION_INPUT_NAMES, LOOKAHEAD_INPUT_NAME) if config.lookahead_truncation else CONDITION_INPUT_NAMES


def condition_path(step_path: Path | str) -> Path:
    """Where the condition graph of the step graph at ``step_path`` lives (same folder)."""
    step_path = Path(step_path)
    return step_path.with_name(step_path.stem + CONDITION_FILE_SUFFIX + step_path.suffix)


@dataclass(frozen=True)
class FrameInputs:
    """Step-graph inputs of one or more frames: x (B, M, C), t (B, M) int64, condition (B, M, Dc)."""

    x: np.ndarray
    t: np.ndarray
    condition: np.ndarray

    def concat(self, later: FrameInputs) -> FrameInputs:
        pairs = zip(self.astuple(), later.astuple(), strict=True)
        return FrameInputs(*(np.concatenate([a, b], axis=1) for a, b in pairs))

    def astuple(self) -> tuple[np.ndarray, ...]:
        return (self.x, self.t, self.condition)


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


def _check_metadata(session, path: Path) -> DenoiserConfig:
    metadata = session.get_modelmeta().custom_metadata_map
    if CONFIG_METADATA_KEY not in metadata:
        raise UserError(f"{path!s:.200} is not a gesturecast denoiser export (no {CONFIG_METADATA_KEY} metadata)")
    return DenoiserConfig.from_dict(json.loads(metadata[CONFIG_METADATA_KEY]))


class DenoiserRuntime:
    def __init__(self, path: Path | str, threads: int = DEFAULT_THREADS):
        path = Path(path)
        session = make_session(path, threads)
        config = _check_metadata(session, path)
        conditions = condition_path(path)
        if not conditions.is_file():
            raise UserError(f"{conditions} is missing (a denoiser export has two graphs); re-export the model "
                            "with `gesturecast export`")
        condition_session = make_session(conditions, threads)
        _check_metadata(condition_session, conditions)
        self._attach(session, condition_session, config)

    def _attach(self, session, condition_session, config: DenoiserConfig) -> None:
        """The graphs to call (anything with ``run(output_names, feeds)``) and a fresh one-row state."""
        self.session = session
        self.condition_session = condition_session
        self.config = config
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
        """Pure step-graph call: → x0 (B, M, C), new keys/values (L, B, H, M, Dh)."""
        feeds = dict(zip(FRAME_INPUT_NAMES, frames.astuple(), strict=True))
        feeds.update(cache_keys=state.keys, cache_values=state.values, cache_length=state.length)
        x0, new_keys, new_values = self.session.run(None, feeds)
        return x0, new_keys, new_values

    def condition(self, windows, audio_present, style, style_present, lookahead: int | None = None) -> np.ndarray:
        """Condition-graph call on M frames: windows (B, M, A, F), audio_present (B, M), style (B, M, S),
        style_present (B, M), look-ahead δ of every frame (default δa; another δ needs a truncation model)
        → (B, M, Dc)."""
        cfg = self.config
        lookahead = cfg.audio_lookahead if lookahead is None else lookahead
        arrays = [windows, audio_present, style, style_present]
        if cfg.lookahead_truncation:
            arrays.append(np.full(np.shape(audio_present), lookahead))
        elif lookahead != cfg.audio_lookahead:
            raise ValueError(f"this denoiser serves only look-ahead {cfg.audio_lookahead}, not {lookahead}")
        names = condition_input_names(cfg)
        feeds = {name: np.asarray(value, np.float32) for name, value in zip(names, arrays, strict=True)}
        return self.condition_session.run(None, feeds)[0]

    def frame_condition(self, audio_window, style, audio_present=None, style_present=None,
                        lookahead: int | None = None) -> np.ndarray:
        """One frame's condition (B, Dc): audio_window (B, A, F), style (B, S), audio_present / style_present
        (B,) in {0, 1} (default 1), look-ahead δ (default δa)."""
        ones = np.ones(len(style), dtype=np.float32)
        present = ones if audio_present is None else audio_present
        style_on = ones if style_present is None else style_present
        arrays = (audio_window, present, style, style_on)
        return self.condition(*(np.asarray(value, np.float32)[:, None] for value in arrays), lookahead)[:, 0]

    @staticmethod
    def frame(x, t, condition) -> FrameInputs:
        """One frame's step inputs with M = 1: x (B, C), t int or (B,), condition (B, Dc)."""
        batch = x.shape[0]
        return FrameInputs(
            np.asarray(x, np.float32)[:, None],
            np.broadcast_to(np.asarray(t, np.int64), (batch,))[:, None].copy(),
            np.asarray(condition, np.float32)[:, None],
        )

    def step(self, x_t, t, condition) -> np.ndarray:
        """x0 prediction (B, C) for the current noisy latent (B, C) given the history and its (B, Dc) condition;
        history is unchanged except that a pending committed latent is moved into the cache."""
        current = self.frame(x_t, t, condition)
        pending = self.state.pending
        frames = current if pending is None else pending.concat(current)
        x0, new_keys, new_values = self.run(frames, self.state)
        if pending is not None:
            self.state = replace(roll_cache(self.state, new_keys[:, :, :, :1], new_values[:, :, :, :1]), pending=None)
        return x0[:, -1]

    def commit(self, x0, condition) -> None:
        """Make the clean latent x0 (B, C) history, with the (B, Dc) condition it was made with (folded into the
        next :meth:`step`)."""
        if self.state.pending is not None:
            self.flush()
        self.state = replace(self.state, pending=self.frame(x0, CLEAN_TIMESTEP, condition))

    def flush(self) -> None:
        """Move a pending committed latent into the cache now (one call)."""
        pending = self.state.pending
        if pending is None:
            return
        _, new_keys, new_values = self.run(pending, self.state)
        self.state = replace(roll_cache(self.state, new_keys, new_values), pending=None)
