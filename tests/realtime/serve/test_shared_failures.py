"""serve --workers: the wrong-token limit counts across the workers (one table in a file they share)."""

import pytest

from gesturecast.bridges.ws_access import MAX_TOKEN_FAILURES
from gesturecast.realtime.serve.server import ServeConfig
from gesturecast.realtime.serve.shared_failures import SharedFailedTokens, shared_failures_file
from gesturecast.realtime.serve.workers import Workers
from gesturecast.realtime.timing.clock import FakeClock
from gesturecast.settings import Settings


@pytest.fixture
def table():
    path = shared_failures_file()
    yield path
    path.unlink(missing_ok=True)


def test_wrong_tokens_sent_to_two_workers_count_together(table):
    """With --workers 2 it took 8 wrong tokens before the first 429, not the documented 5."""
    clock = FakeClock()
    first, second = SharedFailedTokens(table, clock.now), SharedFailedTokens(table, clock.now)
    for attempt in range(MAX_TOKEN_FAILURES):
        (first if attempt % 2 else second).record("198.51.100.4")
    assert first.blocked("198.51.100.4") and second.blocked("198.51.100.4")
    assert not first.blocked("198.51.100.5")


def test_a_torn_table_starts_empty_instead_of_locking_anyone_out(table):
    table.write_text('[["198.51.100.4", [1.0, 2.')  # a worker killed in the middle of a write
    assert not SharedFailedTokens(table, FakeClock().now).blocked("198.51.100.4")


def test_the_workers_share_one_table_that_the_parent_removes():
    workers = Workers(Settings(), ServeConfig(host="127.0.0.1", port=0), 2)
    shared = workers.token_failures
    assert workers._worker_args[1].token_failures == shared and shared.is_file()
    workers.stop()
    assert not shared.exists()
