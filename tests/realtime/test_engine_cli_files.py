"""`live` and `generate` never destroy files: inputs are checked before outputs open, outputs that alias
inputs or each other are refused, FIFOs stay FIFOs, and a write failure keeps the old file (CLI subprocesses)."""

from __future__ import annotations

import hashlib
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import soundfile

from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.models.motion.bvh import read_bvh

SPEECH_SECONDS = 1
SIZE_LIMIT_BYTES = 20_000  # RLIMIT_FSIZE: the header fits, one second of frames (about 20 KB) does not
OLD_TAKE = "an older take that must survive\n"

# the CLI with a file size limit (SIGXFSZ ignored, so writes fail with EFBIG, also as root)
LIMITED_CLI = f"""
import resource, signal, sys
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
resource.setrlimit(resource.RLIMIT_FSIZE, ({SIZE_LIMIT_BYTES}, {SIZE_LIMIT_BYTES}))
from gesturecast.cli import main
sys.exit(main(sys.argv[1:]))
"""


@pytest.fixture(scope="module")
def speech(tmp_path_factory, shared_data) -> Path:
    audio = load_audio(shared_data / "speech" / "tts_01_en-us.wav")[: SPEECH_SECONDS * SAMPLE_RATE]
    path = tmp_path_factory.mktemp("cli_files") / "speech.wav"
    soundfile.write(path, audio, SAMPLE_RATE, subtype="PCM_16")
    return path


def run_cli(*argv: str, size_limited: bool = False) -> subprocess.CompletedProcess:
    code = LIMITED_CLI if size_limited else "import sys; from gesturecast.cli import main; sys.exit(main(sys.argv[1:]))"
    env = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1"}
    return subprocess.run([sys.executable, "-c", code, *argv], capture_output=True, text=True, timeout=300, env=env)


def digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def assert_one_line_error(result: subprocess.CompletedProcess, command: str, message: str) -> None:
    lines = [line for line in result.stderr.splitlines() if not line.startswith(("INFO", "WARNING"))]
    assert result.returncode == 2, result.stderr[-2000:]
    assert len(lines) == 1 and lines[0].startswith(f"gesturecast {command}: error: ") and message in lines[0], lines


def test_live_with_a_bad_input_leaves_the_bvh_untouched(tiny_model, tmp_path, cli_here):
    take = tmp_path / "take.bvh"
    take.write_text(OLD_TAKE)
    result = cli_here("live", "--input", str(tmp_path / "typo.wav"), "--bvh", str(take), "--model", str(tiny_model[1]))
    assert_one_line_error(result, "live", "no such audio file")
    assert take.read_text() == OLD_TAKE


def test_live_refuses_a_bvh_that_is_the_input(tiny_model, speech, tmp_path, cli_here):
    link = tmp_path / "same.wav"
    link.symlink_to(speech)
    before = digest(speech)
    result = cli_here("live", "--input", str(speech), "--bvh", str(link), "--model", str(tiny_model[1]))
    assert_one_line_error(result, "live", "is the same file as --input")
    assert digest(speech) == before


@pytest.mark.parametrize("outputs", [["-o", "{audio}"], ["-o", "{dir}/a.bvh", "--json", "{dir}/./a.bvh"]])
def test_generate_refuses_an_output_that_is_an_input_or_another_output(tiny_model, speech, tmp_path, outputs, cli_here):
    before = digest(speech)
    flags = [flag.format(audio=speech, dir=tmp_path) for flag in outputs]
    result = cli_here("generate", str(speech), *flags, "--model", str(tiny_model[1]))
    assert_one_line_error(result, "generate", "is the same file as")
    assert digest(speech) == before and not (tmp_path / "a.bvh").exists()


def test_generate_refuses_to_replace_a_fifo(tiny_model, speech, tmp_path, cli_here):
    fifo = tmp_path / "out.bvh"
    os.mkfifo(fifo)
    result = cli_here("generate", str(speech), "-o", str(fifo), "--model", str(tiny_model[1]))
    assert_one_line_error(result, "generate", "not a regular file")
    assert fifo.is_fifo() and sorted(tmp_path.iterdir()) == [fifo]


def test_generate_writes_files_with_the_umask_mode(tiny_model, speech, tmp_path, cli_here):
    previous = os.umask(0o022)
    try:
        result = cli_here("generate", str(speech), "-o", str(tmp_path / "a.bvh"), "--json", str(tmp_path / "a.json"),
                          "--model", str(tiny_model[1]))
    finally:
        os.umask(previous)
    assert result.returncode == 0, result.stderr[-2000:]
    assert {p.name: oct(p.stat().st_mode & 0o777) for p in tmp_path.iterdir()} == {"a.bvh": "0o644", "a.json": "0o644"}


def test_generate_writes_the_pose_stream_when_the_output_ends_in_json(tiny_model, speech, tmp_path):
    result = run_cli("generate", str(speech), "-o", str(tmp_path / "a.json"), "--model", str(tiny_model[1]))
    assert result.returncode == 0, result.stderr[-2000:]
    poses = json.loads((tmp_path / "a.json").read_text())
    assert len(poses["frames"]) == SPEECH_SECONDS * 30 and "visemes" in poses
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.json"]


def test_generate_on_a_full_disk_keeps_the_old_files(tiny_model, speech, tmp_path):
    bvh, poses = tmp_path / "a.bvh", tmp_path / "a.json"
    bvh.write_text(OLD_TAKE)
    poses.write_text(OLD_TAKE)
    result = run_cli("generate", str(speech), "-o", str(bvh), "--json", str(poses), "--model", str(tiny_model[1]),
                     size_limited=True)
    assert_one_line_error(result, "generate", "File too large")
    assert bvh.read_text() == OLD_TAKE and poses.read_text() == OLD_TAKE
    assert sorted(tmp_path.iterdir()) == [bvh, poses]  # no temporary file left behind


def test_live_bvh_on_a_full_disk_fails_the_run_after_the_summary(tiny_model, speech, tmp_path):
    take = tmp_path / "take.bvh"
    take.write_text(OLD_TAKE)
    result = run_cli("live", "--input", str(speech), "--pace", "fast", "--bvh", str(take),
                     "--model", str(tiny_model[1]), size_limited=True)
    assert "frames from" in result.stdout  # the summary line is still printed
    assert_one_line_error(result, "live", "File too large")
    assert take.read_text() == OLD_TAKE and sorted(tmp_path.iterdir()) == [take]


def test_live_bvh_replaces_the_old_take_when_done(tiny_model, speech, tmp_path, cli_here):
    take = tmp_path / "take.bvh"
    take.write_text(OLD_TAKE)
    result = cli_here("live", "--input", str(speech), "--pace", "fast", "--bvh", str(take),
                      "--model", str(tiny_model[1]))
    assert result.returncode == 0, result.stderr[-2000:]
    assert read_bvh(take).num_frames > 0 and sorted(tmp_path.iterdir()) == [take]


SHORT_INPUT_SAMPLES = 160  # 10 ms: less than one motion frame (533 samples)


@pytest.mark.parametrize(("name", "message"), [("nan.wav", "NaN/inf samples"),
                                               ("short.wav", "shorter than one motion frame")])
def test_live_input_that_gives_no_frame_is_an_error_and_keeps_the_old_take(tiny_model, tmp_path, name, message,
                                                                          cli_here):
    audio = np.full(SAMPLE_RATE if name == "nan.wav" else SHORT_INPUT_SAMPLES, 0.1, np.float32)  # (n,)
    if name == "nan.wav":
        audio[100] = np.nan  # in the first motion frame: the run fails before any frame
    soundfile.write(tmp_path / name, audio, SAMPLE_RATE, subtype="FLOAT")
    take = tmp_path / "take.bvh"
    take.write_text(OLD_TAKE)
    result = cli_here("live", "--input", str(tmp_path / name), "--pace", "fast", "--bvh", str(take),
                      "--model", str(tiny_model[1]))
    assert_one_line_error(result, "live", message)
    assert take.read_text() == OLD_TAKE and sorted(tmp_path.iterdir()) == sorted([take, tmp_path / name])
