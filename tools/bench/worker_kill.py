"""``gesturecast bench worker-kill``: ``serve --workers N`` under churn while its workers are SIGKILLed in turn.

Starts ``gesturecast serve --workers N --port 0`` as a real process and runs ``--clients`` clients on this one, each
streaming ``--stream-seconds`` of the bundled sample at real-time pace, ending, and connecting again until the run's
``--minutes`` are over. Every ``--kill-every`` seconds one worker (each in turn) is SIGKILLed, as the OOM killer
would. Then SIGTERM goes to the parent, and the seconds until every process of the service has ended are timed.

Reported (JSON): each kill's seconds until its replacement was ready; the connections by outcome (``served``: the
stream's stats arrived; ``cut``: it ended without them, its worker killed under it; ``refused``: no hello, the
client tries again after :data:`REFUSED_PAUSE_S`) and when the refused ones began; the connections begun while
every worker was ready and not cut by a kill during their life, and those of them not served (none is the goal);
the stop's seconds, exit status and processes left running.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import re
import signal
import subprocess
import sys
import threading
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
from websockets.asyncio.client import connect

from gesturecast.models.audio.files import PACKAGED_SAMPLE, SAMPLE_RATE, load_audio

CHUNK = 1600  # 100 ms per audio message
START_TIMEOUT_S = 300.0
OPEN_TIMEOUT_S = 10.0
STATS_TIMEOUT_S = 30.0
REFUSED_PAUSE_S = 0.5  # a refused client tries again after this (not in a tight loop)
READY = re.compile(r"worker-(\d+) ready \(pid (\d+)\)")


@dataclass
class Connection:
    start: float  # seconds from the run's start
    end: float
    outcome: str  # served, cut or refused
    frames: int


def register_bench(bench_subparsers: argparse._SubParsersAction) -> None:
    parser = bench_subparsers.add_parser("worker-kill", help="serve --workers under churn, one worker SIGKILLed at a "
                                         "time: who is served, how the stop ends (JSON)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--clients", type=int, default=10)
    parser.add_argument("--minutes", type=float, default=5.0)
    parser.add_argument("--kill-every", type=float, default=30.0, metavar="S")
    parser.add_argument("--stream-seconds", type=float, default=10.0, metavar="S")
    parser.set_defaults(func=run)


class ServeProcess:
    """``gesturecast serve --workers N`` with its stderr lines collected, each with its arrival time."""

    def __init__(self, workers: int, clients: int) -> None:
        self.process = subprocess.Popen([sys.executable, "-m", "gesturecast.cli", "serve", "--workers", str(workers),
                                         "--port", "0", "--max-streams", str(clients)],
                                        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.lines: list[tuple[float, str]] = []
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        for line in self.process.stderr:
            self.lines.append((time.monotonic(), line.rstrip("\n")))

    def wait_for(self, text: str, count: int = 1) -> str:
        deadline = time.monotonic() + START_TIMEOUT_S
        while time.monotonic() < deadline and self.process.poll() is None:
            found = [line for _, line in self.lines if text in line]
            if len(found) >= count:
                return found[count - 1]
            time.sleep(0.05)
        raise RuntimeError(f"serve never printed {text!r}: {[line for _, line in self.lines][-5:]}")

    def readies(self) -> list[tuple[float, int, int]]:
        """(arrival, worker index, pid) of every worker-ready line so far."""
        return [(at, int(m.group(1)), int(m.group(2))) for at, line in self.lines if (m := READY.search(line))]

    def children(self) -> list[int]:
        pids = []
        for task in Path(f"/proc/{self.process.pid}/task").glob("*"):
            pids += [int(pid) for pid in (task / "children").read_text().split()]
        return pids


async def one_connection(url: str, audio: np.ndarray, origin: float) -> Connection:
    """Stream ``audio`` at real-time pace, end, and wait for the stats."""
    start, frames, outcome = time.monotonic() - origin, 0, "refused"
    try:
        async with connect(url, open_timeout=OPEN_TIMEOUT_S) as websocket:
            json.loads(await asyncio.wait_for(websocket.recv(), OPEN_TIMEOUT_S))
            outcome = "cut"
            sending = asyncio.create_task(send_audio(websocket, audio))
            try:
                async for message in websocket:
                    if isinstance(message, bytes):
                        frames += 1
                    elif json.loads(message).get("type") == "stats":
                        outcome = "served"
                        break
            finally:
                sending.cancel()
                await asyncio.gather(sending, return_exceptions=True)  # its end (the connection closed) is no news
    except Exception:  # noqa: BLE001 - any failure (refused, reset, timed out) is an outcome here
        pass
    return Connection(start, time.monotonic() - origin, outcome, frames)


async def send_audio(websocket, audio: np.ndarray) -> None:
    began = time.monotonic()
    for offset in range(0, len(audio), CHUNK):
        await websocket.send(audio[offset : offset + CHUNK].astype("<f4").tobytes())
        await asyncio.sleep(max(0.0, began + (offset + CHUNK) / SAMPLE_RATE - time.monotonic()))
    await websocket.send(json.dumps({"type": "end"}))


async def client(url: str, audio: np.ndarray, origin: float, until: float, index: int) -> list[Connection]:
    done = []
    while time.monotonic() < until:
        done.append(await asyncio.wait_for(one_connection(f"{url}c{index}-{len(done)}", audio, origin),
                                           len(audio) / SAMPLE_RATE + STATS_TIMEOUT_S + OPEN_TIMEOUT_S))
        if done[-1].outcome == "refused":
            await asyncio.sleep(REFUSED_PAUSE_S)
    return done


async def killer(server: ServeProcess, workers: int, every: float, until: float, origin: float) -> list[dict]:
    kills = []
    while time.monotonic() + every < until:
        await asyncio.sleep(every)
        index = len(kills) % workers
        pid = [pid for _, i, pid in server.readies() if i == index][-1]
        os.kill(pid, signal.SIGKILL)
        kills.append({"at": time.monotonic() - origin, "worker": index, "pid": pid})
    return kills


def ready_after(server: ServeProcess, kill: dict, origin: float) -> float | None:
    """Seconds from the run's start to the kill's replacement being ready (None: never)."""
    times = [at - origin for at, index, pid in server.readies() if index == kill["worker"] and pid != kill["pid"]
             and at - origin > kill["at"]]
    return min(times, default=None)


def stop(server: ServeProcess) -> dict:
    children = server.children()
    started = time.monotonic()
    server.process.send_signal(signal.SIGTERM)
    try:
        code = server.process.wait(timeout=60)
    except subprocess.TimeoutExpired:
        code = None
    while any(Path(f"/proc/{pid}").exists() for pid in children) and time.monotonic() - started < 60:
        time.sleep(0.05)
    left = [pid for pid in children if Path(f"/proc/{pid}").exists()]
    for pid in left:
        os.kill(pid, signal.SIGKILL)
    server.process.kill()
    return {"stop_s": time.monotonic() - started, "exit_status": code, "left_running": left,
            "summary": server.process.stdout.read().strip().splitlines()[-1:]}


def run(args: argparse.Namespace) -> int:
    audio = load_audio(PACKAGED_SAMPLE)[: int(args.stream_seconds * SAMPLE_RATE)]  # (n,)
    server = ServeProcess(args.workers, args.clients)
    url = re.search(r"ws://\S+/stream/", server.wait_for("serving streams on")).group(0)
    server.wait_for(" ready (pid ", args.workers)
    origin = time.monotonic()
    until = origin + args.minutes * 60

    async def everything():
        return await asyncio.gather(killer(server, args.workers, args.kill_every, until, origin),
                                    *(client(url, audio, origin, until, i) for i in range(args.clients)))

    kills, *per_client = asyncio.run(everything())
    for kill in kills:
        kill["ready_at"] = ready_after(server, kill, origin)
    connections = [c for done in per_client for c in done]
    print(json.dumps(summary(args, kills, connections) | stop(server), indent=2))
    return 0


def summary(args: argparse.Namespace, kills: list[dict], connections: list[Connection]) -> dict:
    """The counts of the module docstring."""
    down = [(k["at"], k["ready_at"] if k["ready_at"] is not None else float("inf")) for k in kills]
    calm = [c for c in connections if not any(a <= c.start < b for a, b in down)
            and not any(c.start <= a <= c.end for a, _ in down)]
    outcomes = {name: sum(c.outcome == name for c in connections) for name in ("served", "cut", "refused")}
    return {"bench": "worker-kill", "workers": args.workers, "clients": args.clients, "minutes": args.minutes,
            "kill_every_s": args.kill_every, "kills": kills,
            "respawn_s": [None if k["ready_at"] is None else k["ready_at"] - k["at"] for k in kills],
            "connections": len(connections), "outcomes": outcomes,
            "refused_at_s": [round(c.start, 2) for c in connections if c.outcome == "refused"],
            "begun_with_all_ready_and_not_cut": len(calm),
            "of_those_not_served": [asdict(c) for c in calm if c.outcome != "served"]}
