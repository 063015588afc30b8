
"""`gesturecast live --device pulse` through real PortAudio on a virtual microphone (a private PulseAudio
whose source is a FIFO fed with real speech at real-time pace): frames reach VMC and BVH, a stalled device
is reported and recovers, a silent or vanished device ends the run with one error line, and Ctrl-C ends
the run within a bound with the final summary, whatever the device does."""

import json
import re
import socket
import subprocess
import sys

import pytest

from gesturecast.models.motion.bvh import read_bvh
from gesturecast.tools.bench.virtual_mic import DEVICE_NAME

START_BOUND_S = 90.0  # model load + first frames on a loaded 2-core machine
INTERRUPT_BOUND_S = 5.0  # Ctrl-C ends a run in ~0.2 s here; the bound is generous for shared CI cores
STALL_TEXT = "no audio from input device"
DATAGRAM_BYTES = 65536


@pytest.fixture
def vmc_receiver():
    """A real UDP socket on a free loopback port: where `live --vmc` sends its bundles."""
    receiver = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    receiver.bind(("127.0.0.1", 0))
    receiver.settimeout(START_BOUND_S)
    yield receiver
    receiver.close()


def start_live(cli_process, mic, tmp_path, receiver, *extra: str):
    port = receiver.getsockname()[1]
    return cli_process(["live", "--device", DEVICE_NAME, "--vmc", f"127.0.0.1:{port}", "--bvh",
                        str(tmp_path / "live.bvh"), *extra], env=mic.env)


def summary_frames(stdout: str) -> int:
    """Frames counted by the final summary line ("stopped by Ctrl-C: N frames from ...")."""
    line = next(line for line in stdout.splitlines() if line.startswith("stopped by Ctrl-C:"))
    return int(line.split(":", 1)[1].split()[0])


def test_live_microphone_reaches_vmc_and_bvh_and_ctrl_c_prints_the_summary(
        virtual_mic, speech_16k, cli_process, vmc_receiver, tmp_path):
    feeder = virtual_mic.feed(speech_16k, loop=True)
    live = start_live(cli_process, virtual_mic, tmp_path, vmc_receiver)
    assert vmc_receiver.recv(DATAGRAM_BYTES).startswith(b"#bundle")  # poses arrive while the mic speaks
    status, seconds, stdout = live.interrupt(INTERRUPT_BOUND_S)
    feeder.stop()
    assert status == 130 and seconds < INTERRUPT_BOUND_S
    assert summary_frames(stdout) >= read_bvh(tmp_path / "live.bvh").motion.shape[0] > 0
    assert not [line for line in live.stderr_lines if "Traceback" in line or STALL_TEXT in line]


def test_ctrl_c_on_a_stalled_microphone_ends_live_at_once_after_warning_and_recovery(
        virtual_mic, speech_16k, cli_process, vmc_receiver, tmp_path):
    feeder = virtual_mic.feed(speech_16k, loop=True)
    live = start_live(cli_process, virtual_mic, tmp_path, vmc_receiver)
    vmc_receiver.recv(DATAGRAM_BYTES)
    feeder.pause()  # the device stalls: PulseAudio's source delivers nothing, PortAudio's stop() would hang
    warning = live.wait_for_stderr(STALL_TEXT, timeout_s=START_BOUND_S)
    assert f"({DEVICE_NAME})" in warning and warning.startswith("WARNING")
    feeder.resume()
    live.wait_for_stderr("is back after", timeout_s=START_BOUND_S)
    feeder.pause()
    live.wait_for_stderr(STALL_TEXT, timeout_s=START_BOUND_S, count=2)  # stalled again when Ctrl-C comes
    status, seconds, stdout = live.interrupt(INTERRUPT_BOUND_S)
    feeder.stop()
    assert status == 130 and seconds < INTERRUPT_BOUND_S
    assert summary_frames(stdout) >= read_bvh(tmp_path / "live.bvh").motion.shape[0] > 0


def test_a_microphone_silent_past_the_stall_timeout_ends_live_with_one_error_line(
        virtual_mic, speech_16k, cli_process, vmc_receiver, tmp_path):
    feeder = virtual_mic.feed(speech_16k, loop=True)
    live = start_live(cli_process, virtual_mic, tmp_path, vmc_receiver, "--stall-timeout", "3")
    vmc_receiver.recv(DATAGRAM_BYTES)
    feeder.stop()  # and the device stays silent
    status, _, _ = live.wait(START_BOUND_S)
    errors = [line for line in live.stderr_lines if line.startswith("gesturecast live: error:")]
    assert status == 2 and len(errors) == 1
    assert re.search(rf"\({DEVICE_NAME}\) delivered no audio for 3\.\d s", errors[0])  # measured: 3.0 s or a bit more
    assert read_bvh(tmp_path / "live.bvh").motion.shape[0] > 0  # the recording is closed and valid


def test_a_microphone_that_vanishes_mid_stream_ends_live_with_one_error_line(
        virtual_mic, speech_16k, cli_process, vmc_receiver, tmp_path):
    feeder = virtual_mic.feed(speech_16k, loop=True)
    live = start_live(cli_process, virtual_mic, tmp_path, vmc_receiver)
    vmc_receiver.recv(DATAGRAM_BYTES)
    virtual_mic.unload_source()  # as when a USB microphone is unplugged
    status, _, _ = live.wait(START_BOUND_S)
    feeder.stop()
    errors = [line for line in live.stderr_lines if line.startswith("gesturecast live: error:")]
    assert status == 2 and len(errors) == 1 and "stopped delivering audio" in errors[0]
    assert read_bvh(tmp_path / "live.bvh").motion.shape[0] > 0


CAPTURE_PROBE = """
import json, time
from gesturecast.realtime.audio.sources import MicConfig, MicSource
source = MicSource(MicConfig(device="pulse"))
rows = []
for chunk in source:
    rows.append([chunk.capture_time, time.monotonic()])
    if len(rows) == 40:
        break
print(json.dumps({"rows": rows, "untimed_blocks": source.stats().untimed_blocks}))
"""


def test_microphone_capture_times_come_from_portaudio_adc_timestamps(virtual_mic, speech_16k):
    feeder = virtual_mic.feed(speech_16k, loop=True)
    probe = subprocess.run([sys.executable, "-c", CAPTURE_PROBE], env=virtual_mic.env, capture_output=True,
                           text=True, timeout=START_BOUND_S)
    feeder.stop()
    result = json.loads(probe.stdout)
    captures = [capture for capture, _ in result["rows"]]
    assert result["untimed_blocks"] == 0  # every PortAudio block carried an ADC time
    assert captures == sorted(set(captures))
    assert all(0 < received - capture < 1.0 for capture, received in result["rows"])
