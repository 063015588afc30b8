"""Ctrl-C on a real `gesturecast serve` subprocess with a client streaming: it ends at once, with a summary."""

import asyncio
import re
import signal
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


def test_serve_workers_share_one_port_serve_every_stream_and_stop_together(cli_process, speech_16k):
    """Two server processes on one port: both listen, streams go to them, and SIGTERM to the command and its
    children (as systemd sends it) ends all of them with one summary over every stream."""
    server = cli_process(["serve", "--port", "0", "--workers", "2", "--steps", "2"])
    listening = server.wait_for_stderr("serving streams on", 2 * START_BOUND_S, count=2)
    urls = set(re.findall(r"worker-\d \S+: serving streams on (ws://\S+/stream/)", listening))
    assert len(urls) == 1  # the same port
    url = urls.pop()
    clients = [stream_in_background(f"{url}s{i}", speech_16k[: 16000]) for i in range(6)]
    for client in clients:
        client.join(START_BOUND_S)
    server.wait_for_stderr("stream s", START_BOUND_S, count=6)
    workers = server.children()
    status, seconds, stdout = server.stop(signal.SIGTERM, INTERRUPT_BOUND_S, with_children=True)
    assert status == 128 + signal.SIGTERM and seconds < INTERRUPT_BOUND_S
    summary = re.search(r"stopped by SIGTERM: last (\d+) streams served: (\d+) frames", stdout)
    assert summary is not None and int(summary.group(1)) == 6 and int(summary.group(2)) == 6 * 30
    assert workers and not server.still_running(workers, INTERRUPT_BOUND_S)
