"""SIGTERM and SIGHUP as Ctrl-C (gesturecast.stop_signals): raised once in the main thread while handled, the
signal's exit status, an ignored signal left ignored, the previous handlers back afterwards."""

from __future__ import annotations

import os
import signal
import time

import pytest

from gesturecast import stop_signals
from gesturecast.errors import INTERRUPTED_EXIT

HANDLER_S = 0.01  # a sleep in which Python runs the handler of a signal sent to itself

pytestmark = pytest.mark.skipif(not hasattr(signal, "SIGHUP"), reason="SIGTERM is not sent between processes here")


def test_sigterm_raises_once_names_itself_and_gives_143():
    with stop_signals.handled():
        with pytest.raises(KeyboardInterrupt) as stopped:
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(HANDLER_S)  # the handler runs here
        os.kill(os.getpid(), signal.SIGHUP)  # a second stop signal while stopping: ignored
        time.sleep(HANDLER_S)
        assert stopped.value.signum == signal.SIGTERM and stop_signals.stopped_by() == "SIGTERM"
        assert stop_signals.exit_status(INTERRUPTED_EXIT) == 143 and stop_signals.exit_status(2) == 2


def test_the_previous_handlers_come_back_and_an_ignored_signal_stays_ignored():
    previous = signal.signal(signal.SIGHUP, signal.SIG_IGN)  # as under nohup
    try:
        term = signal.getsignal(signal.SIGTERM)
        with stop_signals.handled():
            assert signal.getsignal(signal.SIGHUP) is signal.SIG_IGN
            assert signal.getsignal(signal.SIGTERM) is not term
            assert stop_signals.stopped_by() == "Ctrl-C"  # nothing received yet
        assert signal.getsignal(signal.SIGTERM) is term
    finally:
        signal.signal(signal.SIGHUP, previous)
