"""`gesturecast live --ws` as a real subprocess: the viewer hello names the style, a bad control value is
answered with an error before any ack and the run goes on to exit 0."""

import json
import socket
import subprocess
import sys
import time

import pytest
import soundfile
from websockets.sync.client import connect

from gesturecast.models.audio.files import SAMPLE_RATE, load_audio

SPEECH_SECONDS = 6  # played at real-time pace: long enough to connect and steer while it runs
CONNECT_TIMEOUT_S = 120.0  # the subprocess loads the model before listening
REPLY_TIMEOUT_S = 30.0
RETRY_S = 0.2


@pytest.fixture(scope="module")
def speech(tmp_path_factory, shared_data):
    audio = load_audio(shared_data / "speech" / "tts_01_en-us.wav")[: SPEECH_SECONDS * SAMPLE_RATE]
    path = tmp_path_factory.mktemp("live_ws") / "speech.wav"
    soundfile.write(path, audio, SAMPLE_RATE, subtype="PCM_16")
    return path


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def connect_when_listening(url: str, process: subprocess.Popen):
    deadline = time.monotonic() + CONNECT_TIMEOUT_S
    while True:
        try:
            return connect(url, open_timeout=REPLY_TIMEOUT_S)
        except OSError:
            if process.poll() is not None or time.monotonic() > deadline:
                raise AssertionError(f"live never listened: {process.communicate()[1]}") from None
            time.sleep(RETRY_S)


def exchange(client, message: dict) -> dict:
    client.send(json.dumps(message))
    while True:
        reply = client.recv(REPLY_TIMEOUT_S)
        if isinstance(reply, str) and json.loads(reply)["type"] in ("ack", "error"):
            return json.loads(reply)


def test_live_ws_refuses_bad_controls_before_acking_and_keeps_running(tiny_model, speech):
    port = free_port()
    command = [sys.executable, "-m", "gesturecast.cli", "live", "--input", str(speech), "--model", str(tiny_model[1]),
               "--steps", "2", "--style", "old", "--ws", str(port)]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        with connect_when_listening(f"ws://127.0.0.1:{port}/", process) as client:
            hello = json.loads(client.recv(REPLY_TIMEOUT_S))
            typo = exchange(client, {"type": "control", "style": "hapy"})
            placeholder = exchange(client, {"type": "control", "style": "happy, sweeping gestures"})
            prompt = exchange(client, {"type": "control", "prompt": "happy, sweeping gestures"})
        _, stderr = process.communicate(timeout=CONNECT_TIMEOUT_S)
    finally:
        process.kill()
    assert hello["style"] == "old"
    assert typo["type"] == "error" and "unknown style 'hapy'" in typo["message"]
    assert placeholder["type"] == "error" and "unknown style" in placeholder["message"]
    assert prompt == {"type": "ack", "applied": {"prompt": "happy, sweeping gestures"}}
    assert process.returncode == 0, stderr
