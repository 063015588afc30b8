"""A cued gesture is carried out by the generator: its part channels are inpainted at every sampler step (the
committed latents hold the clip's channels where the weight is 1), the other parts stay generated, frames name
the gesture, and streaming = offline holds with cues."""

import numpy as np
import pytest

from gesturecast.controls import parse_controls
from gesturecast.models.audio.files import PACKAGED_SAMPLE, SAMPLE_RATE, load_audio
from gesturecast.realtime.audio.sources import AudioChunk
from gesturecast.realtime.gestures.cues import RAMP_LATENTS, Cue, GestureClip
from gesturecast.realtime.gestures.repertoire import GestureRepertoire
from gesturecast.realtime.run.engine_setup import SessionFactory, build_session
from gesturecast.realtime.timing.clock import MonotonicClock
from gesturecast.settings import Settings

SECONDS = 4


@pytest.fixture(scope="module")
def speech() -> np.ndarray:
    return load_audio(PACKAGED_SAMPLE)[: SECONDS * SAMPLE_RATE]


def session_with(clip: GestureClip):
    factory = SessionFactory(Settings(gestures=None))
    factory.repertoire = GestureRepertoire((clip,))
    return factory.session(MonotonicClock())


def run(session, speech: np.ndarray, block: int) -> list:
    frames = []
    for start in range(0, speech.shape[0], block):
        frames += session.push(AudioChunk(speech[start : start + block], start, start / SAMPLE_RATE))
    return frames + session.finish()


@pytest.fixture(scope="module")
def clip() -> GestureClip:
    session = build_session(Settings(gestures=None), MonotonicClock())
    channels = np.zeros(session.generator.latent_dim, bool)
    channels[session.bundle.part_channels["arms"]] = True
    latents = np.random.default_rng(1).normal(0.0, 1.5, (12, session.generator.latent_dim)).astype(np.float32)
    features = np.zeros((48, session.bundle.motion_feature_dim), np.float32)  # (N·d, D)
    return GestureClip("raise", latents, channels, 3, features, np.zeros(features.shape[1], bool))


def test_the_clip_channels_are_committed_and_the_other_parts_stay_generated(clip, speech):
    session = session_with(clip)
    assert session.gestures.cue(Cue("raise", 2.0, "hooray")).status == "on time"
    (placement,) = session.gestures.cues.placements
    run(session, speech, 512)
    history = [h.latent for h in session.generator.history]  # the last window of committed latents
    first = placement.first - (session.next_latent - len(history))
    full = [k for k in range(clip.num_latents) if RAMP_LATENTS <= k < clip.num_latents - RAMP_LATENTS]  # weight 1
    assert full
    for k in full:
        assert np.allclose(history[first + k][clip.channels], clip.latents[k, clip.channels], atol=1e-5)
        assert not np.allclose(history[first + k][~clip.channels], clip.latents[k, ~clip.channels], atol=0.1)


def test_frames_name_the_gesture_and_streaming_equals_offline_with_cues(clip, speech):
    runs = []
    for block in (SAMPLE_RATE, 333):
        session = session_with(clip)
        session.gestures.cue(Cue("raise", 2.0, "hooray"))
        runs.append(run(session, speech, block))
    assert np.array_equal(np.stack([f.rotations for f in runs[0]]), np.stack([f.rotations for f in runs[1]]))
    named = [f.seq for f in runs[0] if f.gesture == "raise"]
    assert named == list(range(named[0], named[0] + clip.num_latents * 4))
    stroke_time = (named[0] + clip.stroke_latent * 4) / 30
    assert abs(stroke_time - 2.0) < 4 / 30


def test_a_gesture_control_is_checked_on_submit_and_placed_at_the_next_latent(clip, speech):
    from gesturecast.errors import UserError

    session = session_with(clip)
    with pytest.raises(UserError, match="unknown gesture 'wave'"):
        session.controls.submit(parse_controls({"gesture": "wave"}))
    session.push(AudioChunk(speech[:SAMPLE_RATE], 0, 0.0))
    waiting = session.next_latent
    notes = session.controls.submit(parse_controls({"gesture": "raise"}))  # the ack: when the stroke shows (L + 0.4 s)
    assert 0 < notes["gesture_stroke_in_ms"] < (session.budget.total_s + 1.0) * 1e3
    frames = session.push(AudioChunk(speech[SAMPLE_RATE:], SAMPLE_RATE, 1.0)) + session.finish()
    assert min(f.seq for f in frames if f.gesture) == waiting * 4
