"""``generate --batch --ray``: the same jobs on Ray Data, one actor per CPU, each loading the bundle once.

``ray.data.from_items`` holds one row per file (one block each, so idle actors take the next file),
``map_batches`` runs :class:`RayBatchActor` on an actor pool of ``workers`` actors with one file per
call, and the results stream back to the caller's progress bar as they complete. Ray runs locally
(``ray.init(num_cpus=workers)``, no dashboard) and is shut down at the end. Ray is an optional extra,
imported only here and only for ``--ray``.
"""

from __future__ import annotations

import json
import logging
from pathlib import Path

import numpy as np

from gesturecast.errors import UserError
from gesturecast.realtime.jobs.batch import BatchWorker, JobResult, ResultSink
from gesturecast.realtime.jobs.batch_jobs import BatchJob
from gesturecast.settings import Settings

logger = logging.getLogger(__name__)

FILES_PER_CALL = 1  # one file per actor call: a long file never holds short ones back
NO_FILE = ""  # an output a job does not write (JSON, VRMA), in a row (Ray rows hold no None)
INSTALL_HINT = "pip install 'gesturecast[scale]'"


def import_ray():
    """The ``ray`` module, or one line saying how to install it."""
    try:
        import ray
        import ray.data  # noqa: F401  # the Data library comes with the [data] extra only
    except ImportError as error:
        raise UserError(f"--ray needs Ray Data ({error.name} is not installed): {INSTALL_HINT}") from None
    return ray


def job_row(job: BatchJob) -> dict:
    """A job as a Ray Data row (strings only)."""
    return {"audio": str(job.audio), "bvh": str(job.bvh), "json": NO_FILE if job.json is None else str(job.json),
            "vrma": NO_FILE if job.vrma is None else str(job.vrma), "overrides": json.dumps(job.overrides),
            "transcript": NO_FILE if job.transcript is None else str(job.transcript)}


def row_job(row: dict) -> BatchJob:
    """The job of a row made by :func:`job_row`."""
    return BatchJob(Path(row["audio"]), Path(row["bvh"]), _path(row["json"]), json.loads(row["overrides"]),
                    _path(row["vrma"]), _path(row["transcript"]))


def _path(cell: str) -> Path | None:
    return None if cell == NO_FILE else Path(cell)


class RayBatchActor:
    """A Ray Data actor: the bundle loaded once in its constructor, then one batch of rows per call."""

    def __init__(self, base: Settings) -> None:
        self.worker = BatchWorker(base)

    def __call__(self, batch: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        rows = [dict(zip(batch, values, strict=True)) for values in zip(*batch.values(), strict=True)]
        results = [self.worker(row_job(row)) for row in rows]
        return {"audio": np.array([r.audio for r in results]),
                "audio_seconds": np.array([r.audio_seconds for r in results], np.float64),
                "error": np.array([r.error or "" for r in results])}


def run_with_ray(jobs: list[BatchJob], base: Settings, workers: int, on_result: ResultSink) -> None:
    """The jobs on a local Ray with ``workers`` CPUs; ``on_result`` sees each result as it completes."""
    ray = import_ray()
    ray.init(num_cpus=workers, include_dashboard=False, log_to_driver=False, configure_logging=False)
    try:
        ray.data.DataContext.get_current().enable_progress_bars = False  # the batch has its own bar
        dataset = ray.data.from_items([job_row(job) for job in jobs], override_num_blocks=len(jobs))
        results = dataset.map_batches(RayBatchActor, fn_constructor_args=(base,), batch_size=FILES_PER_CALL,
                                      concurrency=workers, num_cpus=1)
        for row in results.iter_rows():
            on_result(JobResult(str(row["audio"]), float(row["audio_seconds"]), str(row["error"]) or None))
    finally:
        ray.shutdown()
