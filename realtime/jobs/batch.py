"""``gesturecast generate --batch DIR_OR_CSV -o OUTDIR``: many audio files → BVH (and JSON), resumable.

The jobs (:mod:`gesturecast.realtime.jobs.batch_jobs`) whose outputs already exist are skipped (outputs
are written atomically, so an existing one is complete); the rest run on a pool of worker processes
(``--workers``, default: every core) or, with ``--ray``, on Ray Data
(:mod:`gesturecast.realtime.jobs.batch_ray`). Each worker loads the model bundle once and runs
:func:`gesturecast.realtime.run.offline_generate.generate_to_files` per file with one onnxruntime thread,
the same code as ``generate FILE``. A file that fails is logged and listed with its one-line reason;
the others go on. Ctrl-C, SIGTERM and SIGHUP are the parent's to handle (also when sent to the whole
process group, as systemd and a closed terminal do): the files already running finish, no new ones
start, the workers exit and the summary is written. At the end ``OUTDIR/batch_summary.json`` says what
was done; the exit status is :data:`BATCH_FAILED_EXIT` when any file failed.
"""

from __future__ import annotations

import logging
import multiprocessing
import multiprocessing.forkserver
import multiprocessing.resource_tracker
import signal
from collections.abc import Callable
from concurrent.futures import Future, ProcessPoolExecutor, as_completed
from dataclasses import asdict, dataclass, field

from gesturecast import stop_signals
from gesturecast.errors import UserError
from gesturecast.realtime.gestures.transcripts import transcript_beside, transcript_file
from gesturecast.realtime.jobs.batch_jobs import BatchJob
from gesturecast.realtime.pose.session import GestureSession
from gesturecast.realtime.run.engine_setup import build_session, load_bundle
from gesturecast.realtime.run.offline_generate import body_only, generate_to_files
from gesturecast.realtime.timing.clock import MonotonicClock
from gesturecast.realtime.timing.latency import LatencyStats
from gesturecast.settings import Settings

logger = logging.getLogger(__name__)

SUMMARY_NAME = "batch_summary.json"
BATCH_FAILED_EXIT = 1  # some files failed (each is listed in the summary); the others were written
# workers start from a clean server process, not a fork of this one; Windows has no forkserver: there they are spawned
PROCESS_START_METHOD = "forkserver" if "forkserver" in multiprocessing.get_all_start_methods() else "spawn"
RUNNER_PROCESSES = "processes"
RUNNER_RAY = "ray"

ResultSink = Callable[["JobResult"], None]


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
    same bytes as a new one (tests/realtime/jobs/test_batch.py)."""

    def __init__(self, base: Settings) -> None:
        self.base = base
        self.bundle = load_bundle(base.model)
        self._settings: Settings | None = None
        self._session: GestureSession | None = None

    def __call__(self, job: BatchJob) -> JobResult:
        """One file: never raises for a bad file, so the batch goes on."""
        try:
            settings = job.settings(self.base)
            transcript = transcript_file(job.transcript or transcript_beside(job.audio), settings, job.audio)
            session = self._session_for(body_only(settings, job.motion_paths(), job.json))
            transcript.cue(session.gestures)
            report = generate_to_files(session, job.audio, job.motion_paths(), job.json)
        except UserError as error:
            return JobResult(str(job.audio), error=str(error))
        except Exception as error:  # any failure of one file is that file's result, never the batch's end
            logger.debug("%s failed", job.audio, exc_info=True)
            return JobResult(str(job.audio), error=f"{type(error).__name__}: {error}")
        return JobResult(str(job.audio), report.audio_seconds)

    def _session_for(self, settings: Settings) -> GestureSession:
        if self._session is not None and settings == self._settings:
            self._session.reset()
            self._session.stats = LatencyStats(self._session.stats.clock)  # per-file timings in the log line
            return self._session
        self._session = None  # a failed build must not leave the previous settings' session behind
        self._session = build_session(settings, MonotonicClock(), self.bundle)
        self._settings = settings
        return self._session


_process_worker: BatchWorker | None = None  # in a pool process only: its worker, set once by the initializer


def _start_process_worker(base: Settings) -> None:
    """Pool initializer: Ctrl-C and the stop signals are the parent's to handle (it lets running files finish,
    then stops the workers)."""
    global _process_worker
    for signum in (signal.SIGINT, *stop_signals.STOP_SIGNALS):
        signal.signal(signum, signal.SIG_IGN)
    _process_worker = BatchWorker(base)


def _start_process_server() -> None:
    """Start the forkserver (where there is one) with the stop signals blocked: it and the workers it forks never
    get them, so a SIGTERM or SIGHUP to the whole process group neither kills a running file nor orphans the
    workers (a dead forkserver looks like dead workers: the pool breaks and never stops them); the parent, which
    gets the signal too, stops them in order.

    The resource tracker that the forkserver needs is started first, on its own: starting it unblocks SIGTERM.
    """
    if PROCESS_START_METHOD == "forkserver":
        with stop_signals.shielded_children():
            multiprocessing.resource_tracker.ensure_running()
        with stop_signals.shielded_children():
            multiprocessing.forkserver.ensure_running()


def _run_in_process(job: BatchJob) -> JobResult:
    return _process_worker(job)


def run_with_processes(jobs: list[BatchJob], base: Settings, workers: int, on_result: ResultSink) -> None:
    """The jobs on ``workers`` local processes; ``on_result`` sees each result as it completes."""
    context = multiprocessing.get_context(PROCESS_START_METHOD)
    _start_process_server()
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
        stopped = f"stopped by {stop_signals.stopped_by()}: " if self.interrupted else ""
        return (f"{stopped}{self.files} files: {self.generated} generated, {self.skipped} already done, "
                f"{len(self.failures)} failed | {self.audio_seconds:.1f} s of audio in {self.wall_seconds:.1f} s "
                f"({self.audio_hours_per_wall_hour:.1f} audio-h per wall-h, {self.workers} workers on {self.runner})")
