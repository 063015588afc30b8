"""One denoiser ONNX session shared by many streams: concurrent calls are stacked into one batched call.

Every stream keeps its own :class:`DenoiserRuntime` state (KV cache rows, pending latent) and its own
sampler loop; only the graph call is shared. A stream's runtime talks to a :class:`BatchPort` instead
of an onnxruntime session. The :class:`DenoiserBatcher` thread takes every request waiting at that
moment, concatenates the feeds of requests with the same frame count M along the batch dimension
(frame inputs on axis 0, KV caches ``(L, B, H, W, Dh)`` on axis 1), makes one call per group and
splits the outputs back. Rows never interact inside the graph (each row has its own cache length and
attention mask), so a stream's output does not depend on who it was batched with.

Batching is continuous (no waiting timer): an idle server answers a lone request at once, and under
load the requests that arrive during one call form the next batch.
"""

from __future__ import annotations

import logging
import queue
import threading
import time
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass, field, fields
from pathlib import Path

import numpy as np

from gesturecast.models.runtime.bundle import ModelBundle
from gesturecast.models.runtime.denoiser_runtime import FRAME_INPUT_NAMES, OUTPUT_NAMES, DenoiserRuntime
from gesturecast.models.runtime.ort_session import DEFAULT_THREADS
from gesturecast.realtime.timing.latency import charge_cpu

logger = logging.getLogger(__name__)

FRAME_BATCH_AXIS = 0  # x_t (B, M, C), t (B, M), ... and x0 (B, M, C)
CACHE_BATCH_AXIS = 1  # cache_keys / cache_values / new_keys / new_values (L, B, H, ·, Dh)
BATCH_AXIS = {
    **dict.fromkeys(FRAME_INPUT_NAMES, FRAME_BATCH_AXIS),
    "cache_keys": CACHE_BATCH_AXIS,
    "cache_values": CACHE_BATCH_AXIS,
    "cache_length": FRAME_BATCH_AXIS,
}
OUTPUT_BATCH_AXIS = (FRAME_BATCH_AXIS, CACHE_BATCH_AXIS, CACHE_BATCH_AXIS)  # x0, new_keys, new_values
STOP_TIMEOUT_S = 5.0

Feeds = dict[str, np.ndarray]
Outputs = list[np.ndarray]


def batch_size(feeds: Feeds) -> int:
    return int(feeds["x_t"].shape[FRAME_BATCH_AXIS])


def group_key(feeds: Feeds) -> tuple:
    """Requests can share a call when every input matches except along its batch axis."""
    return tuple(feeds[name].shape[:axis] + feeds[name].shape[axis + 1:] for name, axis in BATCH_AXIS.items())


def stack_feeds(requests: Sequence[Feeds]) -> Feeds:
    """Feeds of several requests → one feed dict with their rows concatenated in request order (a lone request's
    own feeds: most calls carry one stream, and copying its KV cache cost a tenth of a busy server's CPU)."""
    if len(requests) == 1:
        return requests[0]
    return {name: np.concatenate([r[name] for r in requests], axis=axis) for name, axis in BATCH_AXIS.items()}


def split_outputs(outputs: Outputs, sizes: Sequence[int]) -> list[Outputs]:
    """The outputs of a stacked call → each request's own outputs (rows in request order; a lone request's: as
    they are)."""
    if len(sizes) == 1:
        return [list(outputs)]
    bounds = np.cumsum(sizes)[:-1]
    parts = [np.split(array, bounds, axis=axis) for array, axis in zip(outputs, OUTPUT_BATCH_AXIS, strict=True)]
    return [list(per_request) for per_request in zip(*parts, strict=True)]


@dataclass
class _Request:
    feeds: Feeds
    done: threading.Event = field(default_factory=threading.Event)
    outputs: Outputs | None = None
    error: Exception | None = None
    cpu_seconds: float = 0.0  # its rows' share of the batched call's CPU time


@dataclass
class BatchStats:
    """How many requests (streams) and rows each graph call carried."""

    calls: int = 0
    requests: int = 0
    rows: int = 0
    requests_per_call: Counter = field(default_factory=Counter)  # bounded: keys ≤ max streams

    def add(self, requests: int, rows: int) -> None:
        self.calls += 1
        self.requests += requests
        self.rows += rows
        self.requests_per_call[requests] += 1

    def to_dict(self) -> dict:
        return {
            "calls": self.calls,
            "mean_streams_per_call": self.requests / self.calls if self.calls else 0.0,
            "mean_rows_per_call": self.rows / self.calls if self.calls else 0.0,
            "streams_per_call": {str(k): v for k, v in sorted(self.requests_per_call.items())},
        }


class BatchPort:
    """Stands in for an onnxruntime session inside one stream's :class:`DenoiserRuntime`."""

    def __init__(self, batcher: DenoiserBatcher) -> None:
        self.batcher = batcher

    def run(self, output_names: Sequence[str] | None, feeds: Feeds) -> Outputs:
        """Same contract as ``InferenceSession.run(None, feeds)``; blocks until the batched call is done."""
        if output_names is not None and tuple(output_names) != OUTPUT_NAMES:
            raise ValueError(f"a batched denoiser call returns all outputs {OUTPUT_NAMES}, not {output_names}")
        return self.batcher.submit(feeds)


class StreamDenoiser(DenoiserRuntime):
    """A :class:`DenoiserRuntime` (own state, own cache rows) whose graph calls go through a batcher."""

    def __init__(self, batcher: DenoiserBatcher) -> None:  # no super().__init__: the sessions are shared
        # the step goes through the batcher; the condition (once per latent) runs directly (thread-safe)
        self._attach(BatchPort(batcher), batcher.runtime.condition_session, batcher.config)


class DenoiserBatcher:
    """Owns the one denoiser session and the thread that runs stacked calls (start / close)."""

    def __init__(self, path: Path | str, threads: int = DEFAULT_THREADS, max_waiting: int = 64) -> None:
        self.runtime = DenoiserRuntime(path, threads)
        self.config = self.runtime.config
        self.stats = BatchStats()
        self._requests: queue.Queue[_Request | None] = queue.Queue(maxsize=max_waiting)
        self._thread = threading.Thread(target=self._serve, name="denoiser-batcher", daemon=True)

    def start(self) -> DenoiserBatcher:
        self._thread.start()
        return self

    def close(self) -> None:
        self._requests.put(None)
        self._thread.join(STOP_TIMEOUT_S)

    def submit(self, feeds: Feeds) -> Outputs:
        """Queue one call (blocks while ``max_waiting`` calls wait) and wait for its outputs."""
        if not self._thread.is_alive():
            raise RuntimeError("the denoiser batcher is not running")
        request = _Request(feeds)
        self._requests.put(request)
        request.done.wait()
        charge_cpu(request.cpu_seconds)  # the stream's denoiser stage counts its share of the call
        if request.error is not None:
            raise request.error
        return request.outputs

    def _serve(self) -> None:
        while (first := self._requests.get()) is not None:
            waiting = [first]
            stop = self._take_waiting(waiting)
            self._run_groups(waiting)
            if stop:
                break
        self._refuse_waiting()

    def _refuse_waiting(self) -> None:
        """After close: requests still queued get an error instead of waiting for ever."""
        leftover: list[_Request] = []
        self._take_waiting(leftover)
        for request in leftover:
            request.error = RuntimeError("the denoiser batcher was closed")
            request.done.set()

    def _take_waiting(self, waiting: list[_Request]) -> bool:
        """Append every request already queued; True if the stop sentinel was among them."""
        while True:
            try:
                request = self._requests.get_nowait()
            except queue.Empty:
                return False
            if request is None:
                return True
            waiting.append(request)

    def _run_groups(self, waiting: list[_Request]) -> None:
        groups: dict[tuple, list[_Request]] = {}
        for request in waiting:
            groups.setdefault(group_key(request.feeds), []).append(request)
        for group in groups.values():
            self._run_group(group)

    def _run_group(self, group: list[_Request]) -> None:
        sizes = [batch_size(r.feeds) for r in group]
        cpu_start = time.thread_time()
        try:
            outputs = self.runtime.session.run(None, stack_feeds([r.feeds for r in group]))
            for request, own in zip(group, split_outputs(outputs, sizes), strict=True):
                request.outputs = own
        except Exception as error:  # handed to every waiting stream: each reports it, the server keeps running
            logger.exception("batched denoiser call failed")
            for request in group:
                request.error = error
        self.stats.add(len(group), sum(sizes))
        cpu = time.thread_time() - cpu_start
        for request, rows in zip(group, sizes, strict=True):
            request.cpu_seconds = cpu * rows / sum(sizes)
            request.done.set()


@dataclass(frozen=True)
class SharedDenoiserBundle(ModelBundle):
    """A bundle whose :meth:`denoiser` hands each new generator a stream denoiser on the shared batcher."""

    batcher: DenoiserBatcher

    @classmethod
    def wrap(cls, bundle: ModelBundle, batcher: DenoiserBatcher) -> SharedDenoiserBundle:
        return cls(**{f.name: getattr(bundle, f.name) for f in fields(ModelBundle)}, batcher=batcher)

    def denoiser(self, threads: int = DEFAULT_THREADS) -> DenoiserRuntime:
        return StreamDenoiser(self.batcher)
