"""Latency budget arithmetic and bounded rolling statistics."""

import json

import numpy as np
import pytest

from gesturecast.errors import UserError
from gesturecast.realtime.timing.clock import FakeClock
from gesturecast.realtime.timing.latency import LatencyBudget, LatencyStats
from gesturecast.settings import LATENCY_SETTINGS


def test_budget_d4_lookahead8_is_400ms_algorithmic():
    budget = LatencyBudget(latent_frames=4, lookahead_frames=8, compute_margin_ms=75.0)
    assert budget.algorithmic_ms == pytest.approx(400.0)
    assert budget.total_ms == pytest.approx(475.0)
    assert budget.total_s == pytest.approx(0.475)


def test_budget_scales_with_frame_rate_and_zero_lookahead():
    budget = LatencyBudget(latent_frames=6, lookahead_frames=0, compute_margin_ms=0.0, fps=60.0)
    assert budget.algorithmic_ms == pytest.approx(100.0)
    assert budget.total_ms == pytest.approx(100.0)


@pytest.mark.parametrize(("setting", "lookahead", "total_ms"),
                         [("low", 0, 5000 / 30 + 80.0), ("balanced", 4, 9000 / 30 + 80.0), ("quality", 8, 533.3333)])
def test_each_latency_setting_gives_its_budget_for_the_bundled_layout(setting, lookahead, total_ms):
    """d = 4, δa = 8, smoothing k = 1 (the bundled model and the default smoothing): low stays within 250 ms."""
    chosen = LATENCY_SETTINGS[setting]
    assert chosen.lookahead_for(8) == lookahead
    budget = LatencyBudget(4, chosen.lookahead_for(8), chosen.compute_margin_ms, smoothing_frames=1)
    assert budget.total_ms == pytest.approx(total_ms, abs=1e-3)
    assert setting != "low" or budget.total_ms <= 250.0  # the 250 ms target of low


def test_a_setting_never_asks_for_more_look_ahead_than_the_model_has():
    assert [LATENCY_SETTINGS[name].lookahead_for(2) for name in ("low", "balanced", "quality")] == [0, 2, 2]


def test_describe_names_the_audio_delay():
    line = LatencyBudget(latent_frames=4, lookahead_frames=8, compute_margin_ms=100.0).describe()
    assert "delay your audio by 500 ms to stay in sync" in line
    assert "400 ms" in line


@pytest.mark.parametrize(
    "kwargs", [{"latent_frames": 0}, {"lookahead_frames": -1}, {"compute_margin_ms": -5.0}, {"fps": 0.0}]
)
def test_budget_rejects_impossible_settings(kwargs):
    with pytest.raises(UserError):
        LatencyBudget(**kwargs)


def test_budget_dict_is_json_and_reports_l():
    data = json.loads(json.dumps(LatencyBudget(4, 8, 100.0).to_dict()))
    assert data["latency_budget_ms"] == pytest.approx(500.0)


def test_percentiles_match_numpy_within_the_window():
    stats = LatencyStats(FakeClock(), window=1000)
    values = np.random.default_rng(0).uniform(0.0, 0.2, size=500)
    for v in values:
        stats.record("denoiser", v)
    summary = stats.stage_summary("denoiser")
    assert summary["count"] == 500
    assert summary["p50"] == pytest.approx(np.percentile(values, 50) * 1000)
    assert summary["p99"] == pytest.approx(np.percentile(values, 99) * 1000)
    assert summary["max"] == pytest.approx(values.max() * 1000)
    assert summary["mean"] == pytest.approx(values.mean() * 1000)


def test_memory_stays_bounded_after_1e5_samples_and_window_rolls():
    window = 256
    stats = LatencyStats(FakeClock(), window=window)
    n = 100_000
    for i in range(n):
        stats.record("end_to_end", i * 1e-6)
    ring = stats._rings["end_to_end"]
    assert ring.samples.size == window
    assert ring.recent().size == window
    assert stats.count("end_to_end") == n
    summary = stats.stage_summary("end_to_end")
    newest = np.arange(n - window, n) * 1e-3  # ms
    assert summary["p50"] == pytest.approx(np.percentile(newest, 50))
    assert summary["max"] == pytest.approx((n - 1) * 1e-3)
    assert summary["mean"] == pytest.approx((n - 1) / 2 * 1e-3)


def test_last_n_percentiles_use_only_the_newest_samples():
    stats = LatencyStats(FakeClock(), window=100)
    for v in [1.0] * 150 + [0.002] * 10:
        stats.record("bridge", v)
    (p95,) = stats.percentiles_ms("bridge", (95.0,), last=10)
    assert p95 == pytest.approx(2.0)


def test_time_context_uses_the_injected_clock():
    clock = FakeClock()
    stats = LatencyStats(clock)
    with stats.time("features"):
        clock.advance(0.012)
    assert stats.stage_summary("features")["max"] == pytest.approx(12.0)


def test_summary_is_json_serialisable_and_unknown_stage_is_nan():
    stats = LatencyStats(FakeClock())
    stats.record("decoder", 0.003)
    json.dumps(stats.summary())
    assert set(stats.summary()) == {"decoder"}
    assert np.isnan(stats.percentiles_ms("missing")[0])


def test_a_short_stream_holds_kilobytes_not_a_full_window_per_stage():
    """Before: every stage allocated the whole 512 KiB window on its first sample (3 MiB for a 1 s
    serve stream), which `serve` left behind in the allocator for every stream it started."""
    import tracemalloc

    stages = ("features", "denoiser", "decoder", "sink", "lateness", "end_to_end")
    tracemalloc.start()
    try:
        stats = LatencyStats(FakeClock())
        for k in range(30):  # one second of frames
            for stage in stages:
                stats.record(stage, k * 1e-3)
        held = tracemalloc.get_traced_memory()[0]
    finally:
        tracemalloc.stop()
    assert held < 64 * 1024, f"{held} bytes for 30 samples of {len(stages)} stages"


def test_a_growing_ring_keeps_exactly_the_newest_window_samples():
    window = 5000
    stats = LatencyStats(FakeClock(), window=window)
    values = np.random.default_rng(1).uniform(0.0, 0.1, size=12_345)  # grows 512 -> ... -> 5000, then wraps
    for k, v in enumerate(values):
        stats.record("denoiser", v)
        if k + 1 in (511, 512, 513, 1024, window, window + 1):
            newest = values[max(0, k + 1 - window) : k + 1]
            assert stats.stage_summary("denoiser")["p50"] == pytest.approx(np.percentile(newest, 50) * 1000)
    assert stats._rings["denoiser"].samples.size == window
    summary = stats.stage_summary("denoiser")
    assert summary["p95"] == pytest.approx(np.percentile(values[-window:], 95) * 1000)
    assert summary["count"] == values.size and summary["max"] == pytest.approx(values.max() * 1000)
    (p50_last_10,) = stats.percentiles_ms("denoiser", (50.0,), last=10)
    assert p50_last_10 == pytest.approx(np.percentile(values[-10:], 50) * 1000)
