"""Every benchmark generates at the product's defaults (``Settings()``) unless told otherwise, and says so."""

from __future__ import annotations

import argparse

import numpy as np
import pytest

from gesturecast.models.generator.diffusion import SamplerConfig
from gesturecast.models.generator.style_prompt import StylePrompt
from gesturecast.realtime.run.engine_setup import generator_settings, load_bundle, resolve_latency
from gesturecast.realtime.timing.clock import FakeClock
from gesturecast.settings import Settings
from gesturecast.tools.bench.following import register_bench as register_following
from gesturecast.tools.bench.speech.voices import register_bench as register_voices
from gesturecast.tools.eval.condition import DEFAULT_CONDITION, Condition
from gesturecast.tools.eval.eval_command import register as register_eval
from gesturecast.tools.eval.generate import _session, eval_settings


def parsed(register, *argv: str) -> argparse.Namespace:
    parser = argparse.ArgumentParser()
    register(parser.add_subparsers())
    return parser.parse_args(list(argv))


@pytest.mark.parametrize("argv", [("voices",), ("following",), ("eval", "--json", "x.json")])
def test_the_benchmarks_default_condition_is_the_products_settings(argv):
    register = {"voices": register_voices, "following": register_following, "eval": register_eval}[argv[0]]
    condition = Condition.from_args(parsed(register, *argv))
    assert condition == DEFAULT_CONDITION and condition.describe()["default_settings"]
    assert (condition.style, condition.generator_style) == (Settings().style, Settings().generator_style)


def test_another_condition_is_reported_as_not_the_default():
    condition = Condition.from_args(parsed(register_voices, "voices", "--style", "speech", "--generator-style",
                                           "Neutral"))
    assert condition.describe() == {"style": "speech", "generator_style": "neutral", "default_settings": False}


def test_an_evaluation_session_is_the_one_the_product_builds_from_settings():
    bundle = load_bundle(Settings().model)
    settings = eval_settings(bundle, SamplerConfig("ddim", bundle.default_steps), "neutral", seed=3)
    assert settings == Settings(seed=3, steps=bundle.default_steps)  # every other field at the product's default
    session = _session(bundle, settings, FakeClock())
    assert session.generator.settings == generator_settings(settings, bundle, resolve_latency(settings, bundle))
    speech = session.generator.styles.embed(StylePrompt("label", "speech"))
    np.testing.assert_array_equal(session.generator.style_embedding, speech)
