"""The stylizer after the generator: streaming = offline bit for bit, strength 0 and neutral leave the generator's
motion untouched, every way to give a style reaches it, live changes blend in."""

import numpy as np
import pytest
import soundfile

from gesturecast.controls import parse_controls
from gesturecast.errors import UserError
from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.models.generator.diffusion import SamplerConfig
from gesturecast.models.generator.style_prompt import StylePrompt
from gesturecast.models.motion.skeleton import NUM_JOINTS
from gesturecast.models.runtime.bundle import ModelBundle
from gesturecast.models.style.descriptors import clip_descriptor
from gesturecast.models.style.joint_limits import MARGIN, JointRanges
from gesturecast.models.style.params import (
    DEFAULT_STYLE_PARAMS,
    STYLED_INDEX,
    STYLED_JOINTS,
    TENSION,
    StyleBook,
    part_rows,
)
from gesturecast.realtime.audio.sources import FastFileSource, PacedFileSource
from gesturecast.realtime.generation.generator import Generator, GeneratorSettings
from gesturecast.realtime.pose.session import GestureSession, SessionConfig
from gesturecast.realtime.pose.stylizer import StyleCodes
from gesturecast.realtime.run.engine import run_offline
from gesturecast.realtime.timing.clock import FakeClock
from gesturecast.realtime.timing.latency import LatencyBudget
from gesturecast.settings import DEFAULT_MODEL_DIR

SECONDS = 6.0


@pytest.fixture(scope="module")
def bundle():
    return ModelBundle.load(DEFAULT_MODEL_DIR)


@pytest.fixture(scope="module")
def speech(tmp_path_factory, shared_data):
    """6 s of real speech (ZeroEGGS 067 from 3 s) as a 16 kHz WAV."""
    audio = load_audio(shared_data / "zeggs" / "067_Speech_2_x_1_0.wav")[3 * SAMPLE_RATE:][: int(SECONDS * SAMPLE_RATE)]
    path = tmp_path_factory.mktemp("speech") / "speech.wav"
    soundfile.write(path, audio, SAMPLE_RATE, subtype="FLOAT")
    return path


def make_session(bundle, style="angry", clock=None, stylizer=True, **settings) -> GestureSession:
    settings = {"sampler": SamplerConfig("ddim", 2), "seed": 1, "style": StylePrompt.parse(style), **settings}
    generator = Generator(bundle, GeneratorSettings(**settings))
    budget = LatencyBudget(bundle.frames_per_latent, generator.lookahead, 100.0, smoothing_frames=1)
    config = SessionConfig(style_params=DEFAULT_STYLE_PARAMS if stylizer else None)
    return GestureSession(bundle, generator, budget, clock or FakeClock(), config)


def poses(frames) -> np.ndarray:
    return np.stack([np.concatenate([f.rotations.ravel(), f.root_position]) for f in frames])


def run(session, speech, chunk_samples=16000, controls=()) -> list:
    """Frames of ``speech`` pushed in chunks; ``controls`` (sample, control) are submitted at those samples."""
    frames = []
    for chunk in FastFileSource(speech, chunk_samples=chunk_samples):
        for sample, control in controls:
            if chunk.start_sample <= sample < chunk.start_sample + len(chunk.samples):
                session.controls.submit(parse_controls(control))
        frames.extend(session.push(chunk))
    return frames + session.finish()


def test_a_styled_stream_with_a_live_change_is_offline_bit_for_bit_at_any_chunking(bundle, speech):
    change = [(2 * SAMPLE_RATE, {"style": "sad"})]
    offline = run(make_session(bundle), speech, 16000, change)
    odd = run(make_session(bundle), speech, 1600, change)
    np.testing.assert_array_equal(poses(offline), poses(odd))
    clock = FakeClock(100.0)
    paced, _ = run_offline(make_session(bundle, clock=clock), PacedFileSource(speech, chunk_samples=512, clock=clock))
    plain, _ = run_offline(make_session(bundle), FastFileSource(speech, chunk_samples=16000))
    np.testing.assert_array_equal(poses(paced), poses(plain))


@pytest.mark.parametrize("style, strength", [("angry", 0.0), ("neutral", 1.0)])
def test_strength_zero_and_neutral_leave_the_generators_motion_bit_for_bit(bundle, speech, style, strength):
    styled = run(make_session(bundle, style, style_strength=strength), speech)
    unstyled = run(make_session(bundle, style, stylizer=False, style_strength=strength), speech)
    np.testing.assert_array_equal(poses(styled), poses(unstyled))


def descriptor(frames) -> np.ndarray:
    rotations = np.stack([f.rotations for f in frames])
    return clip_descriptor(rotations, np.stack([f.root_position for f in frames]), 30.0)


def test_styles_move_the_body_as_their_takes_do(bundle, speech):
    """Sad and old make smaller, slower gestures than the generator's; sad bows the head; strength 2 goes further."""
    plain = descriptor(run(make_session(bundle, "sad", stylizer=False), speech))
    sad, sad2 = (descriptor(run(make_session(bundle, "sad", style_strength=k), speech)) for k in (1.0, 2.0))
    plain2 = descriptor(run(make_session(bundle, "sad", stylizer=False, style_strength=2.0), speech))
    wrist_speed, head_pitch = 0, 6
    assert sad[wrist_speed] < 0.8 * plain[wrist_speed]
    assert sad[head_pitch] > plain[head_pitch] + 0.1
    assert sad2[head_pitch] - plain2[head_pitch] > sad[head_pitch] - plain[head_pitch]


def max_step_degrees(frames) -> np.ndarray:
    rotations = np.stack([f.rotations for f in frames])  # (T, J, 4)
    dots = np.abs(np.sum(rotations[1:] * rotations[:-1], axis=-1)).clip(0, 1)  # (T-1, J)
    return np.degrees(2 * np.arccos(dots)).max(axis=1)


def test_a_live_style_change_blends_in_without_a_pop(bundle, speech):
    frames = run(make_session(bundle, "neutral"), speech, 1600, [(3 * SAMPLE_RATE, {"style": "old"})])
    steps = max_step_degrees(frames)
    change = 90
    assert frames[-1].style == "old"
    assert steps[change - 5: change + 25].max() < 3.0 * np.percentile(steps[:change], 95) + 1.0


@pytest.fixture(scope="module")
def codes(bundle):
    generator = Generator(bundle, GeneratorSettings(sampler=SamplerConfig("ddim", 2)))
    return StyleCodes(StyleBook.load(DEFAULT_STYLE_PARAMS), generator.styles.embed)


def test_free_text_takes_the_nearest_styles_and_labels_the_book_lacks_are_left_to_the_generator(codes):
    labels = codes.book.labels
    assert labels[int(np.argmax(codes.weights(StylePrompt("text", "exhausted"))))] == "tired"
    assert labels[int(np.argmax(codes.weights(StylePrompt("text", "an elderly man"))))] == "old"
    text = StylePrompt("text", "furious")
    np.testing.assert_allclose(codes.params(text).values, sum(w * codes.book.styles[label].values
                                                              for w, label in zip(codes.weights(text), labels,
                                                                                  strict=True)))
    assert codes.params(StylePrompt("label", "laughing")).is_identity  # a paired speech style: the generator's
    np.testing.assert_array_equal(codes.params(StylePrompt("label", "elderly")).values, codes.book.styles["old"].values)
    with pytest.raises(UserError, match="unknown style 'grumpy'"):
        codes.params(StylePrompt("label", "grumpy"))


def test_the_generator_hears_its_own_speech_styles_and_neutral_for_the_stylizers(bundle):
    """build_session: a label the stylizer gives is heard as neutral at s; a paired speech style (speech, flirty),
    which only the generator learned, is heard as asked, at k·s."""
    from gesturecast.realtime.run.engine_setup import build_session
    from gesturecast.realtime.timing.clock import MonotonicClock
    from gesturecast.settings import Settings

    sessions = {style: build_session(Settings(style=style, style_strength=1.5), MonotonicClock())
                for style in ("neutral", "old", "speech", "flirty")}
    heard = {style: session.generator.style_embedding for style, session in sessions.items()}
    np.testing.assert_array_equal(heard["old"], heard["neutral"])
    for style in ("speech", "flirty"):
        np.testing.assert_array_equal(heard[style], bundle.styles.embedding(style))
        assert sessions[style].generator.guidance == pytest.approx(1.5 * bundle.default_guidance)
    assert sessions["old"].generator.guidance == pytest.approx(bundle.default_guidance)


def test_mixes_parts_and_strength_combine_the_fitted_styles(bundle, codes):
    from gesturecast.realtime.pose.stylizer import Stylizer

    stylizer = Stylizer(codes, 30.0)
    happy, sad, old = (codes.book.styles[name].values for name in ("happy", "sad", "old"))
    happy_p, sad_p = StylePrompt("label", "happy"), StylePrompt("label", "sad")
    np.testing.assert_allclose(stylizer.target(happy_p, sad_p, 0.25, (), 1.0), 0.25 * happy + 0.75 * sad)
    np.testing.assert_allclose(stylizer.target(happy_p, None, 1.0, (), 2.0), 2.0 * happy)
    arms = part_rows("arms")
    target = stylizer.target(happy_p, None, 1.0, (("arms", StylePrompt("label", "old")),), 1.0)
    np.testing.assert_array_equal(target[arms], old[arms])
    np.testing.assert_array_equal(target[~arms], happy[~arms])
    assert len(arms) == len(STYLED_JOINTS) and not part_rows("legs").any()
    assert not np.array_equal(happy[:, TENSION], sad[:, TENSION])


def test_a_broken_style_file_is_a_one_line_error(tmp_path):
    path = tmp_path / "styles.json"
    path.write_text('{"format": "something else"}')
    with pytest.raises(UserError, match="not a gesturecast-style-params-1 file"):
        StyleBook.load(path)
    with pytest.raises(UserError, match="not a readable"):
        StyleBook.load(tmp_path / "missing.json")


def test_the_products_generator_hears_neutral_and_a_live_strength_of_zero_gives_its_motion(speech):
    """build_session (every command's path): the denoiser hears ``neutral`` whatever the style, so once a live
    ``style_strength`` 0 has ramped in, "old" gives the neutral style's body bit for bit (the procedural fingers
    follow the body's motion with a fading memory, so they only converge)."""
    from gesturecast.realtime.run.engine_setup import build_session
    from gesturecast.realtime.timing.clock import MonotonicClock
    from gesturecast.settings import Settings

    old = build_session(Settings(style="old"), MonotonicClock())
    neutral = build_session(Settings(style="neutral"), MonotonicClock())
    np.testing.assert_array_equal(old.generator.style_embedding, neutral.generator.style_embedding)
    calmed = run(old, speech, 1600, [(SAMPLE_RATE, {"style_strength": 0.0})])
    plain = run(neutral, speech, 1600)
    settled = 2 * 30  # the control lands at 1 s and ramps over 0.5 s

    def bodies(frames) -> np.ndarray:
        return np.stack([np.concatenate([f.rotations[:NUM_JOINTS].ravel(), f.root_position]) for f in frames])

    assert not np.array_equal(bodies(calmed[:30]), bodies(plain[:30]))
    np.testing.assert_array_equal(bodies(calmed[settled:]), bodies(plain[settled:]))


def largest_angles(frames) -> dict[str, float]:
    """Each styled joint's largest local rotation angle over the frames, degrees."""
    rotations = np.stack([f.rotations for f in frames])[:, STYLED_INDEX]  # (T, S, 4)
    degrees = np.degrees(2 * np.arccos(np.abs(rotations[..., 3]).clip(0, 1))).max(axis=0)  # (S,)
    return dict(zip(STYLED_JOINTS, degrees, strict=True))


@pytest.mark.parametrize("door", ["settings", "live control"])
def test_an_extrapolated_mix_keeps_every_joint_within_a_human_range(bundle, speech, door):
    """γ = −2 of angry against tired turned the head backwards (neck and head at 179°), at every door: the session's
    stylizer keeps each joint within its range (or the generator's own pose, if further) plus the margin."""
    mix = {"style": "angry", "style2": "tired", "gamma": -2.0, "style_strength": 2.0}

    def frames(stylizer: bool) -> list:
        if door == "settings":
            return run(make_session(bundle, "angry", stylizer=stylizer, second_style=StylePrompt.parse("tired"),
                                    gamma=-2.0, style_strength=2.0), speech)
        return run(make_session(bundle, "neutral", stylizer=stylizer), speech, 16000, [(0, mix)])

    styled, given = largest_angles(frames(True)), largest_angles(frames(False))
    limits = np.degrees(JointRanges.load().angle + MARGIN)
    assert all(styled[joint] <= max(limit, given[joint] + np.degrees(MARGIN))
               for joint, limit in zip(STYLED_JOINTS, limits, strict=True)), styled
    assert styled["Neck"] < 90 and styled["Head"] < 90
