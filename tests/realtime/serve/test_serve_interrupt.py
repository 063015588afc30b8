"""Ctrl-C on a real `gesturecast serve` subprocess with a client streaming: it ends at once, with a summary."""

import asyncio
import re
import threading
import time

from gesturecast.tools.bench.serve_client import stream_audio

START_BOUND_S = 90.0  # model load on a loaded 2-core machine
INTERRUPT_BOUND_S = 15.0  # serve closes in well under a second here; generous for shared, loaded CI cores
STREAMING_S = 2.0


def stream_in_background(url: str, audio) -> threading.Thread:
    """A client sending ``audio`` at real-time pace; the server going away ends it (its error is expected)."""

    def run() -> None:
        try:
            asyncio.run(stream_audio(url, audio, start={}))
        except Exception:  # noqa: BLE001 - the server closes the connection on Ctrl-C: any way it ends is fine
            return

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    return thread


def test_ctrl_c_on_serve_with_a_stream_ends_within_the_bound_and_prints_the_summary(cli_process, speech_16k):
    server = cli_process(["serve", "--port", "0"])
    url = re.search(r"ws://\S+/stream/", server.wait_for_stderr("serving streams on", START_BOUND_S)).group(0)
    client = stream_in_background(url + "one", speech_16k)
    server.wait_for_stderr("stream one started", START_BOUND_S)
    time.sleep(STREAMING_S)  # let some speech through before Ctrl-C
    status, seconds, stdout = server.interrupt(INTERRUPT_BOUND_S)
    client.join(INTERRUPT_BOUND_S)
    assert status == 130 and seconds < INTERRUPT_BOUND_S
    summary = re.search(r"stopped by Ctrl-C: last 1 streams served: (\d+) frames", stdout)
    assert summary is not None and int(summary.group(1)) > 0
