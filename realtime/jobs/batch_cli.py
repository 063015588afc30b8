"""``gesturecast generate --batch DIR_OR_CSV -o OUTDIR``: a batch's run with a progress bar (its flags:
:func:`gesturecast.realtime.cli_flags.add_batch_arguments`; the work itself: :mod:`gesturecast.realtime.jobs.batch`)."""

from __future__ import annotations

import argparse
import json
import logging
import sys
import time
from collections.abc import Callable

from gesturecast.errors import INTERRUPTED_EXIT, UserError
from gesturecast.files import write_text_atomic
from gesturecast.realtime.cli_flags import settings_from_args
from gesturecast.realtime.jobs.batch import (
    BATCH_FAILED_EXIT,
    RUNNER_PROCESSES,
    RUNNER_RAY,
    SUMMARY_NAME,
    BatchSummary,
    JobResult,
    ResultSink,
    run_with_processes,
)
from gesturecast.realtime.jobs.batch_jobs import BatchJob, find_jobs
from gesturecast.realtime.run.engine_setup import SessionFactory
from gesturecast.settings import Settings

logger = logging.getLogger(__name__)


def run_batch(args: argparse.Namespace) -> int:
    """``generate --batch``: check everything, run what is not finished, write the summary."""
    base = _check_batch_flags(args)
    jobs = find_jobs(args.batch, args.output, args.with_json, args.with_vrma)
    summary_path = args.output / SUMMARY_NAME
    if any(summary_path in job.outputs() for job in jobs):
        raise UserError(f"an input would write {summary_path}, the batch summary; rename it")
    run = _ray_runner() if args.ray else run_with_processes
    SessionFactory(base).generator()  # the model, its look-ahead and the command's style, checked before any worker
    todo = [job for job in jobs if not job.finished()]
    ready, missing = _split_missing(todo)
    workers = max(1, min(args.workers, len(ready)))
    summary = BatchSummary(len(jobs), len(jobs) - len(todo), RUNNER_RAY if args.ray else RUNNER_PROCESSES, workers)
    start = time.monotonic()
    if todo:
        summary.interrupted = _run_with_progress(run, ready, missing, base, summary)
    summary.wall_seconds = time.monotonic() - start
    write_text_atomic(summary_path, json.dumps(summary.to_dict(), indent=2) + "\n")
    sys.stdout.write(summary.line() + f" | summary: {summary_path}\n")
    if summary.interrupted:
        return INTERRUPTED_EXIT
    return BATCH_FAILED_EXIT if summary.failures else 0


def _check_batch_flags(args: argparse.Namespace) -> Settings:
    """The settings every job starts from; refuses single-file flags mixed with --batch."""
    if args.audio is not None:
        raise UserError(f"give either an audio file ({args.audio}) or --batch DIR_OR_CSV, not both")
    if args.json is not None:
        raise UserError("with --batch, -o is the output folder: use --with-json for NAME.json beside each NAME.bvh")
    if args.vrma is not None:
        raise UserError("--vrma names one file; with --batch use --with-vrma for NAME.vrma beside each NAME.bvh")
    if args.output.exists() and not args.output.is_dir():
        raise UserError(f"with --batch, -o is the output folder, and {args.output} is a file")
    return settings_from_args(args)


def _split_missing(jobs: list[BatchJob]) -> tuple[list[BatchJob], list[JobResult]]:
    """The jobs whose audio is a regular file, and a failure for each of the others: a stat each, and no worker
    ever sees them (a CSV of many missing files no longer goes through the pool one file at a time)."""
    ready, missing = [], []
    for job in jobs:
        reason = job.missing_reason()
        if reason is None:
            ready.append(job)
        else:
            missing.append(JobResult(str(job.audio), error=reason))
    return ready, missing


def _ray_runner() -> Callable[[list[BatchJob], Settings, int, ResultSink], None]:
    """The Ray Data runner; without Ray installed, one line naming the extra (before any work)."""
    from gesturecast.realtime.jobs.batch_ray import import_ray, run_with_ray

    import_ray()
    return run_with_ray


def _run_with_progress(run: Callable, jobs: list[BatchJob], missing: list[JobResult], base: Settings,
                       summary: BatchSummary) -> bool:
    """Report the ``missing`` files' failures at once, then run the jobs, with a progress bar on stderr; True when
    Ctrl-C stopped the run."""
    from tqdm import tqdm  # loads asyncio: only a batch shows a progress bar
    from tqdm.contrib.logging import logging_redirect_tqdm

    total = len(jobs) + len(missing)
    with logging_redirect_tqdm(), tqdm(total=total, unit="file", desc="generate", file=sys.stderr) as bar:

        def on_result(result: JobResult) -> None:
            summary.add(result)
            if result.error is not None:
                logger.warning("failed: %s", result.reason_line())
            bar.update()

        try:
            for result in missing:
                on_result(result)
            if jobs:
                run(jobs, base, summary.workers, on_result)
        except KeyboardInterrupt:
            return True
    return False
