"""`gesturecast bench latency --device pulse` on the virtual microphone (real PortAudio, real bridges)."""

import json
import subprocess
import sys

from gesturecast.tools.bench.virtual_mic import DEVICE_NAME

RUN_BOUND_S = 120.0  # model load + the recorded seconds + warm-up on a loaded 2-core machine
RECORD_SECONDS = "3"


def test_bench_latency_from_a_microphone_reports_start_and_after_start(virtual_mic, speech_16k):
    feeder = virtual_mic.feed(speech_16k, loop=True)
    run = subprocess.run([sys.executable, "-m", "gesturecast.cli", "bench", "latency", "--device", DEVICE_NAME,
                          "--seconds", RECORD_SECONDS, "--json"], env=virtual_mic.env, capture_output=True,
                         text=True, timeout=RUN_BOUND_S)
    feeder.stop()
    assert run.returncode == 0, run.stderr
    result = json.loads(run.stdout)
    assert result["settings"]["source"] == f"device {DEVICE_NAME}"
    assert result["frames"] > 0 and result["untimed_audio_blocks"] == 0 and result["warm_up_ms"] > 0
    assert result["start"]["frames"] + result["after_start"]["frames"] > 0
    assert result["end_to_end_ms"]["p50"] > 0


def test_bench_latency_wants_a_file_or_a_device(capsys):
    from gesturecast.cli import main

    assert main(["bench", "latency"]) == 2
    assert "give a speech FILE or --device NAME" in capsys.readouterr().err
