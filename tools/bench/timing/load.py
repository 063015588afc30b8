"""A standard competing load for the benchmarks: N CPU-bound processes at the user's own priority.

``--load N`` stands in for what shares a live avatar's machine (a game, OBS, other people's streams): each
process spins on one core until the run ends. They start before the measured run, and :func:`competing_load`
stops them when it ends, also when it raised or was interrupted (Ctrl-C). The JSON names the number of
processes and the system load average before and after, so a figure measured on a machine that was already
busy says so.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager

from gesturecast.errors import UserError

SPIN_PROGRAM = "while True: pass"  # one core's worth of pure CPU, no memory, no I/O
STOP_WAIT_S = 5.0  # after a terminate, this long before a kill
MAX_LOAD = 64


def add_load_argument(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--load", type=int, default=0, metavar="N",
                        help="run N CPU-bound processes at your own priority during the measurement, as a game or "
                             f"other streams would (0..{MAX_LOAD}; default 0)")


def load_averages() -> list[float] | None:
    """The system's 1, 5 and 15 minute load averages (None where the OS has none)."""
    try:
        return [round(value, 2) for value in os.getloadavg()]
    except (AttributeError, OSError):
        return None


@contextmanager
def competing_load(processes: int) -> Iterator[dict]:
    """N spinning processes for the ``with`` body; yields the JSON record, completed with the load after."""
    if not 0 <= processes <= MAX_LOAD:
        raise UserError(f"--load must be within 0..{MAX_LOAD}, got {processes}")
    record = {"processes": processes, "loadavg_before": load_averages()}
    spinners: list[subprocess.Popen] = []
    try:
        spinners.extend(subprocess.Popen([sys.executable, "-c", SPIN_PROGRAM], stdin=subprocess.DEVNULL)
                        for _ in range(processes))
        yield record
    finally:
        record["loadavg_after"] = load_averages()
        stop(spinners)


def stop(spinners: list[subprocess.Popen]) -> None:
    """Terminate every spinner and reap it (kill one that does not end within :data:`STOP_WAIT_S`)."""
    for spinner in spinners:
        spinner.terminate()
    for spinner in spinners:
        try:
            spinner.wait(STOP_WAIT_S)
        except subprocess.TimeoutExpired:
            spinner.kill()
            spinner.wait()
