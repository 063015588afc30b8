"""The log throttle: the first message of an interval is logged, the others counted into the next line."""

import logging

from gesturecast.log_throttle import ThrottledLog


def test_a_flood_gives_one_line_per_interval_with_the_count_of_the_others(caplog):
    now = [0.0]
    log = ThrottledLog(logging.getLogger("throttle-test"), interval_s=5.0, clock=lambda: now[0])
    with caplog.at_level(logging.INFO):
        for step in range(100):  # 10 s of a message every 0.1 s
            now[0] = step * 0.1
            log.log(logging.INFO, f"cue {step}")
    assert [record.getMessage() for record in caplog.records] == [
        "cue 0", "cue 50 (49 more like it in the last 5 s not logged)"]
