"""Which rows one batched denoiser call holds and how their x0 predictions become one (numpy only).

Every prompt of the *style mixture* (R prompts, row 0 the base style c1) is its own sampling trajectory: its
own x_t and its own history of clean latents (in its row's KV cache), i.e. the whole-body generation of that
prompt alone. Rows, in order: the R style rows, then c2 (only with γ ≠ 1; it mixes into the base trajectory),
one null-style row per trajectory (only with guidance s ≠ 1) and one row of each prompt without the audio (only
with audio guidance s_a ≠ 1). With one style that is [c1, (c2), (∅), (c1, ∅a)] as in the single-style sampler.

Per trajectory r (GestureDiffuCLIP §6.3's body-part style control, with the parts' trajectories kept apart):

    x̂0_r = D(c_r)                                       (style r)
    x̂0_0 ← γ·x̂0_0 + (1 − γ)·D(c2)                       (DiffuseStyleGesture style interpolation, base only)
    x̂0_r ← D_r(∅) + s·(x̂0_r − D_r(∅))                   (classifier-free guidance, Ho & Salimans 2022 eq. 6)
    x̂0_r ← x̂0_r + (s_a − 1)·(D(c_r) − D(c_r, ∅a))       (audio guidance)

and the motion is their fusion, z = Σ_r W_r ⊙ z_r, with a weight matrix W (R, C) giving each latent channel's
share of each trajectory, Σ_r W[r, c] = 1: with per-part prompts W[r] is the 0/1 mask M_o of the channels of
the parts whose prompt is r (E = Σ_o E_o · M_o on whole trajectories), and a change of part styles ramps W (a
soft mask) instead of jumping. A part therefore moves as the same speech, seed and prompt move it on a whole
body; the parts share the audio and the noise, so their timing stays one. Fusing the predictions of one shared
trajectory instead (the first version) fed every prompt's row a history made mostly of the other prompts'
parts, which pulled a part back toward the base style (docs/part-styles.md).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from gesturecast.errors import UserError
from gesturecast.models.generator.diffusion import classifier_free_guidance, style_interpolation
from gesturecast.models.generator.style_prompt import StylePrompt
from gesturecast.settings import SINGLE_STYLE  # γ = 1 is style 1 alone: no second-style row needed

NO_GUIDANCE = 1.0  # s = 1 is the conditional prediction alone: no null-style row needed


@dataclass(frozen=True)
class RowLayout:
    """The rows of one batched denoiser call: style embeddings (B, S), style_present (B,), hears_audio (B,)
    (0 on the audio-null rows) and the mixture's prompt (= trajectory) count R."""

    styles: np.ndarray
    style_present: np.ndarray
    hears_audio: np.ndarray
    mixture_rows: int
    has_second: bool
    has_null: bool
    has_audio_null: bool

    @property
    def batch(self) -> int:
        return int(self.styles.shape[0])

    @property
    def second_row(self) -> int:
        return self.mixture_rows

    @property
    def null_rows(self) -> slice:
        """The R null-style rows (one per trajectory)."""
        start = self.mixture_rows + int(self.has_second)
        return slice(start, start + self.mixture_rows)

    @property
    def audio_null_rows(self) -> slice:
        """The R rows of the prompts without the audio."""
        start = self.mixture_rows + int(self.has_second) + self.mixture_rows * int(self.has_null)
        return slice(start, start + self.mixture_rows)

    @cached_property
    def row_trajectory(self) -> np.ndarray:
        """(B,) the trajectory whose x_t and history each row sees."""
        trajectories = np.arange(self.mixture_rows)
        second = [0] if self.has_second else []
        repeats = int(self.has_null) + int(self.has_audio_null)
        return np.concatenate([trajectories, second, *([trajectories] * repeats)]).astype(np.int64)

    def same_rows(self, other: RowLayout) -> bool:
        return (self.mixture_rows, self.has_second, self.has_null, self.has_audio_null) == (
            other.mixture_rows, other.has_second, other.has_null, other.has_audio_null)


def row_layout(mixture: np.ndarray, second: np.ndarray | None, gamma: float, guidance: float,
               audio_guidance: float = NO_GUIDANCE) -> RowLayout:
    """Rows for the mixture's style embeddings (R, S) (or one (S,) style), c2, and the guidance settings."""
    mixture = np.atleast_2d(np.asarray(mixture, np.float32))  # (R, S)
    has_second = second is not None and gamma != SINGLE_STYLE
    has_null = guidance != NO_GUIDANCE
    has_audio_null = audio_guidance != NO_GUIDANCE
    count = len(mixture)
    nulls = [np.zeros_like(mixture[0])] * count if has_null else []
    rows = list(mixture) + ([second] if has_second else []) + nulls
    present = [1.0] * (count + int(has_second)) + [0.0] * len(nulls)
    hears = [1.0] * len(rows)
    if has_audio_null:
        rows, present, hears = rows + list(mixture), present + [1.0] * count, hears + [0.0] * count
    return RowLayout(np.stack(rows).astype(np.float32), np.asarray(present, np.float32),
                     np.asarray(hears, np.float32), len(mixture), has_second, has_null, has_audio_null)


def single_style_weights(latent_dim: int) -> np.ndarray:
    """W (1, C) of one style: every channel from row 0."""
    return np.ones((1, latent_dim), np.float32)


def guide_trajectories(x0_rows: np.ndarray, layout: RowLayout, gamma: float, guidance: float,
                       audio_guidance: float = NO_GUIDANCE) -> np.ndarray:
    """(B, C) per-row x0 predictions → the guided prediction of every trajectory (R, C) (module docstring)."""
    x0 = x0_rows.astype(np.float64)
    guided = x0[: layout.mixture_rows].copy()  # (R, C)
    if layout.has_second:
        guided[0] = style_interpolation(guided[0], x0[layout.second_row], gamma)
    if layout.has_null:
        guided = classifier_free_guidance(x0[layout.null_rows], guided, guidance)
    if layout.has_audio_null:
        guided = guided + (audio_guidance - NO_GUIDANCE) * (x0[: layout.mixture_rows] - x0[layout.audio_null_rows])
    return guided


def fuse_trajectories(trajectories: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """z = Σ_r W_r ⊙ z_r: trajectories (R, C), W (R, C) → (C,)."""
    return np.einsum("rc,rc->c", weights, trajectories)


def part_mixture(base: StylePrompt, part_styles: dict[str, StylePrompt], part_channels: dict[str, slice],
                 latent_dim: int) -> tuple[list[StylePrompt], np.ndarray]:
    """The mixture of a base style and per-part prompts: prompts (R, base first, each once) and W (R, C) whose
    row of a part's prompt is 1 on that part's channels; parts not named follow the base style."""
    unknown = sorted(set(part_styles) - set(part_channels))
    if unknown:
        raise UserError(f"unknown body part {unknown[0]!r}; this model's parts: {', '.join(part_channels)}")
    prompts = [base] + list(dict.fromkeys(p for p in part_styles.values() if p != base))
    weights = np.zeros((len(prompts), latent_dim), np.float32)
    weights[0] = 1.0
    for part, prompt in part_styles.items():
        channels = part_channels[part]
        weights[:, channels] = 0.0
        weights[prompts.index(prompt), channels] = 1.0
    return prompts, weights


def align_mixtures(old_prompts: list[StylePrompt], old_weights: np.ndarray, new_prompts: list[StylePrompt],
                   new_weights: np.ndarray) -> tuple[list[StylePrompt], np.ndarray, np.ndarray]:
    """Both mixtures over the union of their prompts (old order first): (prompts, old W, new W), each (R∪, C),
    so a ramp can move W from one to the other."""
    union = list(dict.fromkeys([*old_prompts, *new_prompts]))

    def spread(prompts: list[StylePrompt], weights: np.ndarray) -> np.ndarray:
        spread_weights = np.zeros((len(union), weights.shape[1]), np.float32)
        for prompt, row in zip(prompts, weights, strict=True):
            spread_weights[union.index(prompt)] += row
        return spread_weights

    return union, spread(old_prompts, old_weights), spread(new_prompts, new_weights)


def drop_unused_rows(prompts: list[StylePrompt], weights: np.ndarray,
                     base: StylePrompt) -> tuple[list[StylePrompt], np.ndarray]:
    """The mixture without prompts of zero weight, the base style first (it stays even when every part is named:
    audio guidance uses its row)."""
    base_row = prompts.index(base)
    keep = [base_row] + [row for row in range(len(prompts)) if row != base_row and weights[row].any()]
    return [prompts[row] for row in keep], weights[keep]


def bound_blend_rows(prompts: list[StylePrompt], start: np.ndarray, target: np.ndarray,
                     max_rows: int) -> tuple[list[StylePrompt], np.ndarray, np.ndarray]:
    """A blend's rows (prompts R, W start and target, each (R, C)) cut to at most ``max_rows`` (never fewer than row
    0 and the target's rows): rows of zero weight at both ends go, then the old rows of least weight, whose share of
    each channel moves to the row the target gives that channel (those channels jump part of the way: a bounded
    cost that only controls arriving faster than the fade pay). Both W stay partitions of every channel."""
    used = start.any(axis=1) | target.any(axis=1)  # (R,)
    used[0] = True
    keep = list(np.flatnonzero(used))
    fading = sorted((row for row in keep if row != 0 and not target[row].any()), key=lambda row: start[row].sum())
    dropped = fading[: max(0, len(keep) - max_rows)]
    start = start.copy()
    owner = target.argmax(axis=0)  # (C,) the target's row of each channel (W target is 0/1 per channel)
    for row in dropped:
        np.add.at(start, (owner, np.arange(start.shape[1])), start[row])
    keep = [row for row in keep if row not in dropped]
    return [prompts[row] for row in keep], start[keep], target[keep]
