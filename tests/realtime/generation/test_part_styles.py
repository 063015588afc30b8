"""Per-body-part style prompts (GestureDiffuCLIP §6.3) on the tiny model: rows, fusion by masks, blending."""

import numpy as np
import pytest

from gesturecast.controls import parse_controls
from gesturecast.errors import UserError
from gesturecast.models.generator.style_prompt import StylePrompt, parse_part_styles
from gesturecast.realtime.generation.generator import Generator, GeneratorSettings
from gesturecast.realtime.generation.style_mixture import (
    align_mixtures,
    drop_unused_rows,
    fuse_trajectories,
    guide_trajectories,
    part_mixture,
    row_layout,
)
from gesturecast.realtime.gestures.director import GestureDirector
from gesturecast.realtime.gestures.repertoire import GestureRepertoire
from gesturecast.realtime.pose.session_controls import MAX_MIXTURE_ROWS, SessionControls

STEPS = 4
NEUTRAL = StylePrompt("label", "neutral")
HAPPY = StylePrompt("label", "happy")
OLD = StylePrompt("label", "old")
CHANNELS = {"arms": slice(0, 2), "torso": slice(2, 3), "legs": slice(3, 5)}


@pytest.fixture(scope="module")
def audio(bundle):
    rng = np.random.default_rng(11)
    return rng.standard_normal((STEPS, bundle.audio_window, bundle.denoiser_config.audio_dim)).astype(np.float32)


def no_gestures(generator: Generator) -> GestureDirector:
    """The gestures of a stream without a lexicon (these controls change only the style)."""
    config = generator.audio_config
    return GestureDirector(GestureRepertoire(), config.frames_per_latent / generator.bundle.feature_config.fps, 0.0)


def latents(generator: Generator, audio: np.ndarray) -> np.ndarray:
    return np.stack([generator.denoise(window, True) for window in audio])  # (STEPS, C)


def make(bundle, **settings) -> Generator:
    return Generator(bundle, GeneratorSettings(guidance=1.5, **settings))


def test_part_styles_parse_from_the_command_line_and_from_json():
    assert parse_part_styles(["arms=happy", "legs=text:tired and slow"]) == (
        ("arms", HAPPY), ("legs", StylePrompt("text", "tired and slow")))
    assert parse_part_styles({"torso": "old"}) == (("torso", OLD),)
    with pytest.raises(UserError, match="PART=STYLE"):
        parse_part_styles(["happy"])
    with pytest.raises(UserError, match="two styles"):
        parse_part_styles(["arms=happy", "arms=old"])


def test_mixture_weights_are_the_parts_channel_masks():
    prompts, weights = part_mixture(NEUTRAL, {"arms": HAPPY, "legs": OLD}, CHANNELS, 5)
    assert prompts == [NEUTRAL, HAPPY, OLD]
    np.testing.assert_array_equal(weights, [[0, 0, 1, 0, 0], [1, 1, 0, 0, 0], [0, 0, 0, 1, 1]])
    np.testing.assert_array_equal(weights.sum(axis=0), np.ones(5))  # every channel from exactly one prompt
    same, one_row = part_mixture(HAPPY, {"arms": HAPPY}, CHANNELS, 5)
    assert same == [HAPPY] and one_row.shape == (1, 5)  # a part with the base style costs no row
    with pytest.raises(UserError, match="unknown body part 'tail'"):
        part_mixture(NEUTRAL, {"tail": HAPPY}, CHANNELS, 5)


def test_every_prompt_is_guided_on_its_own_trajectory_and_the_parts_are_fused_by_their_masks():
    rng = np.random.default_rng(0)
    styles = rng.standard_normal((2, 4)).astype(np.float32)
    prompts, weights = part_mixture(NEUTRAL, {"arms": HAPPY}, CHANNELS, 5)
    layout = row_layout(styles, None, 1.0, guidance=2.0, audio_guidance=1.5)
    # neutral, happy, a null row per trajectory, each prompt without the audio
    assert layout.batch == 6 and layout.mixture_rows == 2
    np.testing.assert_array_equal(layout.row_trajectory, [0, 1, 0, 1, 0, 1])
    np.testing.assert_array_equal(layout.style_present, [1, 1, 0, 0, 1, 1])
    np.testing.assert_array_equal(layout.hears_audio, [1, 1, 1, 1, 0, 0])
    x0_rows = rng.standard_normal((6, 5))
    guided = guide_trajectories(x0_rows, layout, 1.0, 2.0, 1.5)  # (R, C)
    for row in (0, 1):
        expected = x0_rows[2 + row] + 2.0 * (x0_rows[row] - x0_rows[2 + row]) + 0.5 * (x0_rows[row] - x0_rows[4 + row])
        np.testing.assert_allclose(guided[row], expected)
    fused = fuse_trajectories(guided, weights)
    np.testing.assert_allclose(fused[CHANNELS["arms"]], guided[1, CHANNELS["arms"]])
    np.testing.assert_allclose(fused[2:], guided[0, 2:])


def test_mixtures_align_for_a_ramp_and_unused_prompts_drop():
    old = part_mixture(NEUTRAL, {"arms": HAPPY}, CHANNELS, 5)
    new = part_mixture(NEUTRAL, {"legs": OLD}, CHANNELS, 5)
    union, start, target = align_mixtures(*old, *new)
    assert union == [NEUTRAL, HAPPY, OLD]
    np.testing.assert_array_equal(start.sum(axis=0), np.ones(5))
    np.testing.assert_array_equal(target.sum(axis=0), np.ones(5))
    halfway = 0.5 * (start + target)  # a ramp's midpoint is still a partition of every channel
    np.testing.assert_allclose(halfway.sum(axis=0), np.ones(5))
    prompts, weights = drop_unused_rows(union, target, NEUTRAL)
    assert prompts == [NEUTRAL, OLD] and weights.shape == (2, 5)


def test_part_styles_add_one_row_per_other_prompt_and_keep_single_style_output(bundle, audio):
    single = make(bundle, style=HAPPY)
    same_prompt_everywhere = make(bundle, style=HAPPY, part_styles=(("arms", HAPPY), ("legs", HAPPY)))
    assert same_prompt_everywhere.layout.batch == single.layout.batch == 2  # style + null
    np.testing.assert_array_equal(latents(single, audio), latents(same_prompt_everywhere, audio))
    two = make(bundle, style=OLD, part_styles=(("arms", HAPPY),))
    assert two.layout.batch == 4  # two styles, a null row for each
    result = latents(two, audio)
    assert np.isfinite(result).all()
    assert np.abs(result - latents(make(bundle, style=OLD), audio)).max() > 1e-3


def test_each_part_moves_as_its_prompt_moves_a_whole_body_latent_after_latent(bundle, audio):
    """Every prompt is its own trajectory (its own x_t and history): a part's channels equal those of a run with
    its prompt alone, on every latent, not only the first."""
    channels = bundle.part_channels
    mixed = latents(make(bundle, style=OLD, part_styles=(("arms", HAPPY),), seed=2, audio_guidance=1.5), audio)
    happy = latents(make(bundle, style=HAPPY, seed=2, audio_guidance=1.5), audio)
    old = latents(make(bundle, style=OLD, seed=2, audio_guidance=1.5), audio)
    np.testing.assert_allclose(mixed[:, channels["arms"]], happy[:, channels["arms"]], atol=1e-5)
    for part in ("torso", "legs"):
        np.testing.assert_allclose(mixed[:, channels[part]], old[:, channels[part]], atol=1e-5)


def test_a_live_part_style_change_blends_in_and_then_drops_the_old_prompt(bundle, audio):
    generator = make(bundle, style=NEUTRAL)
    controls = SessionControls(generator, None, no_gestures(generator), fade_s=0.5)
    controls.submit(parse_controls({"part_styles": {"arms": "happy"}}))
    weights_over_time = []
    for step, t in enumerate(np.linspace(0.0, 0.75, 7)):
        controls.advance(float(t))
        generator.denoise(audio[step % STEPS], True)
        prompts, weights = generator.mixture
        weights_over_time.append(weights[prompts.index(HAPPY), bundle.part_channels["arms"]].mean())
    assert weights_over_time[0] == 0.0 and weights_over_time[-1] == 1.0
    assert all(b >= a for a, b in zip(weights_over_time, weights_over_time[1:], strict=False))  # no jump back
    assert 0.0 < weights_over_time[3] < 1.0  # halfway through the fade both prompts share the arms
    assert generator.mixture[0] == [NEUTRAL, HAPPY]
    controls.submit(parse_controls({"part_styles": {}}))
    controls.advance(1.0)
    controls.advance(2.0)
    assert generator.mixture[0] == [NEUTRAL] and generator.settings.part_styles == ()
    with pytest.raises(UserError, match="unknown body part"):
        controls.submit(parse_controls({"part_styles": {"tail": "happy"}}))


def test_an_unknown_style_inside_part_styles_is_refused_when_submitted(bundle):
    """The styles inside part_styles are resolved before the control is accepted, so a misspelt label is the
    submitter's one-line error instead of a failure of the stream when the control is applied."""
    generator = make(bundle, style=NEUTRAL)
    controls = SessionControls(generator, None, no_gestures(generator), fade_s=0.5)
    with pytest.raises(UserError, match="hapy"):
        controls.submit(parse_controls({"part_styles": {"arms": "hapy"}}))
    controls.advance(0.0)  # nothing was queued: the stream goes on with its mixture
    assert generator.mixture[0] == [NEUTRAL]


def test_part_style_controls_faster_than_the_fade_keep_the_rows_bounded(bundle, audio):
    """New text prompts every tenth of the fade: the rows stay within MAX_MIXTURE_ROWS, W stays a partition of every
    channel, and once the fade is over only the prompts in use are left."""
    generator = make(bundle, style=NEUTRAL)
    controls = SessionControls(generator, None, no_gestures(generator), fade_s=1.0)
    rows = []
    for step in range(30):
        parts = {"arms": f"text:waving number {step}", "legs": f"text:stepping {step}"}
        controls.submit(parse_controls({"part_styles": parts}))
        for t in (0.1 * step, 0.1 * step + 0.05):  # two latents per control: each new prompt gets some weight
            controls.advance(t)
            generator.denoise(audio[step % STEPS], True)
        prompts, weights = generator.mixture
        rows.append(len(prompts))
        np.testing.assert_allclose(weights.sum(axis=0), np.ones(generator.latent_dim), atol=1e-6)
    assert 3 < max(rows) <= MAX_MIXTURE_ROWS  # blends overlapped, and the rows stayed bounded
    controls.advance(10.0)
    last = [NEUTRAL, StylePrompt("text", "waving number 29"), StylePrompt("text", "stepping 29")]
    assert generator.mixture[0] == last and generator.layout.mixture_rows == len(last)
