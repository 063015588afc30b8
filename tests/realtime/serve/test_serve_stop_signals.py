"""SIGTERM and SIGHUP on a real `gesturecast serve` subprocess with a client streaming (what systemd, `docker stop`
and a closed terminal send): the stream's client gets its stats and a 1001 close, and the server its summary."""

from __future__ import annotations

import asyncio
import json
import re
import signal
import threading
import time

import numpy as np
import pytest
from websockets.asyncio.client import connect
from websockets.exceptions import ConnectionClosed

from gesturecast.models.audio.files import SAMPLE_RATE

START_BOUND_S = 90.0  # model load on a loaded 2-core machine
STOP_BOUND_S = 15.0  # serve closes in well under a second here; generous for shared, loaded CI cores
STREAMING_S = 2.0
CHUNK = 1600  # samples per audio message (100 ms)
GOING_AWAY = 1001
STOPS = [("SIGTERM", 143), ("SIGHUP", 129)]


class StreamingClient:
    """Streams ``audio`` at real-time pace to ``url`` on a thread; keeps what the server sent and how it closed."""

    def __init__(self, url: str, audio: np.ndarray) -> None:
        self.url, self.audio = url, audio
        self.frames = 0
        self.stats: dict | None = None
        self.close_code: int | None = None
        self.thread = threading.Thread(target=lambda: asyncio.run(self._run()), daemon=True)
        self.thread.start()

    async def _run(self) -> None:
        async with connect(self.url) as websocket:
            receiving = asyncio.create_task(self._receive(websocket))
            start = time.monotonic()
            try:
                for offset in range(0, len(self.audio), CHUNK):
                    await websocket.send(self.audio[offset : offset + CHUNK].astype("<f4").tobytes())
                    await asyncio.sleep(max(0.0, start + (offset + CHUNK) / SAMPLE_RATE - time.monotonic()))
            except ConnectionClosed:
                pass  # the server went away: expected
            await receiving
        self.close_code = websocket.close_code

    async def _receive(self, websocket) -> None:
        async for message in websocket:
            if isinstance(message, bytes):
                self.frames += 1
            elif json.loads(message).get("type") == "stats":
                self.stats = json.loads(message)


@pytest.mark.parametrize(("name", "status"), STOPS, ids=[name for name, _ in STOPS])
def test_a_stop_signal_closes_each_stream_with_its_stats_and_prints_the_summary(tiny_model, cli_process, speech_16k,
                                                                               name, status):
    if not hasattr(signal, name):
        pytest.skip(f"no {name} on this platform")
    server = cli_process(["serve", "--port", "0", "--model", str(tiny_model[1])])
    url = re.search(r"ws://\S+/stream/", server.wait_for_stderr("serving streams on", START_BOUND_S)).group(0)
    client = StreamingClient(url + "one", speech_16k)
    server.wait_for_stderr("stream one started", START_BOUND_S)
    time.sleep(STREAMING_S)  # let some speech through first
    code, seconds, stdout = server.stop(getattr(signal, name), STOP_BOUND_S)
    client.thread.join(STOP_BOUND_S)
    summary = re.search(rf"stopped by {name}: last 1 streams served: (\d+) frames", stdout)
    assert code == status and seconds < STOP_BOUND_S and summary is not None, (code, stdout, server.stderr_lines)
    assert client.close_code == GOING_AWAY and client.stats is not None
    assert client.stats["frames"] == client.frames == int(summary.group(1)) > 0  # counted as sent, all received
