"""Fit the stylizer's parameters (``gesturecast.models.style.params``) per style from content-paired takes.

For every style s and every content c that has a take in s and in ``neutral``, both takes go through the
stylizer's own causal split (:class:`StyleFilter` with no style: centre m, gesture d = v − m) and give, per content
and body part (torso, head, arms): the gesture's amplitude (RMS of d) and tempo (mean speed of d over its RMS), as
ratios s / neutral. Each is summarised over the contents by the median (the actions range from bows to runs). The
tension α of a part is the value whose filter, run on the neutral takes, changes their tempo by the part's tempo
ratio (grid search); the amplitude gain g is the amplitude ratio over what that filter already does to the
amplitude. The posture offset of each joint is then what is left of the mean pose: the median over contents of
mean(v_s) − p − g·(mean(v_neutral) − p), with p the mean pivot the gain scales about on the neutral take (the rest
pose for the arms, the centre for the torso and head). Tremor is the
high-frequency (above ~3 Hz) motion the style adds over neutral, if any. Everything is clipped to
:data:`LIMITS` so that no style bends a body further than the takes do.
"""

from __future__ import annotations

from collections import defaultdict

import numpy as np
from scipy.signal import lfilter

from gesturecast.models.style.params import (
    CENTRE_S,
    LOG_GAIN,
    OFFSET,
    STYLED_JOINTS,
    TENSION,
    TREMOR,
    StyleFilter,
    StyleParams,
    ema_weight,
    pivots,
    rotation_vectors,
    with_rotation_vectors,
)
from gesturecast.realtime.pose.idle import IdleConfig, relaxed_pose
from gesturecast.tools.style.takes import NEUTRAL, Take

FIT_PARTS = {"torso": ("Spine", "Chest", "UpperChest"), "head": ("Neck", "Head"),
             "arms": STYLED_JOINTS[5:]}
TENSION_GRID = np.linspace(-0.9, 2.0, 30)
HIGH_PASS_S = 0.05  # deviation above ~3 Hz: what a tremor adds
LIMITS = {"offset_rad": 0.6, "log_gain": np.log(2.5), "tremor_rad": 0.0005}


def _rows(part: str) -> np.ndarray:
    return np.array([STYLED_JOINTS.index(name) for name in FIT_PARTS[part]])


REST = rotation_vectors(relaxed_pose(IdleConfig()))  # (S, 3) the rest pose the stylizer scales about


def split(take: Take, values: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """A take's rotation vectors v (T, S, 3) and its gesture d (T, S, 3) after the style filter with ``values``
    (S, CHANNELS) at time 0 (no tremor; no gain or offset is given here); None: the plain split d = v − m."""
    v = rotation_vectors(take.motion.rotations)  # (T, S, 3)
    values = StyleParams.identity().values if values is None else values
    values = np.broadcast_to(values, (len(v), *values.shape))  # (T, S, CHANNELS)
    styled = StyleFilter(take.motion.fps, REST).run(v, values, np.zeros(len(v)))  # (T, S, 3)
    return v, styled - _centres(v, take.motion.fps) - values[..., OFFSET]


def restyled_rotations(take: Take, values: np.ndarray) -> np.ndarray:
    """The take's rotations (T, J, 4) re-performed by the stylizer's filter with parameters ``values`` (S, CHANNELS)
    held over the take (stream time from 0)."""
    v = rotation_vectors(take.motion.rotations)  # (T, S, 3)
    held = np.broadcast_to(values, (len(v), *values.shape))  # (T, S, CHANNELS)
    styled = StyleFilter(take.motion.fps, REST).run(v, held, np.arange(len(v)) / take.motion.fps)  # (T, S, 3)
    return with_rotation_vectors(take.motion.rotations, styled)


def _centres(v: np.ndarray, fps: float) -> np.ndarray:
    """The filter's centre m (T, S, 3) of rotation vectors v (T, S, 3)."""
    a = ema_weight(CENTRE_S, fps)
    return lfilter([a], [1.0, a - 1.0], v, axis=0, zi=(1.0 - a) * v[:1])[0]


def amplitude(d: np.ndarray, rows: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.sum(d[:, rows] ** 2, axis=-1))))


def tempo(d: np.ndarray, rows: np.ndarray, fps: float) -> float:
    """Mean angular speed of the part's gesture (rad/s) over its amplitude: about oscillations per second."""
    speed = float(np.mean(np.linalg.norm(np.diff(d[:, rows], axis=0), axis=-1))) * fps
    return speed / max(amplitude(d, rows), 1e-6)


def high_frequency(d: np.ndarray, rows: np.ndarray, fps: float) -> float:
    """RMS of the part's gesture above ~3 Hz (d minus its one-pole low-pass)."""
    a, low, residual = ema_weight(HIGH_PASS_S, fps), d[0].copy(), np.empty_like(d)
    for t, frame in enumerate(d):
        low += a * (frame - low)
        residual[t] = frame - low
    return amplitude(residual, rows)


def _pairs(takes: list[Take]) -> dict[str, list[tuple[Take, Take]]]:
    """style → [(neutral take, styled take)] over the contents they share (the first take of each)."""
    first: dict[tuple[str, str], Take] = {}
    for take in takes:
        first.setdefault((take.content, take.style), take)
    pairs: dict[str, list[tuple[Take, Take]]] = defaultdict(list)
    for (content, style), take in sorted(first.items()):
        if style != NEUTRAL and (content, NEUTRAL) in first:
            pairs[style].append((first[(content, NEUTRAL)], take))
    return pairs


def _tension_effects(neutral: list[Take]) -> dict[str, np.ndarray]:
    """part → (G, 2) median log change of (tempo, amplitude) that each tension of TENSION_GRID makes on neutral."""
    effects = {part: np.zeros((len(TENSION_GRID), 2)) for part in FIT_PARTS}
    plain = [split(take) for take in neutral]
    for g, alpha in enumerate(TENSION_GRID):
        values = StyleParams.identity().values.copy()
        values[:, TENSION] = alpha
        filtered = [split(take, values) for take in neutral]
        for part in FIT_PARTS:
            rows = _rows(part)
            changes = [(np.log(tempo(df, rows, take.motion.fps) / tempo(d, rows, take.motion.fps)),
                        np.log(amplitude(df, rows) / amplitude(d, rows)))
                       for take, (_, d), (_, df) in zip(neutral, plain, filtered, strict=True)]
            effects[part][g] = np.median(np.array(changes), axis=0)
    return effects


def fit_style(pairs: list[tuple[Take, Take]], effects: dict[str, np.ndarray]) -> tuple[StyleParams, dict]:
    """One style's parameters from its (neutral, styled) take pairs; also the per-part ratios measured."""
    values = StyleParams.identity().values.copy()
    splits = [(split(n), split(s), n.motion.fps) for n, s in pairs]
    report = {}
    for part in FIT_PARTS:
        rows = _rows(part)
        log_amp = np.median([np.log(amplitude(sd, rows) / amplitude(nd, rows)) for (_, nd), (_, sd), _ in splits])
        log_tempo = np.median([np.log(tempo(sd, rows, f) / tempo(nd, rows, f)) for (_, nd), (_, sd), f in splits])
        g = int(np.argmin(np.abs(effects[part][:, 0] - log_tempo)))
        values[rows, TENSION] = TENSION_GRID[g]
        values[rows, LOG_GAIN] = np.clip(log_amp - effects[part][g, 1], -LIMITS["log_gain"], LIMITS["log_gain"])
        extra = np.median([high_frequency(sd, rows, f) ** 2 - (np.exp(log_amp) * high_frequency(nd, rows, f)) ** 2
                           for (_, nd), (_, sd), f in splits])  # beyond what the amplitude change explains
        values[rows, TREMOR] = min(float(np.sqrt(max(extra, 0.0))), LIMITS["tremor_rad"])
        report[part] = {"amplitude_ratio": float(np.exp(log_amp)), "tempo_ratio": float(np.exp(log_tempo)),
                        "contents": len(splits)}
    gain = np.exp(values[:, LOG_GAIN, None])  # (S, 1)
    offsets = [_offset(n_v, s_v, f, gain) for (n_v, _), (s_v, _), f in splits]
    values[:, OFFSET] = _clip_norm(np.median(np.array(offsets), axis=0), LIMITS["offset_rad"])  # (S, 3)
    return StyleParams(values), report


def _offset(neutral: np.ndarray, styled: np.ndarray, fps: float, gain: np.ndarray) -> np.ndarray:
    """(S, 3) what the gain (S, 1) leaves of the styled take's mean pose, from both takes' rotation vectors
    (T, S, 3): mean(v_s) − p − g·(mean(v_n) − p), p the mean pivot on the neutral take."""
    pivot = pivots(REST, _centres(neutral, fps)).mean(axis=0)  # (S, 3)
    return styled.mean(axis=0) - pivot - gain * (neutral.mean(axis=0) - pivot)


def _clip_norm(vectors: np.ndarray, limit: float) -> np.ndarray:
    """Rotation vectors (S, 3) shortened to at most ``limit`` radians."""
    norms = np.linalg.norm(vectors, axis=-1, keepdims=True)
    return vectors * np.minimum(1.0, limit / np.maximum(norms, 1e-12))


def fit_styles(takes: list[Take]) -> tuple[dict[str, StyleParams], dict]:
    """Every style's parameters (``neutral``: the identity) and the measured ratios, from paired takes."""
    pairs = _pairs(takes)
    neutral = [take for take in takes if take.style == NEUTRAL]
    effects = _tension_effects(neutral)
    styles, report = {NEUTRAL: StyleParams.identity()}, {}
    for style, style_pairs in sorted(pairs.items()):
        styles[style], report[style] = fit_style(style_pairs, effects)
    return styles, report
