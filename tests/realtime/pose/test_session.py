"""The live session: offline = streaming, chunk-size invariance, complete output, live changes, idle."""

import numpy as np
import pytest
import soundfile

from gesturecast.controls import parse_controls
from gesturecast.models.audio.dsp import frame_boundary, frames_complete
from gesturecast.models.audio.files import PACKAGED_SAMPLE, SAMPLE_RATE, load_audio
from gesturecast.models.audio.streaming import extract_features, extract_visemes, speaking_flags
from gesturecast.models.generator.diffusion import SamplerConfig
from gesturecast.models.generator.style_prompt import StylePrompt
from gesturecast.models.motion.root_anchor import RootMode
from gesturecast.models.motion.rotations import quat_conj, quat_mul, quat_to_axis_angle
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS, NUM_JOINTS
from gesturecast.realtime.audio.sources import FastFileSource, PacedFileSource
from gesturecast.realtime.generation.generator import Generator, GeneratorSettings
from gesturecast.realtime.pose.session import GestureSession, SessionConfig
from gesturecast.realtime.run.engine import LiveEngine, run_offline
from gesturecast.realtime.run.engine_setup import build_session
from gesturecast.realtime.timing.clock import FakeClock, MonotonicClock
from gesturecast.realtime.timing.latency import LatencyBudget
from gesturecast.settings import LATENCY_SETTINGS, Settings

SECONDS = 4.0  # the speech fixture's length (conftest.py)
MIN_MEAN_FINGER_BEND_DEG = 5.0  # a relaxed hand: its finger joints bend by more than this on average
MIN_FINGER_MOTION_DEG = 0.5  # and move by more than this (standard deviation over the clip)


def make_session(bundle, clock=None, smoothing_frames=0, root_mode=RootMode.BOUNDED, lipsync="vrm0",
                 **settings) -> GestureSession:
    settings = {"sampler": SamplerConfig("ddim", 2), "guidance": 1.5, "seed": 1, **settings}
    generator = Generator(bundle, GeneratorSettings(**settings))
    budget = LatencyBudget(bundle.frames_per_latent, generator.lookahead, 100.0, smoothing_frames=smoothing_frames)
    return GestureSession(bundle, generator, budget, clock or FakeClock(),
                         SessionConfig(root_mode=root_mode, lipsync=lipsync))


def poses(frames) -> np.ndarray:
    return np.stack([np.concatenate([f.rotations.ravel(), f.root_position]) for f in frames])


@pytest.mark.parametrize("smoothing", [0, 2])
def test_offline_equals_paced_live_and_any_chunk_size(bundle, speech, smoothing):
    offline, _ = run_offline(make_session(bundle, smoothing_frames=smoothing),
                             FastFileSource(speech, chunk_samples=16000))
    clock = FakeClock(100.0)
    paced, _ = run_offline(make_session(bundle, clock, smoothing),
                           PacedFileSource(speech, chunk_samples=512, clock=clock))
    odd_chunks, _ = run_offline(make_session(bundle, smoothing_frames=smoothing),
                                FastFileSource(speech, chunk_samples=333))
    np.testing.assert_array_equal(poses(offline), poses(paced))
    np.testing.assert_array_equal(poses(offline), poses(odd_chunks))
    assert [f.seq for f in offline] == list(range(len(offline)))


@pytest.mark.parametrize("setting", list(LATENCY_SETTINGS))
def test_every_latency_setting_streams_exactly_as_offline_at_any_chunk_size(bundle, speech, setting):
    """The tiny preset trains with look-ahead truncation, so one bundle serves low, balanced and quality."""
    lookahead = LATENCY_SETTINGS[setting].lookahead_for(bundle.audio_lookahead)
    offline, _ = run_offline(make_session(bundle, lookahead=lookahead), FastFileSource(speech, chunk_samples=16000))
    clock = FakeClock(100.0)
    paced, _ = run_offline(make_session(bundle, clock, lookahead=lookahead),
                           PacedFileSource(speech, chunk_samples=512, clock=clock))
    odd_chunks, _ = run_offline(make_session(bundle, lookahead=lookahead), FastFileSource(speech, chunk_samples=333))
    np.testing.assert_array_equal(poses(offline), poses(paced))
    np.testing.assert_array_equal(poses(offline), poses(odd_chunks))
    assert len(offline) == frames_complete(int(SECONDS * SAMPLE_RATE), SAMPLE_RATE, 30)
    if setting != "quality":
        quality, _ = run_offline(make_session(bundle), FastFileSource(speech, chunk_samples=16000))
        assert not np.allclose(poses(offline), poses(quality))  # the look-ahead changes what the model hears


def test_a_low_latency_session_makes_a_latent_once_its_own_audio_has_arrived(bundle):
    """δ = 0: latent 0 needs the audio of frames [0, d) only; at δa it waits δa frames more."""
    d = bundle.frames_per_latent
    first_latent_audio = np.zeros(int(frame_boundary(d, SAMPLE_RATE, 30)), np.float32)
    low = make_session(bundle, lookahead=0)
    quality = make_session(bundle)
    assert len(low.push(_chunk(first_latent_audio, 0))) == d
    assert quality.push(_chunk(first_latent_audio, 0)) == []


def test_each_frame_carries_the_visemes_of_its_own_audio_instant(bundle, speech):
    session = make_session(bundle, smoothing_frames=2)
    frames, _ = run_offline(session, FastFileSource(speech, chunk_samples=333))
    expected = extract_visemes(load_audio(speech), config=bundle.feature_config)  # (T, 5), audio frame k = row k
    np.testing.assert_array_equal(np.stack([f.visemes for f in frames]), expected)
    assert expected.sum(axis=1).max() > 0.5  # speech opens the mouth
    assert session.viseme_names == ("A", "I", "U", "E", "O")


FLAG_EDGE_TOLERANCE_FRAMES = 3  # 100 ms


def flag_edges(flags: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Frame indices where a (T,) bool flag turns on, and where it turns off."""
    steps = np.diff(flags.astype(int), prepend=0)
    return np.flatnonzero(steps == 1), np.flatnonzero(steps == -1)


def test_the_speaking_flag_follows_its_own_frames_voice_activity_not_the_idle_fade(tmp_path):
    """The packaged sample with two 1.5 s silences inserted, on the default model: each frame's flag turns on and
    off with the VAD's decision for that audio frame (within 100 ms; in fact exactly), not 0.3 s early and 1 s
    late as the idle cross-fade's look-ahead decision does; the same flags at any chunk size."""
    sample = load_audio(PACKAGED_SAMPLE)
    gap = np.zeros(int(1.5 * SAMPLE_RATE), np.float32)
    audio = np.concatenate([gap, sample[: 4 * SAMPLE_RATE], gap, sample[4 * SAMPLE_RATE : 7 * SAMPLE_RATE], gap])
    path = tmp_path / "gaps.wav"
    soundfile.write(path, audio, SAMPLE_RATE, subtype="FLOAT")
    runs = [run_offline(build_session(Settings(), FakeClock()), FastFileSource(path, chunk_samples=chunk))[0]
            for chunk in (16000, 333)]
    flags = np.array([f.speaking for f in runs[0]])  # (T,)
    assert [f.speaking for f in runs[1]] == flags.tolist()  # streaming = offline
    session = build_session(Settings(), FakeClock())
    vad = speaking_flags(extract_features(audio, session.bundle.feature_config), session.bundle.feature_config)
    vad = vad[: len(flags)]  # (T,) the VAD's per-frame decision, its 267 ms hangover included
    (vad_on, vad_off), (on, off) = flag_edges(vad), flag_edges(flags)
    assert len(vad_on) >= 2 and len(on) == len(vad_on) and len(off) == len(vad_off)  # the gaps are silent
    assert np.abs(on - vad_on).max() <= FLAG_EDGE_TOLERANCE_FRAMES
    assert np.abs(off - vad_off).max() <= FLAG_EDGE_TOLERANCE_FRAMES
    assert np.array_equal(flags, vad)


def test_lipsync_off_leaves_the_visemes_out(bundle, speech):
    session = make_session(bundle, lipsync="off")
    frames, _ = run_offline(session, FastFileSource(speech, chunk_samples=16000))
    assert frames and all(f.visemes is None for f in frames) and session.viseme_names == ()


@pytest.mark.parametrize("smoothing", [0, 1])
def test_every_complete_audio_frame_gets_one_pose_with_fixed_latency(bundle, speech, smoothing):
    clock = FakeClock(50.0)
    session = make_session(bundle, clock, smoothing)
    frames, _ = run_offline(session, PacedFileSource(speech, chunk_samples=512, clock=clock))
    assert len(frames) == frames_complete(int(SECONDS * SAMPLE_RATE), SAMPLE_RATE, 30)
    latency = np.array([f.presentation_time - f.capture_time for f in frames])
    np.testing.assert_allclose(latency, session.budget.total_s, atol=1e-9)
    assert session.budget.total_ms == pytest.approx(500.0 + smoothing * 1000 / 30)
    np.testing.assert_allclose(np.diff([f.capture_time for f in frames]), 1 / 30, atol=1 / SAMPLE_RATE)
    assert frames[0].capture_time == pytest.approx(50.0)


def test_seeds_give_different_gestures(bundle, speech):
    first, _ = run_offline(make_session(bundle, seed=1), FastFileSource(speech))
    second, _ = run_offline(make_session(bundle, seed=2), FastFileSource(speech))
    assert np.abs(poses(first) - poses(second)).max() > 1e-3


def max_step_degrees(frames) -> np.ndarray:
    """Largest joint rotation change between consecutive frames, per frame (degrees)."""
    rotations = np.stack([f.rotations for f in frames])  # (T, J, 4)
    delta = quat_mul(quat_conj(rotations[:-1]), rotations[1:])
    return np.degrees(np.linalg.norm(quat_to_axis_angle(delta), axis=-1)).max(axis=-1)  # (T-1,)


def test_style_change_blends_in_without_a_pop(bundle, speech):
    session = make_session(bundle, style=StylePrompt("label", "neutral"))
    frames = []
    for index, chunk in enumerate(FastFileSource(speech, chunk_samples=1600)):
        if index == 20:  # 2 s in
            session.controls.submit(parse_controls({"style": "old", "guidance": 2.5}))
        frames.extend(session.push(chunk))
    frames.extend(session.finish())
    assert frames[-1].style == "old"
    assert session.generator.settings.second_style is None  # the blend finished and dropped the old style
    assert session.generator.guidance == pytest.approx(2.5)
    steps = max_step_degrees(frames)
    change = 60  # frame of the change (2 s)
    assert steps[change - 5 : change + 20].max() < 3.0 * np.percentile(steps[:change], 95) + 1.0


def frames_with_a_style_change(bundle, speech, chunk_samples: int) -> list:
    """The frames of a neutral session told "happy" after 2 s of audio, pushed in chunks of ``chunk_samples``."""
    session = make_session(bundle, style=StylePrompt("label", "neutral"))
    frames = []
    for chunk in FastFileSource(speech, chunk_samples=chunk_samples):
        if chunk.start_sample == 2 * SAMPLE_RATE:
            session.controls.submit(parse_controls({"style": "happy"}))
        frames.extend(session.push(chunk))
    return frames + session.finish()


def test_a_push_of_many_latents_builds_every_frame_as_one_latent_at_a_time_does(bundle, speech):
    """A one-second push (generate's) builds its latents' poses in batches, split where the style changes: the poses,
    the style each frame names and the face weights equal a live stream's 31 ms pushes, through a style change."""
    live = frames_with_a_style_change(bundle, speech, 500)
    batched = frames_with_a_style_change(bundle, speech, 16000)
    np.testing.assert_array_equal(poses(batched), poses(live))
    np.testing.assert_array_equal(np.stack([f.face for f in batched]), np.stack([f.face for f in live]))
    assert [f.style for f in batched] == [f.style for f in live]
    assert {f.style for f in live} >= {"neutral", "happy"}


def test_audio_guidance_ramps_in_and_out_live_without_a_pop(bundle, speech):
    session = make_session(bundle, audio_guidance=1.0)
    frames, rows = [], []
    for index, chunk in enumerate(FastFileSource(speech, chunk_samples=1600)):
        if index == 10:  # 1 s in: follow the speech more
            session.controls.submit(parse_controls({"audio_guidance": 2.0}))
        if index == 25:  # 2.5 s in: back off
            session.controls.submit(parse_controls({"audio_guidance": 1.0}))
        frames.extend(session.push(chunk))
        rows.append(session.generator.layout.batch)
    frames.extend(session.finish())
    assert rows[5] == 2 and max(rows) == 3  # the audio-null row exists only while s_a ≠ 1
    assert session.generator.settings.audio_guidance == 1.0 and session.generator.layout.batch == 2
    unchanged, _ = run_offline(make_session(bundle, audio_guidance=1.0), FastFileSource(speech, chunk_samples=1600))
    # the changes add no jump beyond what the motion itself does (idle → speech included)
    assert max_step_degrees(frames).max() < 1.5 * max_step_degrees(unchanged).max() + 1.0


def test_style_strength_ramps_live_and_leaves_the_guidance_setting_alone(bundle, speech):
    session = make_session(bundle)
    base = session.generator.base_guidance
    for index, chunk in enumerate(FastFileSource(speech, chunk_samples=1600)):
        if index == 10:
            session.controls.submit(parse_controls({"style_strength": 0.0}))
        session.push(chunk)
    session.finish()
    assert session.generator.settings.style_strength == 0.0 and session.generator.guidance == 0.0
    assert session.generator.base_guidance == base


def test_silence_gives_calm_idle_motion(bundle, tmp_path):
    path = tmp_path / "silence.wav"
    soundfile.write(path, np.zeros(3 * SAMPLE_RATE, np.float32), SAMPLE_RATE)
    frames, _ = run_offline(make_session(bundle), FastFileSource(path))
    assert not any(f.speaking for f in frames)
    late = frames[45:]  # after the fade into idle
    steps = max_step_degrees(late)
    assert steps.max() > 0.01  # breathing and sway: not frozen
    assert steps.max() < 2.0  # and not wild


def test_memory_is_bounded_on_a_long_stream(bundle):
    session = make_session(bundle)
    noise = np.random.default_rng(0).normal(0, 0.05, 20 * SAMPLE_RATE).astype(np.float32)
    for start in range(0, len(noise), 4000):
        session.push(_chunk(noise[start : start + 4000], start))
    assert session.features.kept <= bundle.audio_window + 4000 // 533 + 1
    assert len(session.generator.history) <= bundle.denoiser_config.window


def _chunk(samples, start):
    from gesturecast.realtime.audio.sources import AudioChunk

    return AudioChunk(samples, start, start / SAMPLE_RATE)


def test_live_engine_releases_every_frame_in_order_at_real_time(bundle, speech, tmp_path):
    short = tmp_path / "short.wav"
    soundfile.write(short, load_audio(speech)[: SAMPLE_RATE], SAMPLE_RATE, subtype="FLOAT")
    clock = MonotonicClock()
    received = []
    session = make_session(bundle, clock)
    report = LiveEngine(session, PacedFileSource(short, 512, clock), received.append, clock).run()
    offline, _ = run_offline(make_session(bundle), FastFileSource(short))
    np.testing.assert_array_equal(poses(received), poses(offline))
    assert report.frames == len(received) == 30
    assert report.latency["end_to_end"]["count"] == 30


POISONED_LATENTS = (0, 3, 4)  # the generator's output for these latent frames is NaN


def test_nonfinite_generator_output_never_reaches_a_bridge_bvh_or_json(bundle, speech, tmp_path, caplog):
    """NaN motion at the generator seam: each such pose is replaced by the last good one (idle before any),
    counted in the report, warned about once; the BVH recorder and the JSON stream stay finite and valid."""
    import json

    from gesturecast.bridges.bvh_recorder import BvhRecorder
    from gesturecast.bridges.pose_json import PoseJsonWriter
    from gesturecast.models.motion.bvh import read_bvh

    session = make_session(bundle)
    decode, latents = session.generator.decode, iter(range(1 << 20))

    def poisoned_decode(latent: np.ndarray) -> np.ndarray:
        motion = decode(latent)  # (d, D)
        return np.full_like(motion, np.nan) if next(latents) in POISONED_LATENTS else motion

    session.generator.decode = poisoned_decode
    frames, report = run_offline(session, FastFileSource(speech))
    d = bundle.frames_per_latent
    assert report.nonfinite_poses == report.to_dict()["nonfinite_poses"] == len(POISONED_LATENTS) * d
    assert all(np.isfinite(f.rotations).all() and np.isfinite(f.root_position).all() for f in frames)
    body = slice(0, NUM_JOINTS)  # the fingers (realtime/pose/hands.py) keep moving with stream time
    np.testing.assert_array_equal(frames[0].rotations[body], session.idle.rotations(0.0))  # no good pose yet: idle
    for held in range(3 * d, 5 * d):  # latents 3 and 4 hold the last pose of latent 2
        np.testing.assert_array_equal(frames[held].rotations[body], frames[3 * d - 1].rotations[body])
        np.testing.assert_array_equal(frames[held].root_position, frames[3 * d - 1].root_position)
    assert sum("NaN or infinite" in r.getMessage() for r in caplog.records) == 1
    with BvhRecorder(tmp_path / "take.bvh") as recorder:
        for frame in frames:
            recorder.send(frame)
    assert np.isfinite(read_bvh(tmp_path / "take.bvh").motion).all()
    writer = PoseJsonWriter(tmp_path / "take.json")
    writer.write(frames)
    writer.save()
    json.loads((tmp_path / "take.json").read_text(), parse_constant=lambda name: pytest.fail(f"bare {name}"))


def test_every_frame_carries_curled_fingers_that_move_with_the_gesture(bundle, speech):
    """Frames are poses on CANONICAL_WITH_HANDS: the body as generated, then 30 finger joints that are bent
    (a relaxed hand, never the flat rest pose) and that move over the clip."""
    frames, _ = run_offline(make_session(bundle), FastFileSource(speech))
    rotations = np.stack([f.rotations for f in frames])  # (T, 52, 4)
    assert rotations.shape[1:] == (CANONICAL_WITH_HANDS.num_joints, 4)
    finger_deg = np.degrees(np.linalg.norm(quat_to_axis_angle(rotations[:, NUM_JOINTS:]), axis=-1))  # (T, 30)
    assert finger_deg.mean(axis=1).min() > MIN_MEAN_FINGER_BEND_DEG
    assert finger_deg.std(axis=0).mean() > MIN_FINGER_MOTION_DEG


def test_root_modes_and_a_live_root_change_without_a_jump(bundle, speech):
    def planar(frames) -> np.ndarray:
        return np.stack([f.root_position[[0, 2]] for f in frames])  # (T, 2)

    locked, _ = run_offline(make_session(bundle, root_mode=RootMode.LOCKED), FastFileSource(speech))
    assert np.abs(planar(locked)).max() == 0.0
    session = make_session(bundle, root_mode=RootMode.FREE)
    source = FastFileSource(speech, chunk_samples=SAMPLE_RATE)
    frames = []
    for index, chunk in enumerate(source):
        if index == 2:
            session.controls.submit(parse_controls({"root": "locked"}))
        frames.extend(session.push(chunk))
    frames.extend(session.finish())
    path = planar(frames)
    after = path[-int(30 * 1.0):]  # the last second: pinned where the change found the avatar
    assert np.ptp(after, axis=0).max() == 0.0
    assert np.linalg.norm(np.diff(path, axis=0), axis=1).max() < 0.05  # no jump at the change


JITTER_S = 0.06  # a capture time estimated 60 ms early: more than one frame period (33 ms)


def test_jittery_source_capture_times_never_make_frames_go_back_in_time(bundle, speech):
    """A microphone's capture times are estimates (PortAudio's ADC times through PulseAudio are coarse);
    one estimated early must not give a frame a presentation time before the frame ahead of it (the
    scheduler refused that with ValueError and the live run died with a traceback)."""
    from gesturecast.realtime.audio.sources import AudioChunk
    from gesturecast.realtime.timing.scheduler import FrameScheduler

    audio = load_audio(speech)  # (n,)
    clock = FakeClock(0.0)
    session = make_session(bundle, clock)
    scheduler = FrameScheduler(clock, lambda frame: None)
    chunk = 512
    for index, start in enumerate(range(0, audio.shape[0], chunk)):
        early = JITTER_S if index % 7 == 6 else 0.0
        for frame in session.push(AudioChunk(audio[start : start + chunk], start, 10.0 + start / SAMPLE_RATE - early)):
            scheduler.submit(frame)
    assert scheduler.stats.submitted > 0


def test_the_report_and_summary_say_how_far_the_root_went(bundle, speech):
    from gesturecast.models.motion.root_anchor import RootBounds
    from gesturecast.realtime.engine_cli import summary_line

    frames, report = run_offline(make_session(bundle, root_mode=RootMode.FREE), FastFileSource(speech))
    planar = np.stack([f.root_position[[0, 2]] for f in frames])  # (T, 2)
    distances = np.linalg.norm(planar - planar[0], axis=1)  # (T,)
    root = report.to_dict()["root"]
    assert root["max_distance_m"] == pytest.approx(distances.max()) and root["max_distance_m"] > 0.0
    assert root["net_travel_m"] == pytest.approx(distances[-1])
    _, bounded = run_offline(make_session(bundle), FastFileSource(speech))
    assert bounded.root["max_distance_m"] < RootBounds().radius_m
    assert bounded.root["max_facing_deg"] < RootBounds().max_yaw_deg
    assert (f"root max {root['max_distance_m']:.2f} m, net {root['net_travel_m']:.2f} m, "
            f"facing max {root['max_facing_deg']:.0f}°") in summary_line(report)
