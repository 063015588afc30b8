"""SIGTERM and SIGHUP on a real `generate --batch` subprocess, sent to it alone (`docker stop`) or to it and its
worker processes (systemd stops a service's whole control group, a closed terminal hangs up on the whole job):
the files running finish, the summary is written, and no worker process outlives the batch."""

from __future__ import annotations

import json
import signal
import sys
import time

import pytest
import soundfile

from gesturecast.models.audio.files import PACKAGED_SAMPLE, SAMPLE_RATE, load_audio
from gesturecast.models.motion.bvh import read_bvh
from gesturecast.realtime.jobs.batch import SUMMARY_NAME

FILES = 16
CLIP_S = 1.5
WORKERS = 2
START_BOUND_S = 90.0  # model load and the first file on a loaded 2-core machine
STOP_BOUND_S = 60.0  # the files already running finish first; generous for shared cores
EXIT_BOUND_S = 10.0  # the pool's server and workers end once the batch has exited
POLL_S = 0.05
CASES = [("SIGTERM", 143, False), ("SIGTERM", 143, True), ("SIGHUP", 129, True)]

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="child processes are found through /proc")


@pytest.fixture(scope="module")
def clips(tmp_path_factory):
    folder = tmp_path_factory.mktemp("stop_clips")
    speech, n = load_audio(PACKAGED_SAMPLE), int(CLIP_S * SAMPLE_RATE)  # (samples,)
    for i in range(FILES):
        soundfile.write(folder / f"line_{i:02d}.wav", speech[i * n : (i + 1) * n], SAMPLE_RATE)
    return folder


@pytest.mark.parametrize(("name", "status", "to_children"), CASES,
                         ids=[f"{name}-{'group' if group else 'alone'}" for name, _, group in CASES])
def test_a_stop_signal_ends_the_batch_with_its_summary_and_its_workers(tiny_model, clips, cli_process, tmp_path,
                                                                       name, status, to_children):
    out = tmp_path / "out"
    batch = cli_process(["generate", "--batch", str(clips), "-o", str(out), "--workers", str(WORKERS),
                         "--model", str(tiny_model[1])])
    deadline = time.monotonic() + START_BOUND_S
    while not list(out.glob("*.bvh")) and time.monotonic() < deadline:
        time.sleep(POLL_S)
    children = batch.children()  # the pool's server, its workers, the resource tracker
    assert len(children) > WORKERS, children
    code, _, stdout = batch.stop(getattr(signal, name), STOP_BOUND_S, with_children=to_children)
    summary = json.loads((out / SUMMARY_NAME).read_text())
    assert code == status and stdout.startswith(f"stopped by {name}: "), (code, stdout, batch.stderr_lines[-5:])
    written = sorted(out.glob("*.bvh"))
    assert summary["interrupted"] and summary["failures"] == [] and 1 <= summary["generated"] == len(written) < FILES
    assert all(read_bvh(path).num_frames == CLIP_S * 30 for path in written)  # finished files only
    assert not list(out.glob(".*.tmp"))  # nothing half-written left behind
    assert batch.still_running(children, EXIT_BOUND_S) == []  # no orphaned worker
