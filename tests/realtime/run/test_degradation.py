"""The live engine's degradation ladder on a simulated machine: a fake clock that the generator's work moves on.

Every burst is submitted as the live engine does (:class:`FrameRelease`), with the clock at the audio's arrival
plus the compute the test charges per denoiser call, so whether a latent is late is decided, not measured."""

import numpy as np
import pytest

from gesturecast.models.audio.files import SAMPLE_RATE
from gesturecast.models.generator.diffusion import SamplerConfig
from gesturecast.models.motion.rotations import quat_conj, quat_mul, quat_to_axis_angle
from gesturecast.realtime.audio.sources import FastFileSource
from gesturecast.realtime.generation.degradation import RUNGS
from gesturecast.realtime.generation.generator import Generator, GeneratorSettings
from gesturecast.realtime.pose.session import GestureSession, SessionConfig
from gesturecast.realtime.run.engine import STAGE_MARGIN_USED, FrameRelease, run_offline
from gesturecast.realtime.timing.clock import FakeClock
from gesturecast.realtime.timing.latency import LatencyBudget
from gesturecast.realtime.timing.scheduler import SchedulerConfig

SECONDS = 8.0
CHUNK = 512
MARGIN_MS = 100.0
ASKED = {"sampler": SamplerConfig("ddim", 2), "guidance": 1.5, "audio_guidance": 1.5, "seed": 1}
ROW_STEP_S = 0.03  # charged per denoiser row and DDIM step: the full rung (3 rows × 2 steps) costs 180 ms a latent
BUSY_UNTIL_S = 2.0  # in the busy-then-idle run, work costs that much until this stream time, nothing after


@pytest.fixture(scope="module")
def speech(speech_cut):
    return speech_cut(SECONDS)


def make_session(bundle, clock) -> GestureSession:
    generator = Generator(bundle, GeneratorSettings(**ASKED))
    budget = LatencyBudget(bundle.frames_per_latent, generator.lookahead, MARGIN_MS)
    return GestureSession(bundle, generator, budget, clock, SessionConfig())


def charge_compute(session: GestureSession, clock: FakeClock, busy: callable) -> None:
    """Each denoiser call moves the clock by its rows × steps × ROW_STEP_S while ``busy(stream seconds)``."""
    generator = session.generator
    denoise = generator.denoise

    def timed(*args, **kwargs):
        if busy(session.next_latent * session.denoiser_config.frames_per_latent / session.fps):
            clock.advance(generator.layout.batch * len(generator._plan) * ROW_STEP_S)
        return denoise(*args, **kwargs)

    generator.denoise = timed


def paced_run(bundle, speech, busy, adapt: bool = True) -> tuple[list, FrameRelease]:
    """Chunks arrive at their capture time (the clock waits for them unless the work made it late)."""
    clock = FakeClock()
    session = make_session(bundle, clock)
    charge_compute(session, clock, busy)
    release = FrameRelease(session, lambda frame: None, clock, SchedulerConfig(paced=True), adapt)
    frames = []
    for chunk in FastFileSource(speech, chunk_samples=CHUNK):
        clock.sleep_until(chunk.capture_time + len(chunk.samples) / SAMPLE_RATE)
        burst = session.push(chunk)
        release.submit(burst)
        frames.extend(burst)
    return frames, release


def poses(frames) -> np.ndarray:
    return np.stack([np.concatenate([f.rotations.ravel(), f.root_position]) for f in frames])


def max_step_degrees(frames) -> np.ndarray:
    rotations = np.stack([f.rotations for f in frames])  # (T, J, 4)
    delta = quat_mul(quat_conj(rotations[:-1]), rotations[1:])
    return np.degrees(np.linalg.norm(quat_to_axis_angle(delta), axis=-1)).max(axis=-1)  # (T-1,)


def test_a_run_that_is_never_late_is_bit_for_bit_the_offline_run_on_the_full_rung(bundle, speech):
    frames, release = paced_run(bundle, speech, busy=lambda t: False)
    offline, _ = run_offline(make_session(bundle, FakeClock()), FastFileSource(speech, chunk_samples=CHUNK))
    np.testing.assert_array_equal(poses(frames), poses(offline[: len(frames)]))
    assert release.ladder.counts[1:] == [0] * (len(RUNGS) - 1) and release.ladder.changes == 0
    assert release.ladder_report()["bursts_per_rung"][0] == len(frames) // bundle.frames_per_latent


def test_a_machine_too_slow_for_the_full_work_steps_down_until_the_latents_fit(bundle, speech):
    _, release = paced_run(bundle, speech, busy=lambda t: True)
    assert release.ladder.rung == len(RUNGS) - 1
    generator = release.session.generator
    assert generator.audio_guidance == 1.0 and len(generator._plan) == 1
    assert generator.settings.audio_guidance == ASKED["audio_guidance"]  # what was asked stays, to come back to
    (worst_recent_ms,) = release.session.stats.percentiles_ms(STAGE_MARGIN_USED, (100.0,), last=10)
    assert worst_recent_ms < MARGIN_MS  # on the cheapest rung the latents are on time again


def test_it_climbs_back_to_the_asked_settings_when_the_machine_is_free_again_without_a_pop(bundle, speech):
    frames, release = paced_run(bundle, speech, busy=lambda t: t < BUSY_UNTIL_S)
    assert release.ladder.rung == 0 and max(release.ladder.counts[1:]) > 0 and release.ladder.changes >= 2
    generator = release.session.generator
    assert generator.audio_guidance == ASKED["audio_guidance"] and len(generator._plan) == ASKED["sampler"].steps
    unchanged, _ = run_offline(make_session(bundle, FakeClock()), FastFileSource(speech, chunk_samples=CHUNK))
    # the rung changes add no jump beyond what the motion itself does from frame to frame
    assert max_step_degrees(frames).max() < 1.5 * max_step_degrees(unchanged).max() + 1.0


def test_without_the_ladder_a_machine_too_slow_stays_late_and_says_so(bundle, speech):
    _, release = paced_run(bundle, speech, busy=lambda t: True, adapt=False)
    assert release.ladder is None and release.session.generator.rung == RUNGS[0]
    assert release.late_warning.warnings >= 1


def test_an_unpaced_run_never_degrades(bundle, speech):
    clock = FakeClock()
    session = make_session(bundle, clock)
    release = FrameRelease(session, lambda frame: None, clock, SchedulerConfig(paced=False))
    assert release.ladder is None and release.ladder_report() == {}


def test_each_rung_drops_its_work_and_rung_0_restores_what_was_asked(bundle):
    generator = Generator(bundle, GeneratorSettings(**ASKED))
    seen = []
    for rung in (1, 2, 1, 0):
        generator.degrade(RUNGS[rung])
        seen.append((generator.audio_guidance, len(generator._plan), generator.layout.batch))
    assert seen == [(1.5, 1, 3), (1.0, 1, 2), (1.5, 1, 3), (1.5, 2, 3)]
    assert generator.settings == Generator(bundle, GeneratorSettings(**ASKED)).settings
