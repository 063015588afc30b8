"""The degradation ladder's decisions from the share of the compute margin each burst used."""

from gesturecast.realtime.timing.ladder import DegradationLadder, LadderConfig

CONFIG = LadderConfig(step_down_at=0.9, late_at=1.0, climb_below=0.5, climb_after=4, smoothing=0.25)


def fed(ladder: DegradationLadder, shares: list[float]) -> list[int]:
    return [ladder.observe(share) for share in shares]


def test_bursts_with_slack_stay_on_the_full_rung():
    ladder = DegradationLadder(3, CONFIG)
    assert fed(ladder, [0.3, 0.6, 0.8, 0.4] * 10) == [0] * 40
    assert ladder.to_dict() == {"rung": 0, "bursts_per_rung": [40, 0, 0], "rung_changes": 0}


def test_one_late_burst_steps_one_rung_down_at_once():
    ladder = DegradationLadder(3, CONFIG)
    assert fed(ladder, [0.3, 1.2]) == [0, 1]


def test_a_margin_used_up_little_by_little_steps_down_on_the_moving_estimate():
    ladder = DegradationLadder(3, CONFIG)
    rungs = fed(ladder, [0.99] * 12)
    assert rungs[0] == 0 and rungs[-1] == 1  # no single burst missed; the estimate crossed 0.9, once


def test_the_ladder_stops_at_its_cheapest_rung():
    ladder = DegradationLadder(3, CONFIG)
    assert fed(ladder, [2.0] * 5) == [1, 2, 2, 2, 2]
    assert ladder.counts == [1, 1, 3]


def test_it_climbs_one_rung_after_a_run_of_slack_bursts_and_not_before():
    ladder = DegradationLadder(3, CONFIG)
    fed(ladder, [2.0, 2.0])
    assert fed(ladder, [0.2, 0.2, 0.2, 0.6, 0.2, 0.2, 0.2]) == [2] * 7  # the run broke at 0.6
    assert fed(ladder, [0.2]) == [1]
    assert fed(ladder, [0.2] * 4) == [1, 1, 1, 0]
    assert ladder.changes == 4
