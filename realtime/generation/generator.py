"""The live gesture generator: one latent frame (d motion frames) per :meth:`Generator.step`.

numpy + onnxruntime only (no torch). Per step (GestureDiffuCLIP §3.2, run autoregressively):

1. draw x_T ~ N(0, I) for the new latent from the generator's own seeded RNG, and compute the
   rows' condition (audio-window token + style modulations) once — it is the same at every step;
2. run the sampler (K-step DDIM, or the 1000-step DDPM path) — each step is ONE batched denoiser
   call whose rows are [style 1 and one row per other body-part prompt, style 2 (only with γ), the null
   style (only with guidance s ≠ 1), the prompts without the audio (only with audio guidance s_a ≠ 1)],
   every prompt its own trajectory (its own x_t and clean history in its rows' KV caches); the rows are
   combined per trajectory by :mod:`gesturecast.realtime.generation.style_mixture`: x̂0 = γ·x̂0 + (1 − γ)·D(c2)
   (DiffuseStyleGesture), classifier-free guidance (Ho & Salimans 2022 eq. 6) and audio guidance;
3. commit each trajectory's clean latent to its rows' history (folded into the next denoiser call), fuse the
   trajectories by body part (GestureDiffuCLIP §6.3, z = Σ_o z_o · M_o) and decode the result with the
   streaming VQ decoder into d motion-feature frames (denormalised, canonical layout).

The generator keeps no audio handling and no timing: the caller passes normalised audio windows
(:meth:`ModelBundle.audio_stats`) laid out as :attr:`Generator.audio_config` says (the model's (A, F)
windows, or at a shorter look-ahead δ of a truncation model the (A − δa + δ, F) part it may hear) and
owns the clock.
"""

from __future__ import annotations

import logging
from collections import deque
from dataclasses import dataclass, field, replace

import numpy as np

from gesturecast.errors import UserError
from gesturecast.models.generator.denoiser_config import (
    DenoiserConfig,
    pad_visible_window,
    supported_lookaheads,
    visible_config,
)
from gesturecast.models.generator.diffusion import (
    CLEAN_TIMESTEP,
    SamplerConfig,
    get_schedule,
    sampler_step,
    sampling_plan,
)
from gesturecast.models.generator.style_prompt import PartStyles, StylePrompt
from gesturecast.models.runtime.bundle import ModelBundle
from gesturecast.models.runtime.denoiser_runtime import FrameInputs, roll_cache
from gesturecast.models.runtime.ort_session import DEFAULT_THREADS
from gesturecast.realtime.generation.degradation import RUNGS, Rung
from gesturecast.realtime.generation.style_mixture import (
    NO_GUIDANCE,
    RowLayout,
    fuse_trajectories,
    guide_trajectories,
    part_mixture,
    row_layout,
)
from gesturecast.realtime.generation.style_prompts import StyleResolver
from gesturecast.settings import DEFAULT_STYLE_STRENGTH, SINGLE_STYLE

logger = logging.getLogger(__name__)

NEUTRAL_STYLE = StylePrompt("label", "neutral")


@dataclass(frozen=True)
class GeneratorSettings:
    sampler: SamplerConfig = field(default_factory=lambda: SamplerConfig("ddim", 4))
    guidance: float | None = None  # s before the style strength; None = the bundle's default guidance scale
    style: StylePrompt = NEUTRAL_STYLE  # what the denoiser hears (realtime/pose/style_hearing.py decides it)
    second_style: StylePrompt | None = None  # c2 of x̂0 = γ·D(c1) + (1 − γ)·D(c2)
    gamma: float = SINGLE_STYLE
    seed: int = 0
    threads: int = DEFAULT_THREADS
    audio_guidance: float = NO_GUIDANCE  # s_a: > 1 strengthens the speech's pull on the motion (extra row)
    lookahead: int | None = None  # δ: audio look-ahead frames heard (None = the model's δa; docs/latency.md)
    part_styles: PartStyles = ()  # (body part, prompt) pairs; parts not named follow ``style``
    style_strength: float = DEFAULT_STYLE_STRENGTH  # k: the sampler's guidance is k·s (0: the null style's motion)


@dataclass(frozen=True)
class PreparedConditions:
    """Conditions computed ahead by :meth:`Generator.prepare`, valid for the layout and audio flag they were made
    with, each paired with its padded (A, F) window and used in order."""

    layout: object = None  # the generator's layout at prepare time
    audio_present: bool = True
    pending: deque = field(default_factory=deque)  # (window (A, F), condition (B, Dc)) pairs


@dataclass(frozen=True)
class HistoryFrame:
    """A committed clean latent (normalised, the fusion of the parts), the conditions it was committed with, and
    each prompt's own clean latent (its trajectory; empty for seed-gesture frames)."""

    latent: np.ndarray  # (C,)
    window: np.ndarray  # (A, F)
    audio_present: float
    by_prompt: dict[StylePrompt, np.ndarray] = field(default_factory=dict)  # prompt → (C,)

    def latent_of(self, prompt: StylePrompt) -> np.ndarray:
        """(C,) the history a trajectory of ``prompt`` sees: its own latent, else the fused one (a new prompt
        starts from the body as it is)."""
        return self.by_prompt.get(prompt, self.latent)


def check_lookahead(config: DenoiserConfig, lookahead: int) -> None:
    """One-line UserError unless the model serves look-ahead ``lookahead``."""
    supported = supported_lookaheads(config)
    if lookahead in supported:
        return
    if not config.lookahead_truncation:
        raise UserError(f"this model serves only look-ahead δa = {config.audio_lookahead} frames (--latency "
                        f"quality), not {lookahead}: it was trained without look-ahead truncation; train one with "
                        "`gesturecast train --lookahead-truncation` and pass it with --model")
    raise UserError(f"look-ahead {lookahead} frames is past this model's δa = {config.audio_lookahead} "
                    f"(it serves 0..{config.audio_lookahead})")


class Generator:
    """Seeded, stateful latent-by-latent motion generator over a :class:`ModelBundle`."""

    def __init__(self, bundle: ModelBundle, settings: GeneratorSettings | None = None):
        self.bundle = bundle
        self.settings = settings or GeneratorSettings()
        self.config = bundle.denoiser_config
        self.lookahead = self.config.audio_lookahead if self.settings.lookahead is None else self.settings.lookahead
        check_lookahead(self.config, self.lookahead)
        self.audio_config = visible_config(self.config, self.lookahead)  # the audio layout the caller feeds
        self.schedule = get_schedule(bundle.schedule_name)
        self.denoiser = bundle.denoiser(self.settings.threads)
        self.decoder = bundle.vq_decoder(self.settings.threads)
        self.styles = StyleResolver(bundle, self.settings.threads)
        self.history: deque[HistoryFrame] = deque(maxlen=self.config.window)
        second = self.settings.second_style
        self._second = None if second is None else self.styles.embed(second)
        self._set_mixture_values(*self.part_mixture(self.settings.style, self.settings.part_styles))
        self.rung = RUNGS[0]  # the degradation ladder's: the work as asked
        self._plan = self._sampling_plan()
        self.layout = self._make_layout()
        self._prepared = PreparedConditions()
        self.reset(self.settings.seed)

    @property
    def base_guidance(self) -> float:
        """s as asked for (the bundle's default unless set), before the style strength."""
        return self.bundle.default_guidance if self.settings.guidance is None else float(self.settings.guidance)

    @property
    def guidance(self) -> float:
        """The sampler's classifier-free guidance scale: style strength k times s."""
        return self.settings.style_strength * self.base_guidance

    @property
    def style_embedding(self) -> np.ndarray:
        """(S,) embedding of style c1 (the base style of a part mixture)."""
        return self._mixture_embeddings[0]

    @property
    def mixture(self) -> tuple[list[StylePrompt], np.ndarray]:
        """The style rows' prompts (R) and their latent-channel weights W (R, C) (style_mixture.py)."""
        return list(self._mixture_prompts), self._weights.copy()

    @property
    def second_style_embedding(self) -> np.ndarray | None:
        """(S,) embedding of style c2 (γ mixing), or None."""
        return self._second

    @property
    def latent_dim(self) -> int:
        return self.config.latent_dim

    def _make_layout(self) -> RowLayout:
        return row_layout(self._mixture_embeddings, self._second, self.settings.gamma, self.guidance,
                          self.audio_guidance)

    def part_mixture(self, style: StylePrompt, part_styles: PartStyles) -> tuple[list[StylePrompt], np.ndarray]:
        """The mixture (prompts, W) of a base style and per-part prompts for this model's body parts; UserError
        for a part the model does not have."""
        return part_mixture(style, dict(part_styles), self.bundle.part_channels, self.latent_dim)

    def _set_mixture_values(self, prompts: list[StylePrompt], weights: np.ndarray) -> None:
        self._mixture_embeddings = np.stack([self.styles.embed(prompt) for prompt in prompts])  # (R, S)
        self._mixture_prompts = list(prompts)
        self._weights = np.asarray(weights, np.float32)  # (R, C)

    def reset(self, seed: int | None = None, seed_pose: np.ndarray | None = None) -> None:
        """Start a new stream: fresh RNG (``seed``, default the settings' seed), empty history and decoder
        state; ``seed_pose`` (T, D) denormalised motion features pre-fills the history (seed gesture)."""
        self.rng = np.random.default_rng(self.settings.seed if seed is None else seed)
        self.history.clear()
        self.decoder.reset()
        if seed_pose is not None:
            self._prefill(seed_pose)
        self._rebuild_cache()

    def _prefill(self, seed_pose: np.ndarray) -> None:
        d = self.bundle.frames_per_latent
        usable = len(seed_pose) - len(seed_pose) % d
        if usable == 0:
            raise UserError(f"a seed gesture needs at least {d} frames, got {len(seed_pose)}")
        normalized = self.bundle.motion_stats.normalize(np.asarray(seed_pose[-usable:], np.float32))  # (T', D)
        latents = self.bundle.vq_encoder(self.settings.threads).encode(normalized)  # (N, C)
        silent = np.zeros((self.config.audio_window, self.config.audio_dim), np.float32)  # (A, F)
        for latent in latents:
            self.decoder.step(latent)  # advance the decoder state through the seed gesture
            self.history.append(HistoryFrame(self.bundle.latent_stats.normalize(latent), silent, 0.0))

    def _rebuild_cache(self) -> None:
        """KV caches of every row recomputed from the history (one chunked call; empty history = empty cache)."""
        batch = self.layout.batch
        self.denoiser.reset(batch)
        if not self.history:
            return
        length = len(self.history)
        trajectories = [self._mixture_prompts[index] for index in self.layout.row_trajectory]  # (B,)
        latents = np.stack([[h.latent_of(prompt) for h in self.history] for prompt in trajectories])  # (B, M, C)
        condition = self.denoiser.condition(
            np.broadcast_to(np.stack([h.window for h in self.history]), (batch, length, *self.history[0].window.shape)),
            self.layout.hears_audio[:, None] * np.array([h.audio_present for h in self.history], np.float32),  # (B, M)
            np.repeat(self.layout.styles[:, None], length, axis=1),  # (B, M, S)
            np.repeat(self.layout.style_present[:, None], length, axis=1),  # (B, M)
            self.lookahead,
        )  # (B, M, Dc)
        frames = FrameInputs(
            latents.astype(np.float32),
            np.full((batch, length), CLEAN_TIMESTEP, np.int64),
            condition,
        )
        _, keys, values = self.denoiser.run(frames, self.denoiser.state)
        self.denoiser.state = roll_cache(self.denoiser.state, keys, values)

    def _apply_layout(self) -> None:
        new_layout = self._make_layout()
        rows_changed = not new_layout.same_rows(self.layout)
        self.layout = new_layout
        if rows_changed:
            self._rebuild_cache()

    def set_style(self, style: StylePrompt, second_style: StylePrompt | None = None, gamma: float = SINGLE_STYLE,
                  strength: float | None = None):
        """Change the (base) style, and the style strength k unless None, from the next latent on (history keeps the
        style it was made with); named part styles stay."""
        self._second = None if second_style is None else self.styles.embed(second_style)
        strength = self.settings.style_strength if strength is None else strength
        self.settings = replace(self.settings, style=style, second_style=second_style, gamma=gamma,
                                style_strength=strength)
        self._set_mixture_values(*self.part_mixture(style, self.settings.part_styles))
        self._apply_layout()

    def set_mixture_weights(self, weights: np.ndarray) -> None:
        """New channel weights W (R, C) for the same style rows (a ramp step; no re-embedding, no cache change)."""
        self._weights = np.asarray(weights, np.float32)

    def set_part_styles(self, part_styles: PartStyles) -> None:
        """Give body parts their own prompts from the next latent on (no parts: one style again)."""
        self.settings = replace(self.settings, part_styles=tuple(part_styles))
        self.set_mixture(*self.part_mixture(self.settings.style, part_styles))

    def set_mixture(self, prompts: list[StylePrompt], weights: np.ndarray) -> None:
        """Use these style rows (R prompts, the base style first) with latent-channel weights W (R, C); a ramp
        of W between two mixtures blends a part-style change in (realtime/pose/session_controls.py)."""
        self._set_mixture_values(prompts, weights)
        self._apply_layout()

    def blend_part_styles(self, prompts: list[StylePrompt], weights: np.ndarray, style: StylePrompt,
                          part_styles: PartStyles, strength: float | None = None) -> None:
        """A part-style blend starts: the mixture rows ``prompts`` (R) with ``weights`` (R, C) now, toward ``style``
        and ``part_styles`` (and the style strength k unless None), the styles heard from the next layout on."""
        self.set_mixture(prompts, weights)
        strength = self.settings.style_strength if strength is None else strength
        self.settings = replace(self.settings, style=style, part_styles=tuple(part_styles), style_strength=strength)

    def set_gamma(self, gamma: float) -> None:
        """Move γ of x̂0 = γ·D(c1) + (1 − γ)·D(c2) without re-embedding the styles (used by smooth changes)."""
        self.settings = replace(self.settings, gamma=gamma)
        self._apply_layout()

    def set_guidance(self, scale: float) -> None:
        """s before the style strength."""
        self.settings = replace(self.settings, guidance=scale)
        self._apply_layout()

    def set_style_strength(self, strength: float) -> None:
        """k of the sampler's guidance k·s: 0 is the null style's motion, 1 the default, 2 twice the style's pull."""
        self.settings = replace(self.settings, style_strength=strength)
        self._apply_layout()

    def set_audio_guidance(self, scale: float) -> None:
        """s_a of x̂0 += (s_a − 1)·(D(c1) − D(c1, ∅a)); 1 drops the audio-null row."""
        self.settings = replace(self.settings, audio_guidance=scale)
        self._apply_layout()

    def set_sampler(self, sampler: SamplerConfig) -> None:
        self.settings = replace(self.settings, sampler=sampler)
        self._plan = self._sampling_plan()

    @property
    def audio_guidance(self) -> float:
        """s_a in use: as set, or 1 (no audio-null row) on a rung that drops it."""
        return self.settings.audio_guidance if self.rung.audio_guidance else NO_GUIDANCE

    def degrade(self, rung: Rung) -> None:
        """Do the work of ``rung`` from the next latent on (the settings, history and caches stay; rung 0 is the
        work the settings ask for): :mod:`gesturecast.realtime.generation.degradation`."""
        self.rung = rung
        self._plan = self._sampling_plan()
        self._apply_layout()

    def _sampling_plan(self) -> list[tuple[int, int]]:
        sampler = self.settings.sampler
        if sampler.kind == "ddim" and self.rung.steps is not None:
            sampler = replace(sampler, steps=min(sampler.steps, self.rung.steps))
        return sampling_plan(self.schedule.num_timesteps, sampler)

    def _noise(self, t_prev: int) -> np.ndarray | None:
        sampler = self.settings.sampler
        stochastic = sampler.kind == "ddpm" or sampler.eta > 0.0
        return self.rng.standard_normal(self.latent_dim) if stochastic and t_prev != CLEAN_TIMESTEP else None

    def denoise(self, audio_window: np.ndarray, audio_present: bool,
                imposed: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
        """Sample the next clean latent (C,) (normalised) from its (A', F) window of :attr:`audio_config` and
        commit it to the history. ``imposed`` = (target (C,), weights (C,) in [0, 1]): at every sampler step the
        prediction is pulled to x̂0 + w·(target − x̂0), inpainting a gesture clip's part channels
        (:mod:`gesturecast.realtime.gestures.cues`)."""
        layout = self.layout
        audio_window = pad_visible_window(np.asarray(audio_window, np.float32), self.config)  # (A, F)
        condition = self._prepared_condition(audio_window, audio_present)
        if condition is None:
            condition = self._conditions(audio_window[None], audio_present)[0]  # (B, Dc)
        trajectory = layout.row_trajectory  # (B,)
        x = np.repeat(self.rng.standard_normal(self.latent_dim)[None], layout.mixture_rows, axis=0)  # (R, C) x_T
        for t, t_prev in self._plan:
            x0_rows = self.denoiser.step(x[trajectory], t, condition)  # (B, C)
            x0 = guide_trajectories(x0_rows, layout, self.settings.gamma, self.guidance,
                                    self.audio_guidance)  # (R, C)
            if imposed is not None:
                target, weights = imposed
                x0 = x0 + weights * (target - x0)  # (R, C)
            x = sampler_step(self.schedule, self.settings.sampler, x0, t, t_prev, x, self._noise(t_prev))
        self.denoiser.commit(x[trajectory], condition)
        latent = fuse_trajectories(x, self._weights).astype(np.float32)  # (C,)
        own = dict(zip(self._mixture_prompts, x.astype(np.float32), strict=True)) if layout.mixture_rows > 1 else {}
        self.history.append(HistoryFrame(latent, audio_window, float(audio_present), own))
        return latent

    def prepare(self, audio_windows: list[np.ndarray], audio_present: bool) -> None:
        """Compute the conditions of the next latents' (A', F) windows in one condition-graph call (the same numbers
        as one call per latent); :meth:`denoise` uses them while the style layout and the windows match."""
        padded = np.stack([pad_visible_window(np.asarray(window, np.float32), self.config)
                           for window in audio_windows])  # (n, A, F)
        conditions = self._conditions(padded, audio_present)  # (n, B, Dc)
        self._prepared = PreparedConditions(self.layout, audio_present, deque(zip(padded, conditions, strict=True)))

    def _conditions(self, windows: np.ndarray, audio_present: bool) -> np.ndarray:
        """(n, B, Dc) conditions of n padded windows (n, A, F) for every row of the layout."""
        layout, count = self.layout, len(windows)
        present = np.repeat((layout.hears_audio * float(audio_present))[:, None], count, axis=1)  # (B, n)
        styles = np.repeat(layout.styles[:, None], count, axis=1)  # (B, n, S)
        style_present = np.repeat(layout.style_present[:, None], count, axis=1)  # (B, n)
        windows = np.broadcast_to(windows, (layout.batch, *windows.shape))  # (B, n, A, F)
        return self.denoiser.condition(windows, present, styles, style_present, self.lookahead).transpose(1, 0, 2)

    def _prepared_condition(self, window: np.ndarray, audio_present: bool) -> np.ndarray | None:
        """The prepared (B, Dc) condition of this padded window (A, F), None when none matches."""
        prepared = self._prepared
        if not prepared.pending or prepared.layout is not self.layout or prepared.audio_present != audio_present:
            return None
        next_window, condition = prepared.pending.popleft()
        return condition if np.array_equal(next_window, window) else None

    def decode(self, latent: np.ndarray) -> np.ndarray:
        """A committed (C,) normalised latent → (d, D) denormalised motion features (streaming VQ decoder)."""
        features = self.decoder.step(self.bundle.latent_stats.denormalize(latent))  # (d, D) normalised
        return self.bundle.motion_stats.denormalize(features)

    def step(self, audio_window: np.ndarray, audio_present: bool = True) -> np.ndarray:
        """One latent frame: (A', F) normalised audio window (:attr:`audio_config`) → (d, D) denormalised motion
        features."""
        return self.decode(self.denoise(audio_window, audio_present))
