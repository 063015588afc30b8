"""Thread priority: asked for, never required (this test runs without any rights to raise it)."""

import sys
import threading

from gesturecast.realtime.timing.priority import LIVE_SWITCH_INTERVAL_S, live_switch_interval, raise_thread_priority


def test_raising_priority_without_rights_falls_back_quietly():
    results = []
    thread = threading.Thread(target=lambda: results.append(raise_thread_priority()))
    thread.start()
    thread.join()
    assert results[0] == "realtime" or results[0] == "unchanged" or results[0].startswith("nice ")


def test_switch_interval_is_short_inside_and_restored_after():
    before = sys.getswitchinterval()
    with live_switch_interval():
        assert sys.getswitchinterval() <= LIVE_SWITCH_INTERVAL_S + 1e-9
    assert sys.getswitchinterval() == before


def test_switch_interval_is_restored_when_the_body_raises():
    before = sys.getswitchinterval()
    try:
        with live_switch_interval():
            raise RuntimeError("the stream ended with an error")
    except RuntimeError:
        pass
    assert sys.getswitchinterval() == before
