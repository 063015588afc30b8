"""Ctrl-C on a real `gesturecast demo` subprocess: it ends at once with the summary, latency.json and a valid BVH;
with --loop the viewer stays up after the first run until Ctrl-C."""

import json
import socket
import time
import urllib.request

import pytest
import soundfile

from gesturecast.errors import UserError
from gesturecast.models.motion.bvh import read_bvh

START_BOUND_S = 90.0  # model load on a loaded 2-core machine
SAMPLE_BOUND_S = 120.0  # the 25 s sample at real-time pace, then its preview, on a loaded machine
INTERRUPT_BOUND_S = 5.0  # the demo ends in well under a second here; generous for shared CI cores
POLL_S = 0.1
CLIP_S = 3


def wait_for_recorded_frames(path, timeout_s: float) -> int:
    """Frames in the BVH the demo is recording, once there are some. The recorder writes a hidden temporary
    file beside ``path`` (valid after every frame) and renames it to ``path`` when the run ends."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        for recording in path.parent.glob(f".{path.name}.*.tmp"):
            try:
                return read_bvh(recording).motion.shape[0]
            except (UserError, FileNotFoundError):
                pass
        time.sleep(POLL_S)
    pytest.fail(f"no frames recorded for {path} within {timeout_s} s")


def test_ctrl_c_on_demo_ends_within_the_bound_with_summary_latency_json_and_bvh(cli_process, tmp_path):
    demo = cli_process(["demo", "--out", str(tmp_path)])
    wait_for_recorded_frames(tmp_path / "demo.bvh", START_BOUND_S)
    status, seconds, stdout = demo.interrupt(INTERRUPT_BOUND_S)
    assert status == 130 and seconds < INTERRUPT_BOUND_S
    assert "stopped by Ctrl-C:" in stdout
    report = json.loads((tmp_path / "latency.json").read_text())
    assert report["interrupted"] and report["frames"] >= read_bvh(tmp_path / "demo.bvh").motion.shape[0] > 0
    assert not (tmp_path / "demo.gif").exists()  # no preview after Ctrl-C: it would delay the exit


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def viewer_answers(url: str) -> bool:
    try:
        with urllib.request.urlopen(url, timeout=2) as page:
            return page.status == 200
    except OSError:
        return False


def test_demo_loop_keeps_the_viewer_up_after_the_first_run_until_ctrl_c(cli_process, tmp_path, wait_until,
                                                                         shared_data):
    """The files of the first run are written, the viewer still answers, Ctrl-C ends it (130); the loading lines come
    before the viewer's address, which names the --ws port. A 3 s clip stands in for the sample (--audio)."""
    port = free_port()
    clip = tmp_path / "clip.wav"
    speech, rate = soundfile.read(shared_data / "speech" / "tts_03_en-gb.wav")
    soundfile.write(clip, speech[: CLIP_S * rate], rate)
    demo = cli_process(["demo", "--out", str(tmp_path), "--ws", str(port), "--loop", "--audio", str(clip)])
    preview = tmp_path / "demo.gif"
    assert wait_until(preview.exists, START_BOUND_S + SAMPLE_BOUND_S), demo.stderr_lines
    assert wait_until(lambda: viewer_answers(f"http://127.0.0.1:{port}/"), START_BOUND_S)
    status, _, stdout = demo.interrupt(INTERRUPT_BOUND_S)
    assert status == 130
    lines = stdout.splitlines()
    loading = next(k for k, line in enumerate(lines) if line.startswith("loading the model"))
    link = next(k for k, line in enumerate(lines) if f"open the viewer now: http://127.0.0.1:{port}/" in line)
    assert loading < link and "replaying the sample until Ctrl-C" in stdout
