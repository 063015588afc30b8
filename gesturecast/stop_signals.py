"""SIGTERM and SIGHUP stop a command the way Ctrl-C does.

A service manager (systemd, Docker) stops a process with SIGTERM, and a closed terminal sends SIGHUP.
Left to their default, either kills Python at once: no summary, a recording stranded in its temporary
file, WebSocket clients cut off (1006), a batch's worker processes orphaned. While :func:`handled` is
active (the CLI's ``main``), each of them raises :class:`StopSignal`, a ``KeyboardInterrupt``, in the main
thread, so every command ends through its Ctrl-C path: bounded, with its summary, its outputs closed
and its workers stopped.

- The exit status is 128 + the signal's number, as a shell reports a process ended by that signal:
  130 for Ctrl-C (:data:`~gesturecast.errors.INTERRUPTED_EXIT`), 143 for SIGTERM, 129 for SIGHUP.
- A signal the process was started with ignored stays ignored (``nohup`` ignores SIGHUP).
- Only the first stop signal raises; later ones are logged and ignored, so the shutdown it started is
  not cut short (Ctrl-C still raises, and SIGKILL still ends everything).
- Windows has no SIGHUP; only the signals the platform has are handled.
"""

from __future__ import annotations

import logging
import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager, suppress

from gesturecast.errors import INTERRUPTED_EXIT

logger = logging.getLogger(__name__)

STOP_SIGNALS: tuple[signal.Signals, ...] = tuple(
    getattr(signal, name) for name in ("SIGTERM", "SIGHUP") if hasattr(signal, name))
SIGNAL_EXIT_BASE = 128  # a shell reports a process ended by signal N as status 128 + N

_received: signal.Signals | None = None  # the first stop signal while handled() is active


class StopSignal(KeyboardInterrupt):
    """SIGTERM or SIGHUP arrived: the command stops as after Ctrl-C."""

    def __init__(self, signum: int) -> None:
        super().__init__(signal.Signals(signum).name)
        self.signum = signal.Signals(signum)


def _raise_stop(signum: int, _frame: object) -> None:
    """The handler: the first stop signal raises :class:`StopSignal`, later ones are only logged."""
    global _received
    if _received is not None:
        logger.info("%s: already stopping (on %s)", signal.Signals(signum).name, _received.name)
        return
    _received = signal.Signals(signum)
    logger.info("%s: stopping as after Ctrl-C", _received.name)
    raise StopSignal(signum)


@contextmanager
def handled() -> Iterator[None]:
    """SIGTERM / SIGHUP raise :class:`StopSignal` in the main thread inside the block; the previous handlers
    come back after it. Outside the main thread (where Python cannot handle signals) nothing changes."""
    global _received
    _received = None
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {signum: signal.getsignal(signum) for signum in STOP_SIGNALS}
    for signum, handler in previous.items():
        if handler is not signal.SIG_IGN:
            signal.signal(signum, _raise_stop)
    try:
        yield
    finally:
        for signum, handler in previous.items():
            with suppress(TypeError):  # a handler installed from C is reported as None and cannot be restored
                signal.signal(signum, handler)


def received() -> signal.Signals | None:
    """The stop signal that ended the run, or None (no signal, or Ctrl-C)."""
    return _received


def stopped_by() -> str:
    """What stopped the run, for its summary line: ``"SIGTERM"``, ``"SIGHUP"`` or ``"Ctrl-C"``."""
    return "Ctrl-C" if _received is None else _received.name


def exit_status(status: int) -> int:
    """A command's exit status, with the Ctrl-C status turned into the stop signal's (143 for SIGTERM)."""
    if status == INTERRUPTED_EXIT and _received is not None:
        return SIGNAL_EXIT_BASE + int(_received)
    return status


@contextmanager
def shielded_children() -> Iterator[None]:
    """Processes started inside the block (a process pool's server) begin with the stop signals blocked.

    A blocked signal stays blocked across fork and exec, so they never receive SIGTERM / SIGHUP sent to the
    whole process group (systemd stops every process of a service, a terminal hangs up on its whole job):
    the parent, which gets them too, stops its workers in order. The parent's own signals arriving while it
    is blocked wait and are delivered at the end of the block.
    """
    if not hasattr(signal, "pthread_sigmask") or not STOP_SIGNALS:
        yield
        return
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, STOP_SIGNALS)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)
