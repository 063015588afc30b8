"""The gesture-size dial (``intensity``) and ``pause``: 0 is the idle, breathing pose, 1 the stream bit for bit,
monotonic in between and up to 2; both change live without a pop."""

import numpy as np
import pytest

from gesturecast.controls import parse_controls
from gesturecast.models.audio.files import SAMPLE_RATE
from gesturecast.models.generator.diffusion import SamplerConfig
from gesturecast.models.motion.rotations import quat_conj, quat_mul, quat_to_axis_angle
from gesturecast.models.motion.skeleton import CANONICAL, CANONICAL_WITH_HANDS
from gesturecast.realtime.audio.sources import FastFileSource
from gesturecast.realtime.generation.generator import Generator, GeneratorSettings
from gesturecast.realtime.pose.idle import IdleMotion
from gesturecast.realtime.pose.session import GestureSession, SessionConfig
from gesturecast.realtime.timing.clock import FakeClock
from gesturecast.realtime.timing.latency import LatencyBudget

SEED = 1
ARMS = ("LeftUpperArm", "LeftLowerArm", "RightUpperArm", "RightLowerArm")
CHUNK = 1600  # 0.1 s
FPS = 30.0


def make_session(bundle, **config) -> GestureSession:
    generator = Generator(bundle, GeneratorSettings(sampler=SamplerConfig("ddim", 2), seed=SEED))
    budget = LatencyBudget(bundle.frames_per_latent, generator.lookahead, 100.0, smoothing_frames=1)
    return GestureSession(bundle, generator, budget, FakeClock(), SessionConfig(**config))


def run(bundle, speech, controls: dict[float, dict] | None = None, **config) -> list:
    """The frames of one offline run; ``controls``: stream second → control fields submitted then."""
    session = make_session(bundle, **config)
    frames = []
    for chunk in FastFileSource(speech, chunk_samples=CHUNK):
        for second, fields in (controls or {}).items():
            if chunk.start_sample == round(second * SAMPLE_RATE):
                session.controls.submit(parse_controls(fields))
        frames.extend(session.push(chunk))
    return frames + session.finish()


def bodies(frames) -> np.ndarray:
    """(T, J, 4) body rotations (the fingers left out)."""
    return np.stack([frame.rotations[: CANONICAL.num_joints] for frame in frames])


def arm_speed_deg_s(rotations: np.ndarray) -> float:
    """Mean angular speed of the upper and lower arms' local rotations (T, J, 4), in degrees per second."""
    arms = rotations[:, [CANONICAL.index(name) for name in ARMS]]  # (T, 4, 4)
    steps = quat_to_axis_angle(quat_mul(quat_conj(arms[:-1]), arms[1:]))  # (T-1, 4, 3)
    return float(np.degrees(np.linalg.norm(steps, axis=-1)).mean() * FPS)


def idle_rotations(frames) -> np.ndarray:
    """The idle, breathing pose (T, J, 4) at the frames' stream times."""
    return IdleMotion(seed=SEED).rotations(np.array([frame.seq for frame in frames]) / FPS)


def max_step_degrees(frames) -> np.ndarray:
    """Largest joint rotation change between consecutive frames, per frame (degrees)."""
    rotations = np.stack([frame.rotations for frame in frames])  # (T, J, 4)
    steps = quat_to_axis_angle(quat_mul(quat_conj(rotations[:-1]), rotations[1:]))
    return np.degrees(np.linalg.norm(steps, axis=-1)).max(axis=-1)  # (T-1,)


def largest_speed_jump(frames) -> float:
    """The largest change of the per-frame joint step between consecutive frames (degrees): a pop jumps by tens of
    degrees; a ramp, however far the pose goes, speeds up and slows down smoothly (the smoothstep)."""
    return float(np.abs(np.diff(max_step_degrees(frames))).max())


def test_size_1_is_the_stream_bit_for_bit(bundle, speech):
    plain = run(bundle, speech)
    told = run(bundle, speech, {1.0: {"intensity": 1.0}}, intensity=1.0)
    for field in ("rotations", "root_position"):
        np.testing.assert_array_equal(np.stack([getattr(f, field) for f in told]),
                                      np.stack([getattr(f, field) for f in plain]))
    assert plain[0].rotations.shape == (CANONICAL_WITH_HANDS.num_joints, 4)


def test_size_0_is_the_idle_pose_and_arm_speed_grows_with_the_size(bundle, speech):
    speeds = {size: arm_speed_deg_s(bodies(run(bundle, speech, intensity=size))) for size in (0.0, 0.5, 1.0, 2.0)}
    still = run(bundle, speech, intensity=0.0)
    np.testing.assert_allclose(bodies(still), idle_rotations(still), atol=1e-9)
    assert speeds[0.0] == pytest.approx(arm_speed_deg_s(idle_rotations(still)), rel=1e-6)
    assert speeds[0.0] < speeds[0.5] < speeds[1.0] < speeds[2.0], speeds
    assert {f.speaking for f in still} == {False, True}  # the voice, the mouth and the face go on as before


def test_pause_sends_the_body_to_idle_and_back_without_a_pop(bundle, speech):
    frames = run(bundle, speech, {1.0: {"pause": True}, 2.5: {"pause": False}})
    plain = run(bundle, speech)
    seconds = np.array([frame.seq for frame in frames]) / FPS
    # a control applies at the next latent generated, a look-ahead before the newest audio: the pause from about
    # 0.7 s, ramped over half a second, the resume from about 2.2 s
    paused = (seconds > 1.5) & (seconds < 2.0)
    np.testing.assert_allclose(bodies(frames)[paused], idle_rotations(frames)[paused], atol=1e-9)
    np.testing.assert_array_equal(bodies(frames)[-10:], bodies(plain)[-10:])  # back to the stream as it was
    assert largest_speed_jump(frames) < 2.0 * largest_speed_jump(plain) + 1.0


@pytest.mark.parametrize("size", [0.0, 2.0])
def test_a_live_size_change_blends_in_without_a_pop(bundle, speech, size):
    frames = run(bundle, speech, {2.0: {"intensity": size}})
    plain = run(bundle, speech)
    change = round(2.0 * FPS)  # about: the control applies a look-ahead earlier
    window = slice(change - 20, change + 20)
    assert largest_speed_jump(frames[window]) < 2.0 * largest_speed_jump(plain) + 1.0
    assert np.abs(bodies(frames)[-1] - bodies(plain)[-1]).max() > 1e-3  # and it took effect
