"""Configuration of the causal latent denoiser (no torch import: the ONNX runtime reads it too).

Time layout (GestureDiffuCLIP §3.2, DiffuseStyleGesture §3): latent frame ``i`` covers motion frames
``[i*d, (i+1)*d)`` at 30 fps. Its audio condition is the window of ``audio_window`` feature frames
ending at motion frame ``(i+1)*d + audio_lookahead - 1`` (``δa`` frames of look-ahead).

Look-ahead truncation (docs/latency.md "Latency settings"): a model trained with
``lookahead_truncation`` also serves any shorter look-ahead δ ≤ δa. Its window stays where it is, the
``δa − δ`` frames past ``(i+1)*d + δ`` are masked out, and the model is told δ (a mask channel), so an
engine running at δ needs only the audio up to ``(i+1)*d + δ``. :func:`visible_config` is that
engine's view: the same window start, ending δ frames past the latent.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass, replace

import numpy as np

MODULATION_WIDTHS_PER_LAYER = 4  # (γ, β) before attention + (γ, β) before the feed-forward, D each


@dataclass(frozen=True)
class DenoiserConfig:
    latent_dim: int = 32  # C: VQ-VAE latent channels (VQVAEConfig.latent_dim)
    audio_dim: int = 67  # F: audio feature channels at 30 fps (StreamingFeatureExtractor().num_features)
    style_dim: int = 256  # S: style embedding size (wordllama)
    width: int = 160  # transformer model width
    num_layers: int = 4
    num_heads: int = 4
    ff_mult: int = 4
    window: int = 16  # W: past latent frames each frame may attend to (KV cache length)
    frames_per_latent: int = 4  # d: motion frames per latent frame
    audio_lookahead: int = 8  # δa: audio feature frames past the end of the latent
    audio_window: int = 16  # A: audio feature frames encoded per latent frame
    num_timesteps: int = 1000  # T: diffusion steps of the schedule
    lookahead_truncation: bool = False  # trained with random look-ahead δ ≤ δa: serves every δ in 0..δa

    @property
    def head_dim(self) -> int:
        return self.width // self.num_heads

    @property
    def condition_dim(self) -> int:
        """Per-frame condition width: the audio token (D) + scale and shift of both style modulations per layer (4D)."""
        return self.width * (1 + MODULATION_WIDTHS_PER_LAYER * self.num_layers)

    def __post_init__(self) -> None:
        if self.width % self.num_heads:
            raise ValueError(f"width {self.width} is not divisible by num_heads {self.num_heads}")

    def to_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_dict(cls, values: dict) -> DenoiserConfig:
        return cls(**values)


def supported_lookaheads(config: DenoiserConfig) -> tuple[int, ...]:
    """The look-aheads δ a model serves: 0..δa with truncation training, else only its own δa."""
    if config.lookahead_truncation:
        return tuple(range(config.audio_lookahead + 1))
    return (config.audio_lookahead,)


def visible_config(config: DenoiserConfig, lookahead: int) -> DenoiserConfig:
    """The audio layout an engine at look-ahead δ works with: windows end δ (not δa) frames past the latent
    and are ``A − (δa − δ)`` frames long (the masked tail is never needed); δ = δa gives ``config`` itself."""
    if lookahead not in supported_lookaheads(config):
        raise ValueError(f"look-ahead {lookahead} is not one of {supported_lookaheads(config)}")
    truncated = config.audio_lookahead - lookahead
    if truncated >= config.audio_window:
        raise ValueError(f"look-ahead {lookahead} leaves no frame of the {config.audio_window}-frame window")
    return replace(config, audio_lookahead=lookahead, audio_window=config.audio_window - truncated)


def pad_visible_window(window: np.ndarray, config: DenoiserConfig) -> np.ndarray:
    """A (A', F) window of :func:`visible_config` → the model's (A, F) window, the masked tail zero."""
    padded = np.zeros((config.audio_window, window.shape[-1]), np.float32)  # (A, F)
    padded[: len(window)] = window
    return padded


def audio_window_end(latent_index: int, config: DenoiserConfig) -> int:
    """Exclusive end (motion/audio frame index) of latent ``latent_index``'s audio window."""
    return (latent_index + 1) * config.frames_per_latent + config.audio_lookahead


def audio_window_bounds(latent_index: int, config: DenoiserConfig) -> tuple[int, int]:
    """``[start, end)`` audio feature frames seen by latent ``latent_index``; start may be negative (zero pad)."""
    end = audio_window_end(latent_index, config)
    return end - config.audio_window, end


def audio_frames_needed(num_latents: int, config: DenoiserConfig) -> int:
    """Audio feature frames a sequence of ``num_latents`` latents needs: ``N*d + δa``."""
    return audio_window_end(num_latents - 1, config)


def sequence_audio(audio: np.ndarray, start_latent: int, num_latents: int, config: DenoiserConfig,
                   transform: Callable[[np.ndarray], np.ndarray] | None = None) -> np.ndarray:
    """(T, F) features → the (N·d + δa, F) audio of latents ``[start, start + N)`` (training / evaluation
    sequences), zero-padded past the end of ``audio``; ``transform`` (augmentation) sees the available part."""
    needed = audio_frames_needed(num_latents, config)
    first = start_latent * config.frames_per_latent
    available = audio[first : first + needed]  # (≤ N·d + δa, F)
    if transform is not None:
        available = transform(available)
    window = np.zeros((needed, audio.shape[1]), np.float32)  # (N·d + δa, F)
    window[: len(available)] = available
    return window


def audio_window_from_features(features: np.ndarray, latent_index: int, config: DenoiserConfig) -> np.ndarray:
    """The (A, F) audio window of latent ``latent_index`` from a (T, F) feature array, zero-padded before 0.

    ``features`` must reach frame ``audio_window_end(latent_index) - 1`` (the look-ahead has arrived).
    """
    start, end = audio_window_bounds(latent_index, config)
    if end > len(features):
        raise ValueError(f"latent {latent_index} needs {end} audio frames, got {len(features)}")
    window = np.zeros((config.audio_window, features.shape[1]), dtype=np.float32)  # (A, F)
    clipped = max(start, 0)
    window[clipped - start :] = features[clipped:end]
    return window
