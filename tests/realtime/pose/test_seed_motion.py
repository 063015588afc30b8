"""``--seed-motion FILE``: the stream starts at the (retargeted) last pose of a real ZeroEGGS clip, not idle
(``generate``, the session streaming and offline, ``serve``).

The seed is 2 s cut from the shared ZeroEGGS take (its own 75-joint skeleton, retargeted on load).
"""

from __future__ import annotations

import argparse
import asyncio
from pathlib import Path

import numpy as np
import pytest
import soundfile

from gesturecast.cli import main
from gesturecast.errors import UserError
from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.models.generator.diffusion import SamplerConfig
from gesturecast.models.motion.motion_features import ROOT_DIM, motion_to_features
from gesturecast.models.motion.retarget import load_motion_file
from gesturecast.realtime.audio.sources import FastFileSource, PacedFileSource
from gesturecast.realtime.generation.generator import Generator, GeneratorSettings
from gesturecast.realtime.pose.seed_motion import load_seed_motion
from gesturecast.realtime.pose.session import GestureSession, SessionConfig
from gesturecast.realtime.run.engine import run_offline
from gesturecast.realtime.serve.cli_args import add_serve_arguments
from gesturecast.realtime.serve.serve_command import build_server
from gesturecast.realtime.timing.clock import FakeClock, MonotonicClock
from gesturecast.realtime.timing.latency import LatencyBudget
from gesturecast.tools.bench.serve_client import stream_audio

SEED_FRAMES = slice(900, 960)  # 2 s of the take, mid-gesture
SPEECH_SECONDS = 3
START_TOLERANCE = 0.02  # 6D rotation entries of the first pose against the seed's last (BVH text rounding)
IDLE_DIFFERENCE = 0.1  # the idle start differs from the seed pose by more than this (largest 6D entry)


def crop_bvh(source: Path, frames: slice, target: Path) -> Path:
    """A BVH with the header of ``source`` and only the given frames (a real clip of its skeleton)."""
    header, motion = source.read_text().split("MOTION\n", 1)
    lines = motion.splitlines()
    rows = lines[2:][frames]
    target.write_text(f"{header}MOTION\nFrames: {len(rows)}\n{lines[1]}\n" + "\n".join(rows) + "\n")
    return target


@pytest.fixture(scope="module")
def seed_file(tmp_path_factory, shared_data) -> Path:
    return crop_bvh(shared_data / "zeggs" / "067_Speech_2_x_1_0.bvh", SEED_FRAMES,
                    tmp_path_factory.mktemp("seed") / "seed.bvh")


@pytest.fixture(scope="module")
def speech(tmp_path_factory, shared_data) -> Path:
    audio = load_audio(shared_data / "zeggs" / "067_Speech_2_x_1_0.wav")[: SPEECH_SECONDS * SAMPLE_RATE]
    path = tmp_path_factory.mktemp("seed_speech") / "speech.wav"
    soundfile.write(path, audio, SAMPLE_RATE, subtype="FLOAT")
    return path


def rotation_features(bvh: Path) -> np.ndarray:
    """(T, J·6) facing-free 6D rotations of a motion file, on the canonical body joints."""
    return motion_to_features(load_motion_file(bvh))[:, ROOT_DIM:]


def generate(tiny_model, speech: Path, output: Path, *flags: str) -> np.ndarray:
    code = main(["generate", str(speech), "-o", str(output), "--model", str(tiny_model[1]), "--steps", "2", *flags])
    assert code == 0
    return rotation_features(output)


def test_generate_starts_at_the_seed_pose_instead_of_idle(tiny_model, seed_file, speech, tmp_path):
    seed_pose = rotation_features(seed_file)[-1]  # the retargeted last frame
    seeded = generate(tiny_model, speech, tmp_path / "seeded.bvh", "--seed-motion", str(seed_file))
    plain = generate(tiny_model, speech, tmp_path / "plain.bvh")
    assert np.abs(seeded[0] - seed_pose).max() < START_TOLERANCE
    assert np.abs(plain[0] - seed_pose).max() > IDLE_DIFFERENCE
    assert len(seeded) == len(plain) == SPEECH_SECONDS * 30
    assert np.abs(seeded[-1] - plain[-1]).max() > 0.0  # the history held the seed: generation differs


def seeded_session(bundle, seed, clock=None) -> GestureSession:
    generator = Generator(bundle, GeneratorSettings(sampler=SamplerConfig("ddim", 2), guidance=1.5, seed=1))
    budget = LatencyBudget(bundle.frames_per_latent, bundle.audio_lookahead, 100.0)
    return GestureSession(bundle, generator, budget, clock or FakeClock(), SessionConfig(seed_motion=seed))


def test_streaming_equals_offline_with_a_seed_and_reset_starts_from_it_again(bundle, seed_file, speech):
    seed = load_seed_motion(seed_file, bundle)
    assert len(seed.features) % bundle.frames_per_latent == 0
    assert len(seed.features) <= bundle.denoiser_config.window * bundle.frames_per_latent
    session = seeded_session(bundle, seed)
    offline, _ = run_offline(session, FastFileSource(speech, chunk_samples=16000))
    clock = FakeClock(100.0)
    paced, _ = run_offline(seeded_session(bundle, seed, clock), PacedFileSource(speech, chunk_samples=512,
                                                                                 clock=clock))
    session.reset()
    again, _ = run_offline(session, FastFileSource(speech, chunk_samples=333))
    for frames in (paced, again):
        np.testing.assert_array_equal(np.stack([f.rotations for f in offline]), np.stack([f.rotations for f in frames]))
    np.testing.assert_allclose(np.abs(offline[0].rotations[: len(seed.rotations)] * seed.rotations).sum(-1), 1.0,
                               atol=1e-9)  # same unit quaternions up to sign


def test_bad_seed_files_fail_in_one_line(bundle, seed_file, tmp_path):
    with pytest.raises(UserError, match="seed motion not found"):
        load_seed_motion(tmp_path / "typo.bvh", bundle)
    notes = tmp_path / "notes.txt"
    notes.write_text("not motion")
    with pytest.raises(UserError, match="unsupported motion file type"):
        load_seed_motion(notes, bundle)
    with pytest.raises(UserError, match="needs at least"):
        load_seed_motion(crop_bvh(seed_file, slice(0, 1), tmp_path / "one_frame.bvh"), bundle)
    wrong = seed_file.read_text().replace("Hips", "Pelvis").replace("Spine", "Torso")
    (tmp_path / "unknown.bvh").write_text(wrong)
    with pytest.raises(UserError) as error:
        load_seed_motion(tmp_path / "unknown.bvh", bundle)
    assert "\n" not in str(error.value)


def test_serve_starts_every_stream_at_the_seed_pose(tiny_model, bundle, seed_file, speech):
    parser = argparse.ArgumentParser()
    add_serve_arguments(parser)
    args = parser.parse_args(["--model", str(tiny_model[1]), "--steps", "2", "--port", "0",
                              "--seed-motion", str(seed_file)])
    server = build_server(args, MonotonicClock())
    try:
        result = asyncio.run(asyncio.wait_for(stream_audio(f"{server.url}seeded", load_audio(speech)[:SAMPLE_RATE],
                                                           1600, paced=False), 60))
    finally:
        server.close()
    seed = load_seed_motion(seed_file, bundle)
    first = result.frames[0].rotations[: len(seed.rotations)]  # (J, 4) as sent (internal frame)
    np.testing.assert_allclose(np.abs((first * seed.rotations).sum(-1)), 1.0, atol=1e-5)  # float32 on the wire
