"""Ctrl-C on a real `gesturecast demo` subprocess: it ends at once with the summary, latency.json and a valid BVH."""

import json
import time

import pytest

from gesturecast.errors import UserError
from gesturecast.models.motion.bvh import read_bvh

START_BOUND_S = 90.0  # model load on a loaded 2-core machine
INTERRUPT_BOUND_S = 5.0  # the demo ends in well under a second here; generous for shared CI cores
POLL_S = 0.1


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
