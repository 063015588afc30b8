"""Far-future words sent to a real `gesturecast serve` process are refused with a one-line error (soon the rate
limit's), and the server is idle once the client has gone (before: every word was kept, each cue placed against all
the others, and the stream thread went on placing at 100 % CPU for minutes after its client left)."""

from __future__ import annotations

import json
import os
import re
import time
from pathlib import Path

from websockets.sync.client import connect

from gesturecast.models.audio.files import SAMPLE_RATE

START_BOUND_S = 120.0  # the default model and lexicon load on a loaded 2-core machine
MESSAGES = 40
WORDS_PER_MESSAGE = 500
IDLE_WINDOW_S = 3.0
IDLE_CPU_S = 1.0  # CPU seconds the server may use in the window (it uses a few hundredths when idle)


def far_words(message: int) -> list[dict]:
    """500 trigger words, 5 s apart (each would be placed), the ``message``-th block of them from 10 s on."""
    first = 10.0 + message * WORDS_PER_MESSAGE * 5.0
    return [{"word": "hello", "start": first + 5.0 * i} for i in range(WORDS_PER_MESSAGE)]


def cpu_seconds(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")  # utime + stime


def test_far_future_words_are_refused_and_the_server_is_idle_once_the_client_has_gone(cli_process, speech_16k):
    server = cli_process(["serve", "--port", "0"])
    url = re.search(r"ws://\S+/stream/", server.wait_for_stderr("serving streams on", START_BOUND_S)).group(0)
    with connect(url + "flood", open_timeout=30) as client:
        assert json.loads(client.recv(timeout=30))["type"] == "hello"
        client.send(speech_16k[:SAMPLE_RATE].astype("<f4").tobytes())
        assert json.loads(client.recv(timeout=60))["type"] == "started"
        replies = []
        for message in range(MESSAGES):
            client.send(json.dumps({"type": "words", "words": far_words(message)}))
            while (reply := client.recv(timeout=60)) and isinstance(reply, bytes):
                pass  # pose frames
            replies.append(json.loads(reply))
    assert "ahead of the stream" in replies[0]["message"], replies[0]
    reasons = ("ahead of the stream", "rate limit")  # a flood soon runs into the connection's rate limit
    assert all(reply["type"] == "error" and any(r in reply["message"] for r in reasons) for reply in replies)
    assert any("rate limit" in reply["message"] for reply in replies)
    server.wait_for_stderr("stream flood closed", START_BOUND_S)
    before = cpu_seconds(server.process.pid)
    time.sleep(IDLE_WINDOW_S)
    assert cpu_seconds(server.process.pid) - before < IDLE_CPU_S
    server.interrupt(START_BOUND_S)
