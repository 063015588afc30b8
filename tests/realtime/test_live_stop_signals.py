"""Ctrl-C, SIGTERM and SIGHUP on real `live` and `generate` subprocesses: the same graceful stop, with the summary,
the recording kept (its frame count equal to the summary's), the signal's exit status and no temporary file."""

from __future__ import annotations

import re
import signal
import time

import numpy as np
import pytest
import soundfile

from gesturecast.errors import UserError
from gesturecast.models.audio.files import PACKAGED_SAMPLE, SAMPLE_RATE, load_audio
from gesturecast.models.motion.bvh import read_bvh

START_BOUND_S = 90.0  # model load on a loaded 2-core machine
STOP_BOUND_S = 15.0  # a stop takes well under a second here; generous for shared CI cores
POLL_S = 0.05
RECORDED_FRAMES = 30  # let a second of motion reach the recording before the signal
OLD = "an older file that must survive\n"
LONG_INPUT_REPEATS = 40  # the packaged sample (25 s) this often: 17 minutes, minutes of work for `generate`
STOPS = [("SIGINT", 130, "Ctrl-C"), ("SIGTERM", 143, "SIGTERM"), ("SIGHUP", 129, "SIGHUP")]


def recorded_frames(path) -> int:
    """Frames in the hidden temporary file the recorder is writing beside ``path`` (0 before there is one)."""
    for recording in path.parent.glob(f".{path.name}.*.tmp"):
        try:
            return read_bvh(recording).num_frames
        except (UserError, FileNotFoundError):
            pass
    return 0


def wait_for(predicate, bound_s: float, what: str) -> None:
    deadline = time.monotonic() + bound_s
    while not predicate():
        if time.monotonic() > deadline:
            pytest.fail(f"no {what} within {bound_s} s")
        time.sleep(POLL_S)


@pytest.mark.parametrize(("name", "status", "reason"), STOPS, ids=[stop[0] for stop in STOPS])
def test_a_stopped_live_run_keeps_its_recording_and_counts_what_it_wrote(tiny_model, cli_process, tmp_path, name,
                                                                           status, reason):
    if not hasattr(signal, name):
        pytest.skip(f"no {name} on this platform")
    take = tmp_path / "take.bvh"
    take.write_text(OLD)
    live = cli_process(["live", "--input", str(PACKAGED_SAMPLE), "--bvh", str(take), "--model", str(tiny_model[1])])
    wait_for(lambda: recorded_frames(take) >= RECORDED_FRAMES, START_BOUND_S, "recorded frames")
    code, seconds, stdout = live.stop(getattr(signal, name), STOP_BOUND_S)
    summary = re.search(rf"^stopped by {reason}: (\d+) frames from", stdout, re.MULTILINE)
    assert code == status and seconds < STOP_BOUND_S and summary is not None, (code, stdout, live.stderr_lines)
    assert int(summary.group(1)) == read_bvh(take).num_frames >= RECORDED_FRAMES  # what was written, not generated
    assert sorted(tmp_path.iterdir()) == [take]  # no temporary file left


@pytest.fixture(scope="module")
def long_speech(tmp_path_factory):
    path = tmp_path_factory.mktemp("long") / "long.wav"
    soundfile.write(path, np.tile(load_audio(PACKAGED_SAMPLE), LONG_INPUT_REPEATS), SAMPLE_RATE, subtype="PCM_16")
    return path


def test_sigterm_stops_a_long_generate_without_touching_its_outputs(tiny_model, cli_process, long_speech, tmp_path):
    outputs = [tmp_path / "a.bvh", tmp_path / "a.json"]
    for path in outputs:
        path.write_text(OLD)
    generate = cli_process(["generate", str(long_speech), "-o", str(outputs[0]), "--json", str(outputs[1]),
                            "--model", str(tiny_model[1])])
    wait_for(lambda: list(tmp_path.glob(".a.json.*.tmp")), START_BOUND_S, "JSON being written")
    code, seconds, _ = generate.stop(signal.SIGTERM, STOP_BOUND_S)
    assert code == 143 and seconds < STOP_BOUND_S, generate.stderr_lines
    assert [path.read_text() for path in outputs] == [OLD, OLD]
    assert sorted(tmp_path.iterdir()) == outputs  # no temporary file left
