"""What the generator hears of the stream's style: a style the stylizer gives never reaches the generator's settings,
from Settings or through a live change; a label it learned with speech does, at the style strength k."""

import numpy as np
import pytest

from gesturecast.controls import StyleChange
from gesturecast.errors import UserError
from gesturecast.models.generator.style_prompt import StylePrompt
from gesturecast.models.style.params import DEFAULT_STYLE_PARAMS, StyleBook
from gesturecast.realtime.audio.sources import AudioChunk
from gesturecast.realtime.pose.style_hearing import STYLIZER_STRENGTH, StyleHearing, StyleState
from gesturecast.realtime.run.engine_setup import build_session
from gesturecast.realtime.timing.clock import MonotonicClock
from gesturecast.settings import Settings

SPEECH = StylePrompt("label", "speech")
HAPPY, SAD, FLIRTY = StylePrompt("label", "happy"), StylePrompt("label", "sad"), StylePrompt("label", "flirty")
STYLIZER_LABELS = frozenset(StyleBook.load(DEFAULT_STYLE_PARAMS).styles)


def test_the_rule_hears_the_generator_style_for_the_stylizers_styles_and_own_labels_as_asked():
    hearing = StyleHearing(SPEECH, frozenset({"speech", "flirty"}))
    state = StyleState(HAPPY, SAD, 0.3, (("arms", FLIRTY), ("legs", StylePrompt("text", "calm"))), 1.5)
    assert hearing.heard(state) == StyleState(SPEECH, SPEECH, 0.3, (("arms", FLIRTY), ("legs", SPEECH)),
                                              STYLIZER_STRENGTH)
    assert hearing.heard(StyleState(FLIRTY, HAPPY, 2.0, (), 1.5)) == StyleState(FLIRTY, SPEECH, 2.0, (), 1.5)
    assert StyleHearing().heard(state) == state  # no stylizer after the generator: every style as asked


def test_a_style_the_model_cannot_use_is_refused_as_the_session_is_made_though_the_generator_hears_speech(tmp_path):
    for style in ("mumbling", f"motion:{tmp_path / 'missing.bvh'}"):
        with pytest.raises(UserError, match="mumbling|missing.bvh"):
            build_session(Settings(style=style, gestures=None), MonotonicClock())


def generator_prompts(session) -> list[StylePrompt]:
    """Every prompt the session's generator holds: its settings' styles and its mixture's rows."""
    return [*StyleState.of(session.generator.settings).prompts(), *session.generator.mixture[0]]


def assert_hears_no_stylizer_style(session) -> None:
    labels = {prompt.value for prompt in generator_prompts(session) if prompt.kind == "label"}
    kinds = {prompt.kind for prompt in generator_prompts(session)}
    assert not labels & STYLIZER_LABELS and kinds == {"label"}


@pytest.mark.parametrize(("style", "heard", "strength"), [("happy", SPEECH, STYLIZER_STRENGTH),
                                                          ("text:calm and slow", SPEECH, STYLIZER_STRENGTH),
                                                          ("flirty", FLIRTY, 1.5), ("speech", SPEECH, 1.5)])
def test_the_generator_is_made_with_what_it_hears(style, heard, strength):
    settings = Settings(style=style, style2="sad", gamma=0.5, part_styles={"arms": "old"}, style_strength=1.5,
                        gestures=None)
    session = build_session(settings, MonotonicClock())
    assert session.controls.style.style == StylePrompt.parse(style)  # the session holds the style asked
    assert session.generator.settings.style == heard and session.generator.settings.style_strength == strength
    assert_hears_no_stylizer_style(session)


def test_live_style_changes_reach_the_generator_as_heard():
    """Every kind of live change (a label, a prompt, γ mixing, part styles and their blends, the strength) passes
    the same rule: after each latent the generator holds no style the stylizer gives."""
    session = build_session(Settings(style="speech", gestures=None), MonotonicClock())
    changes = [StyleChange(style="happy"), StyleChange(prompt="slow and tired"), StyleChange(style="old", style2="sad"),
               StyleChange(part_styles=(("arms", "happy"),)), StyleChange(style="flirty", style_strength=1.5),
               StyleChange(part_styles=(("arms", "angry"), ("legs", "speech"))), StyleChange(style="sad")]
    audio = np.random.default_rng(0).normal(0.0, 0.1, 8000 * len(changes)).astype(np.float32)  # noise: "speech"
    offset = 0
    for change in changes:
        session.controls.submit((change,))
        for start in range(0, 8000, 1600):  # half a second in chunks: the change is applied and ramps
            session.push(AudioChunk(audio[offset + start : offset + start + 1600], offset + start, 0.0))
            assert_hears_no_stylizer_style(session)
        offset += 8000
    assert session.controls.style.style == SAD
    assert session.generator.settings.style == SPEECH
    flirty = session.controls.hearing.heard(StyleState(FLIRTY, strength=1.5))
    assert (flirty.style, flirty.strength) == (FLIRTY, 1.5)
