import numpy as np
import pytest

from gesturecast.errors import UserError
from gesturecast.models.generator.diffusion import SamplerConfig
from gesturecast.models.generator.style_prompt import StylePrompt
from gesturecast.models.motion.motion_features import FEATURE_DIM
from gesturecast.realtime.generation.generator import Generator, GeneratorSettings, row_layout

STEPS = 4
HAPPY = StylePrompt("label", "happy")
OLD = StylePrompt("label", "old")


@pytest.fixture(scope="module")
def audio(bundle):
    """STEPS normalised audio windows with real variation."""
    rng = np.random.default_rng(7)
    return rng.standard_normal((STEPS, bundle.audio_window, bundle.denoiser_config.audio_dim)).astype(np.float32)


def run(generator: Generator, audio: np.ndarray) -> np.ndarray:
    return np.concatenate([generator.step(window, True) for window in audio])  # (STEPS*d, D)


def latents(generator: Generator, audio: np.ndarray) -> np.ndarray:
    """The STEPS clean latents (normalised) the generator commits: where the model's choices show most
    clearly (the tiny model's decoder maps nearly everything to the mean pose)."""
    return np.stack([generator.denoise(window, True) for window in audio])  # (STEPS, C)


def make(bundle, **settings) -> Generator:
    return Generator(bundle, GeneratorSettings(**settings))


def test_step_returns_d_denormalised_feature_frames(bundle, audio):
    frames = make(bundle, style=HAPPY, guidance=2.0).step(audio[0], True)
    assert frames.shape == (bundle.frames_per_latent, FEATURE_DIM) and np.isfinite(frames).all()
    stats = bundle.motion_stats
    assert np.abs((frames - stats.mean) / stats.std).max() < 50  # on the data's scale, not normalised


def test_same_seed_same_motion_other_seed_other_motion(bundle, audio):
    first = run(make(bundle, seed=3), audio)
    np.testing.assert_array_equal(first, run(make(bundle, seed=3), audio))
    assert np.abs(latents(make(bundle, seed=3), audio) - latents(make(bundle, seed=4), audio)).max() > 1e-2


def test_reset_restarts_the_stream_exactly(bundle, audio):
    generator = make(bundle, seed=5)
    expected = run(generator, audio)
    run(generator, audio[::-1])
    generator.reset(5)
    np.testing.assert_array_equal(run(generator, audio), expected)
    generator.reset(5)
    generator.reset(5)
    np.testing.assert_array_equal(run(generator, audio), expected)


def test_guidance_one_equals_the_conditional_row_of_the_batched_call(bundle, audio):
    conditional_only = make(bundle, style=HAPPY, guidance=1.0, seed=1)
    batched = make(bundle, style=HAPPY, guidance=1.0, seed=1)
    batched.layout = row_layout(batched.style_embedding, None, 1.0, guidance=2.0)  # null row computed but s = 1
    batched.reset(1)
    assert conditional_only.layout.batch == 1 and batched.layout.batch == 2
    np.testing.assert_allclose(run(batched, audio), run(conditional_only, audio), atol=1e-5)
    guided = latents(make(bundle, style=HAPPY, guidance=3.0, seed=1), audio)
    assert np.abs(guided - latents(make(bundle, style=HAPPY, guidance=1.0, seed=1), audio)).max() > 1e-4


def test_style_strength_scales_the_guidance_and_zero_gives_the_null_style_for_every_style(bundle, audio):
    doubled = make(bundle, style=HAPPY, guidance=1.5, style_strength=2.0, seed=1)
    assert doubled.guidance == 3.0 and doubled.base_guidance == 1.5
    np.testing.assert_array_equal(latents(doubled, audio), latents(make(bundle, style=HAPPY, guidance=3.0, seed=1),
                                                                   audio))
    # k = 0: x̂0 = D(∅) whatever the style (no audio guidance, which would look at the style's own row)
    neutral = {style: latents(make(bundle, style=style, style_strength=0.0, audio_guidance=1.0, seed=1), audio)
               for style in (HAPPY, OLD)}
    np.testing.assert_allclose(neutral[HAPPY], neutral[OLD], atol=1e-5)
    assert np.abs(latents(make(bundle, style=HAPPY, audio_guidance=1.0, seed=1), audio) - neutral[HAPPY]).max() > 1e-4


def test_gamma_one_equals_style_one(bundle, audio):
    style_one = make(bundle, style=HAPPY, guidance=1.5, seed=2)
    mixed = make(bundle, style=HAPPY, second_style=OLD, gamma=1.0, guidance=1.5, seed=2)
    # the c2 row is computed, but γ = 1 gives it no weight
    mixed.layout = row_layout(mixed.style_embedding, mixed.second_style_embedding, 0.5, guidance=1.5)
    mixed.reset(2)
    assert mixed.layout.batch == 3
    np.testing.assert_allclose(run(mixed, audio), run(style_one, audio), atol=1e-5)


def test_gamma_interpolates_and_extrapolates_between_styles(bundle, audio):
    outputs = {g: latents(make(bundle, style=HAPPY, second_style=OLD, gamma=g, seed=2), audio) for g in (0.0, 0.5, 2.0)}
    assert all(np.isfinite(o).all() for o in outputs.values())
    assert np.abs(outputs[0.5] - outputs[0.0]).max() > 1e-4 and np.abs(outputs[2.0] - outputs[0.5]).max() > 1e-4


def test_free_text_style_and_unknown_label(bundle, audio):
    text = latents(make(bundle, style=StylePrompt.parse("text:slow, calm and sleepy"), seed=0), audio)
    label = latents(make(bundle, style=HAPPY, seed=0), audio)
    assert np.isfinite(text).all() and np.abs(text - label).max() > 1e-4
    with pytest.raises(UserError, match="known styles: .*happy"):
        make(bundle, style=StylePrompt.parse("no-such-style"))


def test_style_and_guidance_change_while_running(bundle, audio):
    generator = make(bundle, style=HAPPY, seed=0)
    generator.step(audio[0], True)
    generator.set_style(OLD, second_style=HAPPY, gamma=0.5)
    assert generator.layout.batch == 3
    generator.set_guidance(1.0)
    assert generator.layout.batch == 2
    frames = generator.step(audio[1], False)
    assert np.isfinite(frames).all() and len(generator.history) == 2


def test_seed_gesture_prefills_history_and_changes_the_start(bundle, audio):
    rng = np.random.default_rng(0)
    clip = bundle.motion_stats.denormalize(rng.standard_normal((3 * bundle.frames_per_latent + 1, FEATURE_DIM)))
    plain = make(bundle, seed=0)
    seeded = make(bundle, seed=0)
    seeded.reset(0, seed_pose=clip)
    assert len(seeded.history) == min(3, bundle.denoiser_config.window)
    assert np.abs(latents(seeded, audio) - latents(plain, audio)).max() > 1e-4
    with pytest.raises(UserError, match="seed gesture"):
        seeded.reset(0, seed_pose=clip[:1])


def test_full_ddpm_path_runs_on_the_same_model(bundle, audio):
    generator = make(bundle, sampler=SamplerConfig("ddpm", 1000), seed=0)
    frames = generator.step(audio[0], True)
    assert np.isfinite(frames).all()


def test_motion_clip_as_style_prompt(tiny_model, bundle, audio):
    clip = tiny_model[1].parent / "zeggs" / "001_Neutral_0_x_1_0.bvh"
    generator = make(bundle, style=StylePrompt.parse(f"motion:{clip}"), seed=0)
    np.testing.assert_allclose(np.linalg.norm(generator.layout.styles[0]), 1.0, atol=1e-5)
    assert np.isfinite(run(generator, audio)).all()
    with pytest.raises(UserError, match="not found"):
        make(bundle, style=StylePrompt.parse("motion:/no/such/clip.bvh"))


def test_audio_guidance_one_equals_no_audio_null_row(bundle, audio):
    plain = make(bundle, style=HAPPY, guidance=1.5, seed=6)
    with_row = make(bundle, style=HAPPY, guidance=1.5, seed=6)
    with_row.layout = row_layout(with_row.style_embedding, None, 1.0, 1.5, audio_guidance=2.0)  # row computed, s_a = 1
    with_row.reset(6)
    assert with_row.layout.batch == 3 and with_row.layout.hears_audio.tolist() == [1.0, 1.0, 0.0]
    np.testing.assert_allclose(run(with_row, audio), run(plain, audio), atol=1e-5)


def test_audio_guidance_scales_the_effect_of_the_speech_exactly_on_a_first_one_step_latent(bundle, audio):
    """K = 1, no history: the latent is the guided x0 = D(a) + (s_a − 1)(D(a) − D(∅a)), and D(∅a) does not
    depend on the audio, so the difference between two audio windows grows exactly by s_a."""
    one_step = SamplerConfig("ddim", 1)

    def first_latent(scale: float, window: np.ndarray) -> np.ndarray:
        return make(bundle, sampler=one_step, guidance=1.0, audio_guidance=scale, seed=8).denoise(window, True)

    plain = first_latent(1.0, audio[0]) - first_latent(1.0, audio[1])
    assert np.abs(plain).max() > 1e-3
    np.testing.assert_allclose(first_latent(3.0, audio[0]) - first_latent(3.0, audio[1]), 3.0 * plain, atol=1e-4)


def test_prepared_conditions_give_the_same_latents_from_one_condition_call(bundle, audio):
    plain = latents(make(bundle, seed=3), audio)
    prepared = make(bundle, seed=3)
    calls = []
    graph = prepared.denoiser.condition_session
    prepared.denoiser.condition_session = type("Counted", (), {
        "run": lambda self, names, feeds: calls.append(feeds) or graph.run(names, feeds)})()
    prepared.prepare(list(audio), True)
    np.testing.assert_array_equal(latents(prepared, audio), plain)
    assert len(calls) == 1  # every latent's condition came from the one prepared call
    prepared.prepare(list(audio[:2]), True)
    prepared.set_style(OLD)  # a new style layout: the prepared conditions no longer apply
    prepared.denoise(audio[0], True)
    assert len(calls) == 3  # the prepare call and one of the latent's own
    assert not np.array_equal(calls[-1]["style"], calls[-2]["style"])
