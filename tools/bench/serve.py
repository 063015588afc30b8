"""``gesturecast bench serve --streams N [N ...] --seconds S --json``: how many live avatars one process carries.

For each N: a fresh ``serve`` server on loopback (in this process) and N clients in a second process, each
streaming its own slice of real speech at real-time pace in 512-sample float32 chunks, starting at staggered
times. Reports per-stream server-side end-to-end latency (capture → handed to the socket), client-side
end-to-end latency (client capture → frame received), deadline misses, audio drops, the server's real-time
factor (its process CPU seconds per second of audio per stream) and the clients' apart, the server's memory per
added stream, and how the batcher grouped calls; then the largest N with zero deadline misses and that per CPU
core.

``--flood``: one more client streams at real-time pace and floods 500-word ``words`` messages meanwhile; the JSON
adds each measured stream's late share and p95 against L, what the flooder was refused, and the server's log
lines per second (:mod:`gesturecast.tools.bench.serve_flood`).

``--churn N [--concurrency C] [--report-every K]``: one server, N short streams, C at a time, each with a new id
(start, CHURN_SECONDS of audio as fast as the server takes it, end, close); reports the process RSS every K
(CHURN_REPORT_EVERY) finished streams, as a server sees it (no forced garbage collection), and the RSS with no
stream open after the warm-up streams (the churn pauses there) and at the end. What closed streams leave
behind shows up as a slope after the warm-up and as idle growth; both must be flat.
"""

from __future__ import annotations

import argparse
import asyncio
import concurrent.futures
import contextlib
import itertools
import json
import multiprocessing
import os
import platform
import sys
import threading
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from gesturecast.errors import UserError
from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.realtime.cli_flags import settings_from_args
from gesturecast.realtime.serve.cli_args import add_serve_arguments, serve_config
from gesturecast.realtime.serve.launch import start_server
from gesturecast.realtime.serve.server import GestureServer
from gesturecast.realtime.serve.workers import Workers
from gesturecast.realtime.timing.clock import MonotonicClock
from gesturecast.realtime.timing.latency import MS_PER_S
from gesturecast.tools.bench.memory import PROC_STATUS, rss_mb
from gesturecast.tools.bench.serve_client import ClientResult, stream_audio
from gesturecast.tools.bench.serve_flood import FLOOD_WORDS_PER_MESSAGE, LogLines, flood_summary, stream_lateness
from gesturecast.tools.bench.timing.load import add_load_argument, competing_load

DEFAULT_AUDIO = Path(__file__).resolve().parents[3] / "shared" / "data" / "zeggs" / "067_Speech_2_x_1_0.wav"
DEFAULT_STREAMS = (1, 2, 4)
DEFAULT_SECONDS = 20.0
MAX_SECONDS = 60.0
CHUNK_SAMPLES = 512  # 32 ms, what a microphone client sends
MAX_STAGGER_S = 1.0  # clients start spread over this long, as independent users would
STAGGER_SEED = 0
CHURN_SECONDS = 1.0  # audio per churn stream: a start, a few latent frames, an end
CHURN_REPORT_EVERY = 50  # finished streams between RSS samples
SLOPE_UNIT_STREAMS = 100  # the slope is reported per this many streams
CHURN_WARMUP_STREAMS = 100  # left out of the slope (first-use allocations: caches, arenas, code paths)
MAX_CHURN_CONCURRENCY = 64
CHURN_CLOSE_WAIT_S = 10.0  # at most this long for the server to close the last streams before counting them
MAX_NICENESS = 19  # the nicest a process can be
CHURN_SETTLE_S = 2.0  # then this long for its rate-limited heap trim (realtime/serve/heap.py) before an idle sample


def register_bench(bench_subparsers: argparse._SubParsersAction) -> None:
    parser = bench_subparsers.add_parser("serve", help="streams per core of `gesturecast serve` (JSON)")
    parser.add_argument("--audio", type=Path, default=DEFAULT_AUDIO, help="speech file the clients replay")
    parser.add_argument("--streams", type=int, nargs="+", default=list(DEFAULT_STREAMS), help="stream counts N")
    parser.add_argument("--seconds", type=float, default=DEFAULT_SECONDS, help=f"audio per stream (≤ {MAX_SECONDS:g})")
    parser.add_argument("--churn", type=int, metavar="N", help="instead: N short streams, each a new id, the RSS every "
                        f"--report-every (must be flat after the first {CHURN_WARMUP_STREAMS})")
    parser.add_argument("--report-every", type=int, default=CHURN_REPORT_EVERY, metavar="K",
                        help=f"with --churn: the RSS every K finished streams (default {CHURN_REPORT_EVERY})")
    parser.add_argument("--concurrency", type=int, default=1, metavar="C",
                        help=f"with --churn: C streams at a time (1..{MAX_CHURN_CONCURRENCY})")
    parser.add_argument("--json", action="store_true", help="print one JSON object on one line")
    parser.add_argument("--flood", action="store_true",
                        help=f"one more client sends {FLOOD_WORDS_PER_MESSAGE}-word `words` messages as fast as it "
                             "can while it streams: what that costs the others, what it is refused, the log lines")
    parser.add_argument("--client-niceness", type=int, default=0, metavar="N",
                        help="run the clients' process N steps nicer (0..19), standing in for clients on other "
                             "machines: the server gets the cores first (default 0)")
    parser.add_argument("--url", help="measure a server that is already running (e.g. serve --ray: "
                                      "ws://127.0.0.1:8766/stream/); rtf then counts only the clients' CPU")
    add_load_argument(parser)
    add_serve_arguments(parser)
    parser.set_defaults(func=run_bench_serve)


def run_bench_serve(args: argparse.Namespace) -> int:
    seconds = min(args.seconds, MAX_SECONDS)
    if not 0 <= args.client_niceness <= MAX_NICENESS:
        raise UserError(f"--client-niceness must be within 0..{MAX_NICENESS}, got {args.client_niceness}")
    speech = load_audio(args.audio)
    if args.churn is not None:
        if not 1 <= args.report_every <= args.churn:
            raise UserError(f"--churn wants at least --report-every ({args.report_every}) streams, got {args.churn}")
        if not 1 <= args.concurrency <= MAX_CHURN_CONCURRENCY:
            raise UserError(f"--concurrency must be within 1..{MAX_CHURN_CONCURRENCY}, got {args.concurrency}")
        result = measure_churn(args, speech[: int(CHURN_SECONDS * SAMPLE_RATE)], args.churn, args.concurrency)
        sys.stdout.write(json.dumps(result, indent=None if args.json else 2) + "\n")
        return 0
    with competing_load(args.load) as load:
        runs = [measure_streams(args, n, speech, seconds) for n in args.streams]
    cores = usable_cores()
    clean = [r["streams"] for r in runs if r["deadline_misses"] == 0 and not r["errors"] and not r["audio_drops"]]
    best = max(clean, default=0)
    result = {
        "runs": runs,
        "max_streams_zero_misses": best,
        "cpu_cores": cores,
        "streams_per_core": best / cores,
        "settings": {"steps": args.steps, "guidance": runs[0]["guidance"], "threads": args.threads,
                     "client_niceness": args.client_niceness,
                     "model": str(args.model), "seconds": seconds, "chunk_samples": CHUNK_SAMPLES},
        "load": load,
        "machine": {"platform": platform.platform(), "python": platform.python_version()},
    }
    sys.stdout.write(json.dumps(result, indent=None if args.json else 2) + "\n")
    return 0


def usable_cores() -> int:
    """The cores this process may run on (its affinity mask on Linux; all of them where there is none, e.g. Windows)."""
    if hasattr(os, "sched_getaffinity"):
        return len(os.sched_getaffinity(0))
    return os.cpu_count() or 1


def stream_slices(speech: np.ndarray, streams: int, seconds: float) -> list[np.ndarray]:
    """Each stream its own part of the speech (tiled when the file is short)."""
    length = int(seconds * SAMPLE_RATE)
    stride = max(len(speech) // streams, 1)
    tiled = np.tile(speech, int(np.ceil((stride * streams + length) / len(speech))))
    return [tiled[i * stride : i * stride + length] for i in range(streams)]


async def _clients(url: str, slices: list[np.ndarray], flood: bool = False) -> list[ClientResult]:
    """One client per slice at real-time pace; with ``flood``, the last one floods ``words`` messages too."""
    delays = np.random.default_rng(STAGGER_SEED).uniform(0.0, MAX_STAGGER_S, len(slices))
    flooder = len(slices) - 1 if flood else -1

    async def one(index: int) -> ClientResult:
        await asyncio.sleep(float(delays[index]))
        words = FLOOD_WORDS_PER_MESSAGE if index == flooder else 0
        return await stream_audio(f"{url}bench-{index}", slices[index], CHUNK_SAMPLES, paced=True,
                                  flood_words_per_message=words)

    return await asyncio.gather(*(one(i) for i in range(len(slices))))


def timed_clients(url: str, slices: list[np.ndarray], flood: bool = False
                  ) -> tuple[list[ClientResult], float, float]:
    """The clients' results, and the process CPU and wall seconds they took."""
    cpu_start, wall_start = time.process_time(), time.monotonic()
    results = asyncio.run(_clients(url, slices, flood))
    return results, time.process_time() - cpu_start, time.monotonic() - wall_start


def timed_clients_apart(url: str, slices: list[np.ndarray], niceness: int = 0, flood: bool = False
                        ) -> tuple[list[ClientResult], float, float, float]:
    """The clients run in a child process (their event loop and parsing never take this process's turns), ``niceness``
    steps nicer than this one: their results, this process's CPU seconds meanwhile (the server's), the clients' CPU
    seconds and the wall seconds."""
    context = multiprocessing.get_context("spawn")
    with concurrent.futures.ProcessPoolExecutor(1, mp_context=context, initializer=os.nice,
                                                initargs=(niceness,)) as pool:
        pool.submit(int).result()  # the child is up and has imported this module: its start-up is not timed
        cpu_start, wall_start = time.process_time(), time.monotonic()
        results, client_cpu, _ = pool.submit(timed_clients, url, slices, flood).result()
        return results, time.process_time() - cpu_start, client_cpu, time.monotonic() - wall_start


class PeakRss:
    """The largest RSS (MiB, summed over ``processes``' /proc status files; default this process) while the
    ``with`` block runs, sampled every 0.2 s on a thread."""

    def __init__(self, processes: list[Path] | None = None) -> None:
        self.processes = processes or [PROC_STATUS]
        self.mb = self.now()
        self._done = threading.Event()
        self._thread = threading.Thread(target=self._sample, daemon=True)

    def now(self) -> float:
        return sum(rss_mb(status) for status in self.processes)

    def _sample(self) -> None:
        while not self._done.wait(0.2):
            self.mb = max(self.mb, self.now())

    def __enter__(self) -> PeakRss:
        self._thread.start()
        return self

    def __exit__(self, *exc_info: object) -> None:
        self._done.set()
        self._thread.join()
        self.mb = max(self.mb, self.now())


def local_server(args: argparse.Namespace, max_streams: int) -> GestureServer:
    """A server on loopback, any free port, no token, at most ``max_streams`` streams, with the flags' settings."""
    config = replace(serve_config(args, token=None), host="127.0.0.1", port=0, max_streams=max_streams)
    return start_server(settings_from_args(args), config, MonotonicClock())


def process_cpu_seconds(pid: int) -> float:
    """User + system CPU seconds of process ``pid`` so far (Linux /proc)."""
    fields = Path(f"/proc/{pid}/stat").read_text().rpartition(")")[2].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")  # utime, stime


def measure_workers(args: argparse.Namespace, streams: int, speech: np.ndarray, seconds: float) -> dict:
    """``serve --workers N`` on a free loopback port and the clients in another process: the workers' CPU and
    summed RSS (the bench's own process only waits)."""
    config = replace(serve_config(args, token=None), host="127.0.0.1", port=0, max_streams=streams + args.flood)
    with flood_logs(args.flood) as logs:  # the workers inherit the standard error it counts: it starts first
        workers = Workers(settings_from_args(args), config, args.workers).start()
        pids = [process.pid for process in workers.processes]
        status = [Path(f"/proc/{pid}/status") for pid in pids]
        try:
            idle_mb = sum(rss_mb(path) for path in status)
            cpu_start = sum(process_cpu_seconds(pid) for pid in pids)
            with PeakRss(status) as peak:
                results, _, client_cpu, wall = timed_clients_apart(f"ws://127.0.0.1:{workers.port}/stream/",
                                                                   stream_slices(speech, streams + args.flood, seconds),
                                                                   args.client_niceness, args.flood)
            cpu = sum(process_cpu_seconds(pid) for pid in pids) - cpu_start
        finally:
            workers.stop()
    summary = run_summary(results[:streams], streams, seconds, cpu, wall, None, None) | flood_part(results, logs)
    return summary | {"workers": args.workers, "streams_per_worker": workers.dealer.dealt,
                      "client_rtf": client_cpu / (streams * seconds),
                      "server_mb": {"idle": idle_mb, "peak": peak.mb, "per_stream": (peak.mb - idle_mb) / streams}}


def measure_streams(args: argparse.Namespace, streams: int, speech: np.ndarray, seconds: float) -> dict:
    if args.url is not None:
        return measure_running_server(args.url, streams, speech, seconds)
    if args.workers > 1:
        return measure_workers(args, streams, speech, seconds)
    server = local_server(args, max_streams=streams + args.flood)
    idle_mb = rss_mb()
    try:
        with PeakRss() as peak, flood_logs(args.flood) as logs:
            results, cpu, client_cpu, wall = timed_clients_apart(server.url,
                                                                 stream_slices(speech, streams + args.flood, seconds),
                                                                 args.client_niceness, args.flood)
        busy_mb = peak.mb
        batching = server.sessions.batcher.stats.to_dict()
        guidance = server.sessions.defaults.guidance
        guidance = server.sessions.bundle.default_guidance if guidance is None else guidance
    finally:
        server.close()
    summary = run_summary(results[:streams], streams, seconds, cpu, wall, batching, guidance)
    return summary | flood_part(results, logs) | {"client_rtf": client_cpu / (streams * seconds),
                      "server_mb": {"idle": idle_mb, "peak": busy_mb,
                                    "per_stream": (busy_mb - idle_mb) / streams}}


def flood_logs(flood: bool) -> contextlib.AbstractContextManager:
    """Counts the server's log lines with ``--flood`` (:class:`LogLines`); nothing otherwise."""
    return LogLines() if flood else contextlib.nullcontext()


def flood_part(results: list[ClientResult], logs: LogLines | None) -> dict:
    """With ``--flood`` (``logs`` given): the last client's flood summary and the log lines; {} otherwise."""
    if logs is None:
        return {}
    return {"flooder": flood_summary(results[-1]), "server_log_lines": logs.to_dict()}


def measure_churn(args: argparse.Namespace, speech: np.ndarray, count: int, concurrency: int = 1) -> dict:
    """RSS (MiB) after every ``args.report_every`` of ``count`` short streams, ``concurrency`` at a time, through one
    server, and its slope after the warm-up; and the RSS with no stream open after the warm-up streams (the churn
    pauses there) and at the end."""
    server = local_server(args, max_streams=max(args.max_streams, concurrency))
    samples = [(0, rss_mb())]
    errors: list[str] = []
    idle: dict[str, float] = {}
    finished = itertools.count(1)
    warmup = min(CHURN_WARMUP_STREAMS, count)
    try:
        for phase, indices in (("after_warmup", range(warmup)), ("end", range(warmup, count))):
            asyncio.run(churn_streams(server.url, speech, indices, concurrency, finished, samples, errors,
                                      args.report_every))
            idle[phase] = idle_rss(server)
        active = server.active_streams()
    finally:
        server.close()
    return {"churn": churn_summary(samples, idle, concurrency, active, errors)}


def idle_rss(server: GestureServer) -> float:
    """RSS (MiB) once the server has closed every stream and had time to hand freed heap back."""
    deadline = time.monotonic() + CHURN_CLOSE_WAIT_S  # the server sees the last clients leave a moment later
    while server.active_streams() and time.monotonic() < deadline:
        time.sleep(0.05)
    time.sleep(CHURN_SETTLE_S)
    return rss_mb()


async def churn_streams(url: str, speech: np.ndarray, indices: range, concurrency: int, finished: itertools.count,
                        samples: list[tuple[int, float]], errors: list[str], report_every: int) -> None:
    """Streams ``indices`` (ids churn-0, churn-1, ...) from ``concurrency`` clients; appends (finished, RSS MiB)
    to ``samples`` every ``report_every`` finished streams (others still in flight)."""
    pending = iter(indices)

    async def client() -> None:
        for index in pending:  # shared: each client takes the next id
            result = await stream_audio(f"{url}churn-{index}", speech, CHUNK_SAMPLES, paced=False)
            errors.extend(result.errors)
            done = next(finished)
            if done % report_every == 0:
                samples.append((done, rss_mb()))

    await asyncio.gather(*(client() for _ in range(concurrency)))


def churn_summary(samples: list[tuple[int, float]], idle: dict[str, float], concurrency: int, active: int,
                  errors: list[str]) -> dict:
    """The churn result: RSS samples, the slope after warm-up, and the idle RSS at the end against the warm-up's."""
    by_count = dict(samples)
    return {"streams": samples[-1][0], "concurrency": concurrency, "seconds_per_stream": CHURN_SECONDS,
            "rss_mib": [{"streams": n, "rss": round(rss, 1)} for n, rss in samples],
            "rss_at_warmup_mib": by_count.get(CHURN_WARMUP_STREAMS), "rss_max_mib": max(rss for _, rss in samples),
            "idle_rss_mib": {phase: round(rss, 1) for phase, rss in idle.items()},
            "idle_end_minus_warmup_mib": round(idle["end"] - idle["after_warmup"], 1),
            "warmup_streams": CHURN_WARMUP_STREAMS,
            "mib_per_100_streams_after_warmup": churn_slope(samples),
            "active_streams_after": active, "errors": errors[:10]}


def churn_slope(samples: list[tuple[int, float]]) -> float | None:
    """Least-squares RSS growth in MiB per 100 streams, after the warm-up streams (None: too few samples)."""
    kept = np.array([(n, rss) for n, rss in samples if n >= CHURN_WARMUP_STREAMS])  # (K, 2)
    if len(kept) < 2:
        return None
    return float(np.polyfit(kept[:, 0], kept[:, 1], 1)[0] * SLOPE_UNIT_STREAMS)


def measure_running_server(url: str, streams: int, speech: np.ndarray, seconds: float) -> dict:
    """N clients against a server started elsewhere (its batching and CPU are not visible from here)."""
    results, cpu, wall = timed_clients(url, stream_slices(speech, streams, seconds))
    return run_summary(results, streams, seconds, float("nan"), wall, None, None) | {
        "url": url, "client_rtf": cpu / (streams * seconds)}


def run_summary(results: list[ClientResult], streams: int, seconds: float, cpu: float, wall: float,
                batching: dict | None, guidance: float | None) -> dict:
    stats = [r.stats or {} for r in results]
    client_ms = np.concatenate([r.latencies_s() for r in results]) * MS_PER_S
    server_p95 = [p for s in stats if (p := s.get("end_to_end_ms", {}).get("p95")) is not None] or [float("nan")]
    return {
        "streams": streams,
        "deadline_misses": int(sum(s.get("deadline_misses", 0) for s in stats)),
        "misses_per_stream": [s.get("deadline_misses") for s in stats],
        "audio_drops": int(sum(s.get("audio_dropped_samples", 0) for s in stats)),
        "per_stream": [stream_lateness(s) for s in stats],
        "frames": int(sum(len(r.frames) for r in results)),
        "latency_budget_ms": stats[0].get("latency_budget_ms"),
        "server_end_to_end_p95_ms": {"median_stream": float(np.median(server_p95)), "worst_stream": max(server_p95)},
        "client_end_to_end_ms": {p: float(np.percentile(client_ms, q)) for p, q in (("p50", 50), ("p95", 95))}
        | {"max": float(client_ms.max())},
        "rtf": cpu / (streams * seconds),
        "rtf_per_core": cpu / (streams * seconds) / usable_cores(),
        "wall_seconds": wall,
        "batching": batching,
        "errors": [e for r in results for e in r.errors] + [s["error"] for s in stats if s.get("error")],
        "missing_stats": sum(1 for r in results if r.stats is None),
        "guidance": guidance,
    }
