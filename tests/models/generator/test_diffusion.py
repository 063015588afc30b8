import math

import numpy as np
import pytest
import torch

from gesturecast.models.generator.diffusion import (
    CLEAN_TIMESTEP,
    MAX_BETA,
    MAX_DDIM_STEPS,
    SCHEDULES,
    SamplerConfig,
    classifier_free_guidance,
    ddim_step,
    ddpm_posterior,
    ddpm_step,
    get_schedule,
    q_sample,
    respace_timesteps,
    sampler_step,
    sampling_plan,
    style_interpolation,
)

T = 1000


@pytest.fixture(scope="module")
def schedule():
    return get_schedule("cosine_1000")


def test_alphas_cumprod_matches_cosine_closed_form(schedule):
    s = 0.008
    f = lambda t: math.cos((t / T + s) / (1 + s) * math.pi / 2) ** 2  # noqa: E731
    unclipped = schedule.betas < MAX_BETA
    expected = np.array([f(t + 1) / f(0) for t in range(T)])
    np.testing.assert_allclose(schedule.alphas_cumprod[unclipped], expected[unclipped], rtol=1e-10, atol=1e-15)
    assert unclipped.sum() >= T - 2  # clipping touches only the very end
    assert schedule.betas.max() == pytest.approx(MAX_BETA)
    assert schedule.alphas_cumprod.dtype == np.float64
    assert np.all(np.diff(schedule.alphas_cumprod) < 0)
    assert schedule.alphas_cumprod[0] > 0.9999 and schedule.alphas_cumprod[-1] < 1e-6


def test_named_schedules_are_frozen_and_unknown_names_fail():
    assert "cosine_1000" in SCHEDULES
    with pytest.raises(TypeError):
        SCHEDULES["other"] = SCHEDULES["cosine_1000"]
    with pytest.raises(KeyError):
        get_schedule("linear_7")


@pytest.mark.parametrize("steps", [*range(1, MAX_DDIM_STEPS + 1), 333, 999, 1000])
def test_respaced_timesteps_are_monotone_unique_and_end_at_last_step(steps):
    timesteps = respace_timesteps(T, steps)
    assert timesteps.shape == (steps,)
    assert np.all(np.diff(timesteps) > 0)
    assert timesteps[-1] == T - 1
    assert timesteps[0] >= 0
    gaps = np.diff(np.concatenate([[CLEAN_TIMESTEP], timesteps]))
    assert gaps.max() - gaps.min() <= 1  # evenly spaced up to rounding


def test_respace_all_steps_is_identity_and_bad_counts_fail():
    np.testing.assert_array_equal(respace_timesteps(T, T), np.arange(T))
    for bad in (0, T + 1):
        with pytest.raises(ValueError):
            respace_timesteps(T, bad)


def test_sampling_plan_walks_down_to_clean():
    plan = sampling_plan(T, SamplerConfig("ddim", steps=4))
    assert plan == [(999, 749), (749, 499), (499, 249), (249, CLEAN_TIMESTEP)]


@pytest.mark.parametrize("steps", range(1, MAX_DDIM_STEPS + 1))
@pytest.mark.parametrize("eta", [0.0, 1.0])
def test_ddim_with_oracle_x0_returns_x0_at_the_end(schedule, steps, eta):
    rng = np.random.default_rng(steps)
    x0 = rng.standard_normal((2, 3, 5))
    sampler = SamplerConfig("ddim", steps=steps, eta=eta)
    x = rng.standard_normal(x0.shape)
    for t, t_prev in sampling_plan(T, sampler):
        x = sampler_step(schedule, sampler, x0, t, t_prev, x, noise=rng.standard_normal(x0.shape))
    np.testing.assert_array_equal(x, x0)


def test_ddim_eta_zero_is_deterministic_and_preserves_noise_direction(schedule):
    rng = np.random.default_rng(0)
    x0, eps = rng.standard_normal((2, 16))
    t, t_prev = 800, 400
    xt = q_sample(schedule, x0, t, eps)
    expected = math.sqrt(schedule.alphas_cumprod[t_prev]) * x0 + math.sqrt(1 - schedule.alphas_cumprod[t_prev]) * eps
    np.testing.assert_allclose(ddim_step(schedule, x0, t, t_prev, xt), expected, atol=1e-12)


def test_ddim_eta_one_variance_equals_ddpm_posterior_variance(schedule):
    x0 = np.zeros(4)
    noise = np.ones(4)
    t, t_prev = 600, 599
    sample = np.zeros(4)
    _, variance = ddpm_posterior(schedule, x0, t, t_prev, sample)
    stepped = ddim_step(schedule, x0, t, t_prev, sample, eta=1.0, noise=noise)
    np.testing.assert_allclose(stepped, math.sqrt(variance) * noise, rtol=1e-12)


@pytest.mark.parametrize("t", [1, 10, 500, 998, 999])
def test_ddpm_posterior_matches_ho_et_al_eq_7(schedule, t):
    rng = np.random.default_rng(t)
    x0, xt = rng.standard_normal((2, 8))
    betas, alpha_bar = schedule.betas, schedule.alphas_cumprod
    beta_t, alpha_t = betas[t], 1 - betas[t]
    coef_x0 = math.sqrt(alpha_bar[t - 1]) * beta_t / (1 - alpha_bar[t])
    coef_xt = math.sqrt(alpha_t) * (1 - alpha_bar[t - 1]) / (1 - alpha_bar[t])
    mean, variance = ddpm_posterior(schedule, x0, t, t - 1, xt)
    np.testing.assert_allclose(mean, coef_x0 * x0 + coef_xt * xt, rtol=1e-9, atol=1e-12)
    assert variance == pytest.approx((1 - alpha_bar[t - 1]) / (1 - alpha_bar[t]) * beta_t, rel=1e-9)


def test_ddpm_posterior_is_the_conditional_of_the_joint_gaussian(schedule):
    """Monte-Carlo-free check: E[x_{t-1} | x_t, x0] from the joint Gaussian of (x_{t-1}, x_t) given x0."""
    t, x0, xt = 300, 0.7, -0.4
    a_prev, a_t = schedule.alphas_cumprod[t - 1], schedule.alphas_cumprod[t]
    alpha = a_t / a_prev
    cov = math.sqrt(alpha) * (1 - a_prev)  # Cov(x_{t-1}, x_t | x0)
    expected_mean = math.sqrt(a_prev) * x0 + cov / (1 - a_t) * (xt - math.sqrt(a_t) * x0)
    expected_var = (1 - a_prev) - cov**2 / (1 - a_t)
    mean, variance = ddpm_posterior(schedule, np.array(x0), t, t - 1, np.array(xt))
    assert float(mean) == pytest.approx(expected_mean, rel=1e-9)
    assert variance == pytest.approx(expected_var, rel=1e-9)


def test_full_ddpm_with_oracle_x0_ends_at_x0(schedule):
    rng = np.random.default_rng(1)
    x0 = rng.standard_normal(6)
    sampler = SamplerConfig("ddpm", steps=T)
    x = rng.standard_normal(6)
    for t, t_prev in sampling_plan(T, sampler):
        x = ddpm_step(schedule, x0, t, t_prev, x, noise=rng.standard_normal(6))
    np.testing.assert_allclose(x, x0, atol=1e-12)


def test_q_sample_per_frame_timesteps_numpy_and_torch_agree(schedule):
    rng = np.random.default_rng(2)
    x0, noise = rng.standard_normal((2, 3, 4, 5))  # (B, N, C) each
    t = rng.integers(0, T, size=(3, 4))  # one timestep per frame
    xt = q_sample(schedule, x0, t, noise)
    b, n = 1, 2
    a = schedule.alphas_cumprod[t[b, n]]
    np.testing.assert_allclose(xt[b, n], math.sqrt(a) * x0[b, n] + math.sqrt(1 - a) * noise[b, n], atol=1e-12)
    xt_torch = q_sample(schedule, torch.from_numpy(x0).float(), torch.from_numpy(t), torch.from_numpy(noise).float())
    assert xt_torch.dtype == torch.float32
    np.testing.assert_allclose(xt_torch.numpy(), xt, atol=1e-5)


def test_steps_accept_torch_tensors(schedule):
    x0, x = torch.randn(2, 3), torch.randn(2, 3)
    out = ddim_step(schedule, x0, 999, CLEAN_TIMESTEP, x)
    assert torch.equal(out, x0)


def test_guidance_scale_one_is_conditional_and_zero_unconditional():
    rng = np.random.default_rng(3)
    uncond, cond = rng.standard_normal((2, 4, 7))
    np.testing.assert_allclose(classifier_free_guidance(uncond, cond, 1.0), cond, atol=1e-15)
    np.testing.assert_allclose(classifier_free_guidance(uncond, cond, 0.0), uncond, atol=1e-15)
    np.testing.assert_allclose(classifier_free_guidance(uncond, cond, 3.0), uncond + 3 * (cond - uncond), atol=1e-14)


def test_style_gamma_one_is_first_style_and_extrapolates_beyond():
    rng = np.random.default_rng(4)
    a, b = rng.standard_normal((2, 5))
    np.testing.assert_array_equal(style_interpolation(a, b, 1.0), a)
    np.testing.assert_array_equal(style_interpolation(a, b, 0.0), b)
    np.testing.assert_allclose(style_interpolation(a, b, 0.5), (a + b) / 2, atol=1e-15)
    np.testing.assert_allclose(style_interpolation(a, b, 2.0), a + (a - b), atol=1e-14)


def test_sampler_config_validates():
    with pytest.raises(ValueError):
        SamplerConfig("euler")
    with pytest.raises(ValueError):
        SamplerConfig("ddim", steps=MAX_DDIM_STEPS + 1)
    with pytest.raises(ValueError):
        SamplerConfig("ddim", eta=-0.1)
    assert SamplerConfig("ddpm", steps=1000).steps == 1000


def test_noisy_steps_without_noise_fail(schedule):
    x = np.zeros(3)
    with pytest.raises(ValueError):
        ddpm_step(schedule, x, 10, 9, x)
    with pytest.raises(ValueError):
        ddim_step(schedule, x, 10, 9, x, eta=0.5)
