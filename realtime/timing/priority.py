"""Thread priority where the operating system grants it without root; never required, never an error.

The live path has two threads whose wake-up time is the deadline: the audio callback (PortAudio's thread)
and the stream thread that turns audio into poses. Next to a game or other streams at the same priority,
each waits for a core and, in Python, for the interpreter lock (GIL) as well:

- :func:`raise_thread_priority` asks for the calling thread: on Linux a real-time class (``SCHED_RR``)
  where ``RLIMIT_RTPRIO`` allows one (``ulimit -r``, e.g. the ``audio`` group's limits), else a lower nice
  value where ``RLIMIT_NICE`` allows it (``ulimit -e``); elsewhere nothing (macOS and Windows give a
  Python thread no such call without extra packages). A refusal leaves the thread as it was and says so
  in one debug line.
- :func:`live_switch_interval` shortens the interpreter's switch interval during a paced run (and while a
  microphone is open), so the audio callback and the frame release thread get the GIL within about 1 ms
  instead of 5 ms from a stream thread busy in Python: a callback that waits 5 ms per block cannot catch up
  after a hiccup, and a release that waits leaves late (measured, docs/latency.md).
"""

from __future__ import annotations

import logging
import os
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager

logger = logging.getLogger(__name__)

REALTIME_PRIORITY = 10  # SCHED_RR priority asked for (1..99; low: above every normal thread, below the kernel's)
RAISED_NICENESS = -5  # nice value asked for where RLIMIT_NICE allows it (never below what the limit grants)
LIVE_SWITCH_INTERVAL_S = 0.001  # interpreter switch interval during a live run (Python's default: 5 ms)
NICE_LIMIT_BASE = 20  # RLIMIT_NICE is 20 - lowest nice value allowed (Linux getrlimit(2))


def raise_thread_priority() -> str:
    """Raise the calling thread's priority as far as allowed; returns what it got ("realtime", "nice N",
    or "unchanged")."""
    thread_id = threading.get_native_id()
    if _realtime_allowed():
        try:
            os.sched_setscheduler(thread_id, os.SCHED_RR, os.sched_param(REALTIME_PRIORITY))
            return "realtime"
        except OSError as error:
            logger.debug("real-time scheduling refused for thread %d (%s)", thread_id, error)
    niceness = _lowest_niceness_allowed()
    if niceness is None:
        logger.debug("thread priority unchanged: this system grants no higher priority without rights")
        return "unchanged"
    try:
        os.setpriority(os.PRIO_PROCESS, thread_id, niceness)  # Linux: a native thread id is a "process" here
    except OSError as error:
        logger.debug("thread priority unchanged for thread %d (%s)", thread_id, error)
        return "unchanged"
    return f"nice {niceness}"


def _realtime_allowed() -> bool:
    if not hasattr(os, "sched_setscheduler") or not hasattr(os, "SCHED_RR"):
        return False
    return _soft_limit("RLIMIT_RTPRIO") >= REALTIME_PRIORITY


def _lowest_niceness_allowed() -> int | None:
    """The nice value to ask for (≤ the current one), or None when nothing lower is allowed or possible."""
    if not sys.platform.startswith("linux"):
        return None
    current = os.getpriority(os.PRIO_PROCESS, threading.get_native_id())
    lowest = max(RAISED_NICENESS, NICE_LIMIT_BASE - _soft_limit("RLIMIT_NICE"))
    return lowest if lowest < current else None


def _soft_limit(name: str) -> int:
    """A resource limit's soft value (0 where the OS or Python lacks it; unlimited counts as very large)."""
    try:
        import resource
    except ImportError:  # Windows
        return 0
    if not hasattr(resource, name):
        return 0
    soft = resource.getrlimit(getattr(resource, name))[0]
    return sys.maxsize if soft == resource.RLIM_INFINITY else soft


@contextmanager
def live_switch_interval(seconds: float = LIVE_SWITCH_INTERVAL_S) -> Iterator[None]:
    """The interpreter's switch interval shortened to ``seconds`` for the ``with`` body (restored after; never
    lengthened)."""
    previous = sys.getswitchinterval()
    sys.setswitchinterval(min(previous, seconds))
    try:
        yield
    finally:
        sys.setswitchinterval(previous)
