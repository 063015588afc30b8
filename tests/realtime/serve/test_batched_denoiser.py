"""Batched denoiser: streams stacked along the batch dimension get exactly their own results."""

import threading

import numpy as np
import pytest

from gesturecast.models.generator.diffusion import SamplerConfig
from gesturecast.models.generator.style_prompt import StylePrompt
from gesturecast.realtime.generation.generator import Generator, GeneratorSettings
from gesturecast.realtime.serve.batched_denoiser import (
    BatchPort,
    DenoiserBatcher,
    SharedDenoiserBundle,
    group_key,
    split_outputs,
    stack_feeds,
)

# (style, guidance, seed, latents already generated): different rows (1 or 2) and cache lengths
STREAMS = [("neutral", 1.5, 1, 0), ("old", 1.0, 2, 2), ("neutral", 2.0, 3, 6)]


class RecordingSession:
    """Delegates to a real onnxruntime session and keeps the feeds of every call."""

    def __init__(self, session):
        self.session = session
        self.calls = []

    def run(self, names, feeds):
        self.calls.append({k: np.array(v) for k, v in feeds.items()})
        return self.session.run(names, feeds)


def next_call_feeds(bundle, style, guidance, seed, latents) -> dict:
    """The feeds of the first denoiser call of latent number ``latents`` of a generator."""
    generator = Generator(bundle, GeneratorSettings(SamplerConfig("ddim", 2), guidance, StylePrompt("label", style),
                                                    seed=seed))
    windows = np.random.default_rng(seed).standard_normal((latents + 1, bundle.audio_window, 67)).astype(np.float32)
    for window in windows[:-1]:
        generator.step(window)
    recorder = RecordingSession(generator.denoiser.session)
    generator.denoiser.session = recorder
    generator.step(windows[-1])
    return recorder.calls[0]


def test_stacked_call_equals_each_stream_alone(bundle):
    runtime = bundle.denoiser()
    requests = [next_call_feeds(bundle, *stream) for stream in STREAMS]
    by_shape = {}
    for request in requests:
        by_shape.setdefault(group_key(request), []).append(request)
    groups = list(by_shape.values())
    assert max(len(g) for g in groups) >= 2  # streams with a pending latent share a call
    for group in groups:
        stacked = runtime.session.run(None, stack_feeds(group))
        for request, own in zip(group, split_outputs(stacked, [len(r["x_t"]) for r in group]), strict=True):
            alone = runtime.session.run(None, request)
            for got, want in zip(own, alone, strict=True):
                np.testing.assert_array_equal(got, want)
    assert {len(r["x_t"]) for r in requests} == {1, 2}  # with and without the guidance row
    assert len({tuple(r["cache_length"]) for r in requests}) == len(STREAMS)


def test_concurrent_generators_through_the_batcher_equal_their_solo_runs(bundle):
    windows = np.random.default_rng(9).standard_normal((6, bundle.audio_window, 67)).astype(np.float32)

    def settings(style, guidance, seed, _):
        return GeneratorSettings(SamplerConfig("ddim", 2), guidance, StylePrompt("label", style), seed=seed)

    solo = []
    for stream in STREAMS:
        generator = Generator(bundle, settings(*stream))
        solo.append(np.stack([generator.step(w) for w in windows]))
    batcher = DenoiserBatcher(bundle.path("denoiser")).start()
    try:
        shared = SharedDenoiserBundle.wrap(bundle, batcher)
        generators = [Generator(shared, settings(*stream)) for stream in STREAMS]
        assert all(isinstance(g.denoiser.session, BatchPort) for g in generators)
        batched = [None] * len(STREAMS)

        def run(index):
            batched[index] = np.stack([generators[index].step(w) for w in windows])

        threads = [threading.Thread(target=run, args=(i,)) for i in range(len(STREAMS))]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
    finally:
        batcher.close()
    for want, got in zip(solo, batched, strict=True):
        np.testing.assert_array_equal(got, want)
    assert batcher.stats.requests == len(STREAMS) * len(windows) * 2  # K = 2 calls per latent, none lost


def test_a_closed_batcher_refuses_calls(bundle):
    batcher = DenoiserBatcher(bundle.path("denoiser")).start()
    batcher.close()
    with pytest.raises(RuntimeError, match="not running"):
        batcher.submit({})
