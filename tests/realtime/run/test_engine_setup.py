"""Flags → Settings and Outputs → bridges: the VMC role picks the default port, the bones and whether the root is
sent; the latency setting is resolved once, into the budget both the generator and the session use."""

import argparse

import numpy as np
import pytest

from gesturecast.bridges.vmc_roles import HEAD_AND_LEGS
from gesturecast.errors import UserError
from gesturecast.models.generator.style_prompt import StylePrompt
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS
from gesturecast.realtime.cli_flags import (
    add_generation_arguments,
    add_output_arguments,
    outputs_from_args,
    settings_from_args,
)
from gesturecast.realtime.run.engine_setup import SessionFactory, build_session, vmc_config
from gesturecast.realtime.timing.clock import MonotonicClock
from gesturecast.settings import LATENCY_SETTINGS, Settings


def vmc(*flags: str):
    parser = argparse.ArgumentParser()
    add_generation_arguments(parser)
    add_output_arguments(parser)
    args = parser.parse_args(list(flags))
    return vmc_config(outputs_from_args(args), settings_from_args(args))


def test_marionette_is_the_default_on_39539_with_every_bone_and_vrm0_visemes():
    config = vmc("--vmc", "127.0.0.1")
    assert (config.host, config.port, config.assistant) == ("127.0.0.1", 39539, False)
    assert config.bones == CANONICAL_WITH_HANDS.names and config.viseme_names == ("A", "I", "U", "E", "O")


def test_assistant_defaults_to_39540_and_the_upper_body():
    config = vmc("--vmc", "10.0.0.2", "--vmc-role", "assistant", "--lipsync", "vrm1")
    assert (config.host, config.port, config.assistant) == ("10.0.0.2", 39540, True)
    assert config.bones and not set(config.bones) & set(HEAD_AND_LEGS)
    assert config.viseme_names == ("aa", "ih", "ou", "ee", "oh")


def test_explicit_port_bones_and_lipsync_off():
    config = vmc("--vmc", "host:40000", "--vmc-role", "assistant", "--vmc-bones", "none", "--lipsync", "off")
    assert (config.port, config.bones, config.viseme_names) == (40000, (), ())


def test_unknown_bone_is_a_user_error():
    with pytest.raises(UserError, match="Wing"):
        vmc("--vmc", "127.0.0.1", "--vmc-bones", "Spine,Wing")


@pytest.mark.parametrize("setting", list(LATENCY_SETTINGS))
def test_one_latency_value_reaches_the_generator_and_the_session(setting):
    session = build_session(Settings(latency=setting, smoothing=2), MonotonicClock())
    budget = session.budget
    expected = LATENCY_SETTINGS[setting].lookahead_for(session.bundle.audio_lookahead)
    assert budget.lookahead_frames == expected == session.generator.settings.lookahead == session.generator.lookahead
    assert budget.compute_margin_ms == LATENCY_SETTINGS[setting].compute_margin_ms and budget.smoothing_frames == 2


def test_lookahead_and_margin_override_the_setting():
    budget = build_session(Settings(latency="low", lookahead=3, margin_ms=50.0), MonotonicClock()).budget
    assert (budget.lookahead_frames, budget.compute_margin_ms) == (3, 50.0)


def test_one_factory_makes_every_stream_sharing_the_model_lexicon_and_each_budget():
    """A server's streams come from one factory: one bundle, the lexicon encoded once, and a latency setting
    resolved once however many streams ask for it; each stream still gets its own generator."""
    factory = SessionFactory(Settings())
    clock = MonotonicClock()
    low = Settings().replace(latency="low")
    first, second, third = factory.session(clock, low), factory.session(clock, low), factory.session(clock)
    assert first.budget is second.budget and third.budget is factory.budget() and first.budget is not third.budget
    assert first.bundle is second.bundle is third.bundle is factory.bundle
    assert first.gestures.repertoire is third.gestures.repertoire is factory.repertoire and factory.repertoire.clips
    assert first.gestures is not second.gestures  # each stream its own cue plan
    assert first.generator is not second.generator and first.generator.lookahead == low_lookahead(factory)
    assert factory.session(clock, Settings(root="free")).config.root_mode.value == "free"


def low_lookahead(factory: SessionFactory) -> int:
    return LATENCY_SETTINGS["low"].lookahead_for(factory.bundle.audio_lookahead)


@pytest.mark.parametrize("style", ["neutral", "happy", "old"])
def test_the_generator_hears_the_speech_label_under_every_stylizer_style(style):
    """The default and every stylizer style: the denoiser is conditioned on ``speech`` (learned with its audio), not
    on the label asked, which the stylizer gives."""
    session = build_session(Settings(style=style, gestures=None), MonotonicClock())
    speech = session.generator.styles.embed(StylePrompt("label", "speech"))
    assert Settings().generator_style == "speech"
    np.testing.assert_array_equal(session.generator.style_embedding, speech)


def test_the_generators_own_neutral_is_a_setting_and_an_unknown_label_is_refused():
    session = build_session(Settings(generator_style="Neutral", gestures=None), MonotonicClock())
    neutral = session.generator.styles.embed(StylePrompt("label", "neutral"))
    np.testing.assert_array_equal(session.generator.style_embedding, neutral)
    with pytest.raises(UserError, match="unknown style 'mumbling'"):
        Settings(generator_style="mumbling")
    parser = argparse.ArgumentParser()
    add_generation_arguments(parser)
    assert settings_from_args(parser.parse_args(["--generator-style", "neutral"])).generator_style == "neutral"


@pytest.mark.parametrize("latency", list(LATENCY_SETTINGS))
def test_every_door_and_a_live_style_change_keep_the_speech_label(latency):
    """``Stream`` (and the Pipecat processor, a Stream), a ``serve`` stream and a live style change: the generator
    still hears ``speech`` at every latency setting."""
    from gesturecast.controls import StyleChange
    from gesturecast.realtime.run.stream import Stream
    from gesturecast.realtime.serve.protocol import StreamOptions
    from gesturecast.realtime.serve.setup import StreamSessions

    settings = Settings(latency=latency, gestures=None)
    stream = Stream(settings, warm=False, paced=False)
    served = StreamSessions(settings, stream.session.bundle, MonotonicClock(), max_streams=1)
    try:
        session = served.session(StreamOptions(style=StyleChange(style="happy"), latency=latency))
        speech = session.generator.styles.embed(StylePrompt("label", "speech"))
        stream.session.controls.submit((StyleChange(style="old"),))
        stream.push(np.zeros(16000, np.float32))  # the change is applied at the next latent
        for generator in (stream.session.generator, session.generator):
            np.testing.assert_array_equal(generator.style_embedding, speech)
        assert stream.session.controls.style.style == StylePrompt("label", "old")  # the session holds the style
        assert stream.session.generator.settings.style == StylePrompt("label", "speech")  # the generator what it hears
    finally:
        stream.close()
        served.close()


def test_the_stylizer_and_the_face_take_the_style_the_session_holds_not_the_generators():
    """The session's controls own the style (from Settings, then live changes); the generator is told it but is not
    read back: a generator holding another style label changes nothing the pose frames show."""
    from dataclasses import replace

    from gesturecast.realtime.audio.sources import AudioChunk

    audio = np.random.default_rng(0).normal(0.0, 0.1, 32000).astype(np.float32)  # 2 s of noise the VAD calls speech

    def frames(session):
        return session.push(AudioChunk(audio, 0, 0.0)) + session.finish()

    settings = Settings(style="happy", gestures=None)
    plain = frames(build_session(settings, MonotonicClock()))
    session = build_session(settings, MonotonicClock())
    session.generator.settings = replace(session.generator.settings, style=StylePrompt("label", "sad"))
    assert session.controls.style.style == StylePrompt("label", "happy")
    told = frames(session)
    assert [frame.style for frame in told] == [frame.style for frame in plain]
    np.testing.assert_array_equal(np.stack([f.rotations for f in told]), np.stack([f.rotations for f in plain]))
    np.testing.assert_array_equal(np.stack([f.face for f in told]), np.stack([f.face for f in plain]))
