"""Diffusion math: noise schedules, forward noising, DDPM and DDIM steps, guidance (numpy, float64 schedules).

Habits from diffusers / improved-diffusion: the scheduler never calls the model, the caller owns the
loop; a named schedule is never changed once committed (add a new name instead).

Timesteps are 0-based indices ``t = 0 .. T-1`` as in improved-diffusion: index ``t`` is the paper's
step ``t + 1``; ``alphas_cumprod[t]`` is ᾱ_{t+1}. The index ``-1`` stands for "clean data"
(ᾱ = 1) and is the ``t_prev`` of the last sampling step.

Every step function only multiplies arrays by Python floats and adds them, so it works unchanged on
numpy arrays of any shape (the live runtime, no torch) and on torch tensors (training).
:func:`q_sample` also accepts per-element timesteps (one per batch item or per frame, as in
diffusion forcing) given as numpy or torch integer arrays.

Typical loop (the caller owns the model)::

    schedule = get_schedule("cosine_1000")
    x = rng.standard_normal(shape)
    for t, t_prev in sampling_plan(schedule.num_timesteps, sampler):
        x0 = model(x, t)
        x = sampler_step(schedule, sampler, x0, t, t_prev, x, noise=rng.standard_normal(shape))
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

import numpy as np

COSINE_OFFSET_S = 0.008  # Nichol & Dhariwal 2021, eq. 17: small offset s keeping β_1 from being tiny
MAX_BETA = 0.999  # Nichol & Dhariwal 2021, §3.2: β clipped to avoid singularities at t = T
DEFAULT_NUM_TIMESTEPS = 1000
DEFAULT_SCHEDULE = "cosine_1000"
DEFAULT_DDIM_STEPS = 4  # DDIM K of a preset that names none, and of a bundle whose model.json names none
CLEAN_TIMESTEP = -1  # the "t_prev" of the last step: ᾱ = 1, the sample is the data itself
MAX_DDIM_STEPS = 50
SAMPLER_KINDS = ("ddim", "ddpm")

Array = Any  # numpy.ndarray or torch.Tensor: the step functions only use * and + with floats


def cosine_alpha_bar(t_fraction: np.ndarray, s: float = COSINE_OFFSET_S) -> np.ndarray:
    """ᾱ(t/T) = f(t)/f(0), f(t) = cos²(((t/T + s)/(1 + s))·π/2) — Nichol & Dhariwal 2021, eq. 17."""
    f = np.cos((np.asarray(t_fraction, dtype=np.float64) + s) / (1.0 + s) * math.pi / 2.0) ** 2
    f0 = math.cos(s / (1.0 + s) * math.pi / 2.0) ** 2
    return f / f0


def cosine_betas(num_timesteps: int = DEFAULT_NUM_TIMESTEPS, max_beta: float = MAX_BETA) -> np.ndarray:
    """β_t = min(1 − ᾱ_t/ᾱ_{t−1}, max_beta) for the cosine schedule (Nichol & Dhariwal 2021, §3.2). (T,) float64."""
    fractions = np.arange(num_timesteps + 1, dtype=np.float64) / num_timesteps
    alpha_bar = cosine_alpha_bar(fractions)
    return np.minimum(1.0 - alpha_bar[1:] / alpha_bar[:-1], max_beta)


@dataclass(frozen=True)
class DiffusionSchedule:
    """A noise schedule and the float64 quantities derived from it (DDPM notation, Ho et al. 2020)."""

    name: str
    betas: np.ndarray  # (T,) β_t
    alphas_cumprod: np.ndarray  # (T,) ᾱ_t = Π_{s≤t} (1 − β_s)

    @classmethod
    def from_betas(cls, name: str, betas: np.ndarray) -> DiffusionSchedule:
        betas = np.asarray(betas, dtype=np.float64)
        if betas.ndim != 1 or np.any(betas <= 0.0) or np.any(betas >= 1.0):
            raise ValueError("betas must be a 1-D array with values in (0, 1)")
        return cls(name=name, betas=betas, alphas_cumprod=np.cumprod(1.0 - betas))

    @property
    def num_timesteps(self) -> int:
        return int(self.betas.shape[0])

    def alpha_bar(self, t: int) -> float:
        """ᾱ at index t, with ᾱ = 1 for :data:`CLEAN_TIMESTEP`."""
        if t == CLEAN_TIMESTEP:
            return 1.0
        if not 0 <= t < self.num_timesteps:
            raise ValueError(f"timestep {t} outside 0..{self.num_timesteps - 1}")
        return float(self.alphas_cumprod[t])


# Never change an entry once committed: trained models refer to schedules by name.
SCHEDULES: Mapping[str, Callable[[], np.ndarray]] = MappingProxyType(
    {
        "cosine_1000": lambda: cosine_betas(1000),
    }
)


def get_schedule(name: str = DEFAULT_SCHEDULE) -> DiffusionSchedule:
    """The named schedule from :data:`SCHEDULES`."""
    if name not in SCHEDULES:
        raise KeyError(f"unknown schedule {name!r}; known: {sorted(SCHEDULES)}")
    return DiffusionSchedule.from_betas(name, SCHEDULES[name]())


def respace_timesteps(num_timesteps: int, steps: int) -> np.ndarray:
    """K evenly spaced timesteps ending at T−1, ascending. (K,) int64.

    Rule: t_k = round((k + 1)·T/K) − 1 for k = 0..K−1 (ties round half to even). The spacing is
    T/K ≥ 1, so the steps are strictly increasing and unique; t_{K−1} = T − 1 (sampling always
    starts from pure noise); K = T gives every step. Each step's ``t_prev`` is the one before it,
    and :data:`CLEAN_TIMESTEP` for the first.
    """
    if not 1 <= steps <= num_timesteps:
        raise ValueError(f"steps must be in 1..{num_timesteps}, got {steps}")
    k = np.arange(1, steps + 1, dtype=np.float64)
    return np.round(k * num_timesteps / steps).astype(np.int64) - 1


@dataclass(frozen=True)
class SamplerConfig:
    """Which sampler to run: "ddim" (Song et al. 2021) with K steps and η, or "ddpm" (Ho et al. 2020).

    DDPM with ``steps = T`` is the original ancestral sampler; fewer steps respace it (Nichol &
    Dhariwal 2021, §4). ``eta`` is used by DDIM only (η = 0 deterministic, η = 1 DDPM-like noise).
    """

    kind: str = "ddim"
    steps: int = 8
    eta: float = 0.0

    def __post_init__(self) -> None:
        if self.kind not in SAMPLER_KINDS:
            raise ValueError(f"sampler kind must be one of {SAMPLER_KINDS}, got {self.kind!r}")
        if self.kind == "ddim" and not 1 <= self.steps <= MAX_DDIM_STEPS:
            raise ValueError(f"DDIM steps must be in 1..{MAX_DDIM_STEPS}, got {self.steps}")
        if self.steps < 1:
            raise ValueError(f"steps must be at least 1, got {self.steps}")
        if self.eta < 0.0:
            raise ValueError(f"eta must be non-negative, got {self.eta}")


def sampling_plan(num_timesteps: int, sampler: SamplerConfig) -> list[tuple[int, int]]:
    """The (t, t_prev) pairs a sampling loop visits, from t = T−1 down to t_prev = CLEAN_TIMESTEP."""
    ascending = respace_timesteps(num_timesteps, sampler.steps).tolist()
    previous = [CLEAN_TIMESTEP, *ascending[:-1]]
    return list(zip(reversed(ascending), reversed(previous), strict=True))


def _gather(values: np.ndarray, t: Any, like: Array) -> Array:
    """values[t] shaped to broadcast against ``like`` (t: int, or an int array of leading dims of like)."""
    index = t.detach().cpu().numpy() if hasattr(t, "detach") else np.asarray(t)
    picked = values[index]  # t.shape
    picked = picked.reshape(picked.shape + (1,) * (like.ndim - picked.ndim))
    if hasattr(like, "new_tensor"):  # torch: same dtype and device as the sample
        return like.new_tensor(picked)
    return picked.astype(like.dtype, copy=False) if np.issubdtype(like.dtype, np.floating) else picked


def q_sample(schedule: DiffusionSchedule, x0: Array, t: Any, noise: Array) -> Array:
    """x_t = √ᾱ_t · x0 + √(1 − ᾱ_t) · ε — Ho et al. 2020, eq. 4.

    ``t`` is an int or an integer array (numpy or torch) whose shape is a prefix of ``x0.shape``
    (one timestep per batch item, or per frame for diffusion forcing).
    """
    sqrt_alpha_bar = _gather(np.sqrt(schedule.alphas_cumprod), t, x0)
    sqrt_one_minus = _gather(np.sqrt(1.0 - schedule.alphas_cumprod), t, x0)
    return sqrt_alpha_bar * x0 + sqrt_one_minus * noise


def predict_noise_from_x0(schedule: DiffusionSchedule, x0: Array, t: int, sample: Array) -> Array:
    """ε = (x_t − √ᾱ_t · x0) / √(1 − ᾱ_t), eq. 4 solved for ε (needs t ≥ 0)."""
    alpha_bar = schedule.alpha_bar(t)
    return (sample - math.sqrt(alpha_bar) * x0) * (1.0 / math.sqrt(1.0 - alpha_bar))


def ddpm_posterior(schedule: DiffusionSchedule, x0: Array, t: int, t_prev: int, sample: Array) -> tuple[Array, float]:
    """Mean and variance of q(x_{t_prev} | x_t, x0) — Ho et al. 2020, eq. 6–7.

    μ̃ = √ᾱ_prev·β_t/(1 − ᾱ_t) · x0 + √α_t·(1 − ᾱ_prev)/(1 − ᾱ_t) · x_t,
    β̃ = (1 − ᾱ_prev)/(1 − ᾱ_t) · β_t, with α_t = ᾱ_t/ᾱ_prev and β_t = 1 − α_t, which is the
    paper's formula for t_prev = t − 1 and its respaced form (Nichol & Dhariwal 2021, §4) otherwise.
    """
    alpha_bar, alpha_bar_prev = schedule.alpha_bar(t), schedule.alpha_bar(t_prev)
    alpha = alpha_bar / alpha_bar_prev
    beta = 1.0 - alpha
    mean = (math.sqrt(alpha_bar_prev) * beta / (1.0 - alpha_bar)) * x0 + (
        math.sqrt(alpha) * (1.0 - alpha_bar_prev) / (1.0 - alpha_bar)
    ) * sample
    variance = (1.0 - alpha_bar_prev) / (1.0 - alpha_bar) * beta
    return mean, variance


def ddpm_step(
    schedule: DiffusionSchedule, x0: Array, t: int, t_prev: int, sample: Array, noise: Array | None = None
) -> Array:
    """Ancestral step x_{t_prev} = μ̃ + √β̃ · z given the model's x0 prediction (Ho et al. 2020, Alg. 2).

    ``noise`` (z ~ N(0, I), same shape as the sample) is needed unless t_prev is the clean step.
    """
    mean, variance = ddpm_posterior(schedule, x0, t, t_prev, sample)
    if variance == 0.0:
        return mean
    if noise is None:
        raise ValueError("ddpm_step needs noise for every step but the last")
    return mean + math.sqrt(variance) * noise


def ddim_sigma(schedule: DiffusionSchedule, t: int, t_prev: int, eta: float) -> float:
    """σ = η·√((1 − ᾱ_prev)/(1 − ᾱ_t))·√(1 − ᾱ_t/ᾱ_prev) — Song et al. 2021, eq. 16."""
    alpha_bar, alpha_bar_prev = schedule.alpha_bar(t), schedule.alpha_bar(t_prev)
    return eta * math.sqrt((1.0 - alpha_bar_prev) / (1.0 - alpha_bar)) * math.sqrt(1.0 - alpha_bar / alpha_bar_prev)


def ddim_step(
    schedule: DiffusionSchedule,
    x0: Array,
    t: int,
    t_prev: int,
    sample: Array,
    eta: float = 0.0,
    noise: Array | None = None,
) -> Array:
    """x_{t_prev} = √ᾱ_prev·x0 + √(1 − ᾱ_prev − σ²)·ε̂ + σ·z — Song et al. 2021, eq. 12.

    ε̂ is implied by the x0 prediction; at t_prev = CLEAN_TIMESTEP this returns x0 exactly.
    """
    alpha_bar_prev = schedule.alpha_bar(t_prev)
    sigma = ddim_sigma(schedule, t, t_prev, eta)
    eps = predict_noise_from_x0(schedule, x0, t, sample)
    direction = math.sqrt(max(1.0 - alpha_bar_prev - sigma**2, 0.0))
    prev = math.sqrt(alpha_bar_prev) * x0 + direction * eps
    if sigma == 0.0:
        return prev
    if noise is None:
        raise ValueError("ddim_step with eta > 0 needs noise for every step but the last")
    return prev + sigma * noise


def sampler_step(
    schedule: DiffusionSchedule,
    sampler: SamplerConfig,
    x0: Array,
    t: int,
    t_prev: int,
    sample: Array,
    noise: Array | None = None,
) -> Array:
    """One step of the configured sampler given the model's x0 prediction."""
    if sampler.kind == "ddpm":
        return ddpm_step(schedule, x0, t, t_prev, sample, noise)
    return ddim_step(schedule, x0, t, t_prev, sample, sampler.eta, noise)


def classifier_free_guidance(x0_uncond: Array, x0_cond: Array, scale: float) -> Array:
    """x̂0 = x0_uncond + s·(x0_cond − x0_uncond) — Ho & Salimans 2022, eq. 6, on x0 predictions.

    s = 1 is the conditional prediction, s = 0 the unconditional one, s > 1 strengthens the condition.
    """
    return x0_uncond + scale * (x0_cond - x0_uncond)


def style_interpolation(x0_style_a: Array, x0_style_b: Array, gamma: float) -> Array:
    """x̂0 = γ·D(c1) + (1 − γ)·D(c2) — DiffuseStyleGesture (Yang et al. 2023), style control.

    0 < γ < 1 interpolates between the styles c1 and c2, γ > 1 extrapolates past c1 away from c2.
    """
    return gamma * x0_style_a + (1.0 - gamma) * x0_style_b
