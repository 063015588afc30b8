"""``--load N``: the competing CPU-bound processes run for the measurement and are always stopped after it."""

import subprocess

import pytest

from gesturecast.errors import UserError
from gesturecast.tools.bench.timing import load


@pytest.fixture
def started(monkeypatch):
    """The spinner processes competing_load starts (real processes, recorded)."""
    processes = []
    real_popen = subprocess.Popen

    def recording_popen(*args, **kwargs):
        process = real_popen(*args, **kwargs)
        processes.append(process)
        return process

    monkeypatch.setattr(load.subprocess, "Popen", recording_popen)
    return processes


def test_the_spinners_run_during_the_body_and_are_stopped_after(started):
    with load.competing_load(2) as record:
        assert len(started) == 2 and all(process.poll() is None for process in started)
    assert all(process.poll() is not None for process in started)
    assert record["processes"] == 2
    assert set(record) == {"processes", "loadavg_before", "loadavg_after"}


def test_the_spinners_are_stopped_when_the_run_raises_or_is_interrupted(started):
    for error in (RuntimeError, KeyboardInterrupt):
        with pytest.raises(error), load.competing_load(1):
            raise error()
    assert len(started) == 2 and all(process.poll() is not None for process in started)


def test_no_load_starts_nothing(started):
    with load.competing_load(0) as record:
        assert record["processes"] == 0
    assert started == []


def test_a_load_out_of_range_is_refused(started):
    with pytest.raises(UserError, match="--load"), load.competing_load(-1):
        pass
    assert started == []
