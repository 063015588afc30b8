"""``gesturecast generate --batch DIR_OR_CSV -o OUTDIR``: many audio files → BVH (and JSON), resumable.

The jobs (:mod:`gesturecast.realtime.batch_jobs`) whose outputs already exist are skipped (outputs
are written atomically, so an existing one is complete); the rest run on a pool of worker processes
(``--workers``, default: every core) or, with ``--ray``, on Ray Data
(:mod:`gesturecast.realtime.batch_ray`). Each worker loads the model bundle once and runs
:func:`gesturecast.realtime.offline_generate.generate_to_files` per file with one onnxruntime thread,
the same code as ``generate FILE``. A file that fails is logged and listed with its one-line reason;
the others go on. At the end ``OUTDIR/batch_summary.json`` says what was done; the exit status is
:data:`BATCH_FAILED_EXIT` when any file failed.
"""

from __future__ import annotations

import argparse
import json
import logging
import multiprocessing
import os
import signal
import sys
import time
from collections.abc import Callable
from concurrent.futures import Future, ProcessPoolExecutor, as_completed
from dataclasses import asdict, dataclass, field
from pathlib import Path

from tqdm import tqdm
from tqdm.contrib.logging import logging_redirect_tqdm

from gesturecast.arguments import int_at_least
from gesturecast.errors import INTERRUPTED_EXIT, UserError
from gesturecast.files import write_text_atomic
from gesturecast.realtime.batch_jobs import BatchJob, find_jobs
from gesturecast.realtime.engine_setup import build_session, load_bundle
from gesturecast.realtime.offline_generate import generate_to_files
from gesturecast.realtime.session import GestureSession
from gesturecast.realtime.timing.clock import MonotonicClock
from gesturecast.realtime.timing.latency import LatencyStats

logger = logging.getLogger(__name__)

SUMMARY_NAME = "batch_summary.json"
BATCH_FAILED_EXIT = 1  # some files failed (each is listed in the summary); the others were written
PROCESS_START_METHOD = "forkserver"  # workers start from a clean server process, not a fork of this one
RUNNER_PROCESSES = "processes"
RUNNER_RAY = "ray"

ResultSink = Callable[["JobResult"], None]


def add_batch_arguments(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group("batch (many files)")
    group.add_argument("--batch", type=Path, metavar="DIR_OR_CSV",
                       help="every audio file under a folder, or the rows of a CSV (columns: path, style, prompt, "
                            "style2, part_style, gamma, guidance, audio_guidance, seed); -o is then the output folder")
    group.add_argument("--workers", type=int_at_least(1), default=os.cpu_count() or 1,
                       help="worker processes (or Ray actors) for --batch (default: every core)")
    group.add_argument("--with-json", action="store_true", help="with --batch: also write NAME.json beside NAME.bvh")
    group.add_argument("--with-vrma", action="store_true",
                       help="with --batch: also write NAME.vrma (VRM Animation) beside NAME.bvh")
    group.add_argument("--ray", action="store_true",
                       help="with --batch: run on Ray Data (pip install 'gesturecast[scale]') instead of processes")


@dataclass(frozen=True)
class JobResult:
    """What became of one file: the seconds of audio it had, or the one-line reason it failed."""

    audio: str
    audio_seconds: float = 0.0
    error: str | None = None

    def reason_line(self) -> str:
        """The failure as one line that names the file (most reasons already start with its path)."""
        return self.error if self.error.startswith(self.audio) else f"{self.audio}: {self.error}"


class BatchWorker:
    """Files one after another (one worker per process or Ray actor): the bundle loaded once, and the last
    file's session reused (reset) while the settings stay the same.

    A new session builds its ONNX runtimes again (about 0.2 s here, as much as generating 3 s of audio);
    :meth:`GestureSession.reset` starts a fresh stream with the same seed, so a reused session writes the
    same bytes as a new one (tests/realtime/test_batch.py)."""

    def __init__(self, base: argparse.Namespace) -> None:
        self.base = base
        self.bundle = load_bundle(base.model)
        self._settings: dict | None = None
        self._session: GestureSession | None = None

    def __call__(self, job: BatchJob) -> JobResult:
        """One file: never raises for a bad file, so the batch goes on."""
        try:
            session = self._session_for(job.settings(self.base))
            report = generate_to_files(session, job.audio, job.motion_paths(), job.json)
        except UserError as error:
            return JobResult(str(job.audio), error=str(error))
        except Exception as error:  # any failure of one file is that file's result, never the batch's end
            logger.debug("%s failed", job.audio, exc_info=True)
            return JobResult(str(job.audio), error=f"{type(error).__name__}: {error}")
        return JobResult(str(job.audio), report.audio_seconds)

    def _session_for(self, settings: argparse.Namespace) -> GestureSession:
        if self._session is not None and vars(settings) == self._settings:
            self._session.reset()
            self._session.stats = LatencyStats(self._session.stats.clock)  # per-file timings in the log line
            return self._session
        self._session = None  # a failed build must not leave the previous settings' session behind
        self._session = build_session(settings, MonotonicClock(), self.bundle)
        self._settings = vars(settings)
        return self._session


_process_worker: BatchWorker | None = None  # in a pool process only: its worker, set once by the initializer


def _start_process_worker(base: argparse.Namespace) -> None:
    """Pool initializer: Ctrl-C is the parent's to handle (it lets running files finish, then stops)."""
    global _process_worker
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _process_worker = BatchWorker(base)


def _run_in_process(job: BatchJob) -> JobResult:
    return _process_worker(job)


def run_with_processes(jobs: list[BatchJob], base: argparse.Namespace, workers: int, on_result: ResultSink) -> None:
    """The jobs on ``workers`` local processes; ``on_result`` sees each result as it completes."""
    context = multiprocessing.get_context(PROCESS_START_METHOD)
    pool = ProcessPoolExecutor(workers, mp_context=context, initializer=_start_process_worker, initargs=(base,))
    futures = {pool.submit(_run_in_process, job): job for job in jobs}
    unreported = set(futures)
    try:
        for future in as_completed(futures):
            unreported.discard(future)
            on_result(_result_of(future, futures[future]))
    except KeyboardInterrupt:
        pool.shutdown(wait=True, cancel_futures=True)  # files already running finish, no new ones start
        for future in [f for f in unreported if not f.cancelled()]:
            on_result(_result_of(future, futures[future]))  # finished while Ctrl-C was handled: still counted
        raise
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def _result_of(future: Future, job: BatchJob) -> JobResult:
    """The job's result, or the reason its worker process died (e.g. killed for memory)."""
    error = future.exception()
    return future.result() if error is None else JobResult(str(job.audio), error=f"{type(error).__name__}: {error}")


@dataclass
class BatchSummary:
    """Counts of one ``--batch`` run, written to ``OUTDIR/batch_summary.json``."""

    files: int
    skipped: int  # finished by an earlier run
    runner: str
    workers: int
    generated: int = 0
    audio_seconds: float = 0.0  # of the files generated by this run
    wall_seconds: float = 0.0
    interrupted: bool = False
    failures: list[dict] = field(default_factory=list)  # {"path", "error"}

    def add(self, result: JobResult) -> None:
        if result.error is None:
            self.generated += 1
            self.audio_seconds += result.audio_seconds
        else:
            self.failures.append({"path": result.audio, "error": result.error})

    @property
    def audio_hours_per_wall_hour(self) -> float:
        return self.audio_seconds / self.wall_seconds if self.wall_seconds else 0.0

    def to_dict(self) -> dict:
        return {**asdict(self), "failed": len(self.failures),
                "audio_hours_per_wall_hour": self.audio_hours_per_wall_hour}

    def line(self) -> str:
        stopped = "stopped by Ctrl-C: " if self.interrupted else ""
        return (f"{stopped}{self.files} files: {self.generated} generated, {self.skipped} already done, "
                f"{len(self.failures)} failed | {self.audio_seconds:.1f} s of audio in {self.wall_seconds:.1f} s "
                f"({self.audio_hours_per_wall_hour:.1f} audio-h per wall-h, {self.workers} workers on {self.runner})")


def run_batch(args: argparse.Namespace) -> int:
    """``generate --batch``: check everything, run what is not finished, write the summary."""
    base = _check_batch_flags(args)
    jobs = find_jobs(args.batch, args.output, args.with_json, args.with_vrma)
    summary_path = args.output / SUMMARY_NAME
    if any(summary_path in job.outputs() for job in jobs):
        raise UserError(f"an input would write {summary_path}, the batch summary; rename it")
    run = _ray_runner() if args.ray else run_with_processes
    build_session(base, MonotonicClock())  # the model and the command's style, checked once before any worker
    todo = [job for job in jobs if not job.finished()]
    workers = max(1, min(args.workers, len(todo)))
    summary = BatchSummary(len(jobs), len(jobs) - len(todo), RUNNER_RAY if args.ray else RUNNER_PROCESSES, workers)
    start = time.monotonic()
    if todo:
        summary.interrupted = _run_with_progress(run, todo, base, summary)
    summary.wall_seconds = time.monotonic() - start
    write_text_atomic(summary_path, json.dumps(summary.to_dict(), indent=2) + "\n")
    sys.stdout.write(summary.line() + f" | summary: {summary_path}\n")
    if summary.interrupted:
        return INTERRUPTED_EXIT
    return BATCH_FAILED_EXIT if summary.failures else 0


def _check_batch_flags(args: argparse.Namespace) -> argparse.Namespace:
    """The generation flags every job starts from; refuses single-file flags mixed with --batch."""
    if args.audio is not None:
        raise UserError(f"give either an audio file ({args.audio}) or --batch DIR_OR_CSV, not both")
    if args.json is not None:
        raise UserError("with --batch, -o is the output folder: use --with-json for NAME.json beside each NAME.bvh")
    if args.vrma is not None:
        raise UserError("--vrma names one file; with --batch use --with-vrma for NAME.vrma beside each NAME.bvh")
    if args.output.exists() and not args.output.is_dir():
        raise UserError(f"with --batch, -o is the output folder, and {args.output} is a file")
    return argparse.Namespace(**{key: value for key, value in vars(args).items() if key != "func"})


def _ray_runner() -> Callable[[list[BatchJob], argparse.Namespace, int, ResultSink], None]:
    """The Ray Data runner; without Ray installed, one line naming the extra (before any work)."""
    from gesturecast.realtime.batch_ray import import_ray, run_with_ray

    import_ray()
    return run_with_ray


def _run_with_progress(run: Callable, jobs: list[BatchJob], base: argparse.Namespace, summary: BatchSummary) -> bool:
    """Run the jobs with a progress bar on stderr; True when Ctrl-C stopped the run."""
    with logging_redirect_tqdm(), tqdm(total=len(jobs), unit="file", desc="generate", file=sys.stderr) as bar:

        def on_result(result: JobResult) -> None:
            summary.add(result)
            if result.error is not None:
                logger.warning("failed: %s", result.reason_line())
            bar.update()

        try:
            run(jobs, base, summary.workers, on_result)
        except KeyboardInterrupt:
            return True
    return False
