"""``serve --workers``: the wrong-token limit counted across the workers, in one file they share.

Each worker is a whole server with its own :class:`~gesturecast.bridges.ws_access.AccessPolicy`; counted per worker,
five wrong tokens took eight tries with two workers. The parent creates a small file (:func:`shared_failures_file`,
removed when the run stops) and every worker keeps its :class:`FailedTokens` in it: each check and each wrong token
reads the table, and a wrong token writes it back, under an exclusive ``flock`` (the kernel releases it when a
worker dies holding it). The times are ``time.monotonic``, one clock for every process of the machine. A table that
cannot be read (a worker killed in the middle of a write) starts empty: the limit forgets, it never locks anyone
out by mistake.
"""

from __future__ import annotations

import json
import os
import tempfile
from collections import OrderedDict, deque
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

from gesturecast.bridges.ws_access import FailedTokens


def shared_failures_file() -> Path:
    """A new empty table file for one ``serve --workers`` run (the caller removes it)."""
    descriptor, name = tempfile.mkstemp(prefix="gesturecast-serve-token-failures-", suffix=".json")
    os.close(descriptor)
    return Path(name)


def shared_failures(path: Path | None, clock: Callable[[], float]) -> SharedFailedTokens | None:
    """The table shared with the other workers in ``path``; None for a server on its own (its own table)."""
    return None if path is None else SharedFailedTokens(path, clock)


class SharedFailedTokens(FailedTokens):
    """:class:`FailedTokens` kept in ``path``, shared with the other workers (module docstring)."""

    def __init__(self, path: Path, clock: Callable[[], float]) -> None:
        super().__init__(clock)
        self.path = path

    def record(self, address: str) -> None:
        with self._table(write=True):
            super().record(address)

    def blocked(self, address: str) -> bool:
        with self._table(write=False):
            return super().blocked(address)

    @contextmanager
    def _table(self, write: bool) -> Iterator[None]:
        """The table read from the file, held under the lock, written back when ``write``."""
        import fcntl  # here: the module imports on Windows too, where serve --workers does not run

        with open(self.path, "r+", encoding="utf-8") as handle:
            fcntl.flock(handle, fcntl.LOCK_EX)  # released when the file closes
            self._failures = self._parsed(handle.read())
            yield
            if write:
                handle.seek(0)
                handle.truncate()
                handle.write(json.dumps([[key, list(times)] for key, times in self._failures.items()]))

    def _parsed(self, text: str) -> OrderedDict[str, deque[float]]:
        try:
            rows = json.loads(text) if text else []
            return OrderedDict((str(key), deque(map(float, times), maxlen=self.limit)) for key, times in rows)
        except (ValueError, TypeError):
            return OrderedDict()
