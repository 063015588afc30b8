"""Frame release on a fake clock: on-time order, deadline misses, bounded queue, 60 fps slerp midpoints."""

import threading

import numpy as np
import pytest

from gesturecast.frames import PoseFrame
from gesturecast.models.motion.rotations import quat_from_axis_angle, quat_to_axis_angle
from gesturecast.models.motion.skeleton import NUM_JOINTS
from gesturecast.realtime.timing.clock import FakeClock
from gesturecast.realtime.timing.latency import LatencyStats
from gesturecast.realtime.timing.scheduler import FrameScheduler, SchedulerConfig, SchedulerWorker

FPS = 30.0
LATENCY_S = 0.5


def make_frame(seq: int, angle: float = 0.0, latency_s: float = LATENCY_S) -> PoseFrame:
    """Frame ``seq``: every joint rotated by ``angle`` about Y, root at x = seq."""
    rotations = quat_from_axis_angle(np.tile([0.0, angle, 0.0], (NUM_JOINTS, 1)))  # (J, 4)
    capture = seq / FPS
    return PoseFrame(seq, capture, capture + latency_s, np.array([float(seq), 1.0, 0.0]), rotations)


class Recorder:
    """A sink that notes each frame and the clock time it was sent."""

    def __init__(self, clock: FakeClock) -> None:
        self.clock = clock
        self.frames: list[PoseFrame] = []
        self.times: list[float] = []

    def __call__(self, frame: PoseFrame) -> None:
        self.frames.append(frame)
        self.times.append(self.clock.now())


def setup(config: SchedulerConfig | None = None, stats: LatencyStats | None = None):
    clock = FakeClock()
    sink = Recorder(clock)
    return clock, sink, FrameScheduler(clock, sink, config, stats)


def test_frames_are_released_in_order_exactly_at_presentation_time():
    clock, sink, scheduler = setup()
    for seq in range(6):
        scheduler.submit(make_frame(seq))
    assert scheduler.pump() == 0  # nothing due before L
    scheduler.run_until(2.0)
    assert [f.seq for f in sink.frames] == list(range(6))
    assert sink.times == pytest.approx([seq / FPS + LATENCY_S for seq in range(6)], abs=1e-12)
    assert scheduler.stats.released == 6
    assert scheduler.stats.deadline_misses == 0
    assert scheduler.stats.max_lateness_s == pytest.approx(0.0, abs=1e-12)
    assert clock.now() == 2.0


def test_run_until_stops_before_frames_that_are_not_due():
    _, sink, scheduler = setup()
    for seq in range(10):
        scheduler.submit(make_frame(seq))
    scheduler.run_until(LATENCY_S + 2.5 / FPS)
    assert [f.seq for f in sink.frames] == [0, 1, 2]
    assert scheduler.pending == 7
    assert scheduler.flush() == 7
    assert scheduler.pending == 0


def test_late_frames_are_counted_and_still_sent_at_once():
    clock, sink, scheduler = setup()
    scheduler.submit(make_frame(0))
    clock.advance(LATENCY_S + 0.1)  # frame 1's deadline (0.533 s) has passed when it arrives
    scheduler.submit(make_frame(1))
    scheduler.submit(make_frame(30))  # due at 1.5 s: on time
    assert scheduler.pump() == 2
    assert scheduler.stats.deadline_misses == 1
    assert scheduler.stats.max_lateness_s == pytest.approx(0.6 - LATENCY_S)
    scheduler.flush()
    assert [f.seq for f in sink.frames] == [0, 1, 30]
    assert scheduler.stats.deadline_misses == 1


def test_queue_is_bounded_with_drop_oldest():
    _, sink, scheduler = setup(SchedulerConfig(max_pending=4))
    for seq in range(10):
        scheduler.submit(make_frame(seq))
    assert scheduler.pending == 4
    assert scheduler.stats.overflow_drops == 6
    scheduler.flush()
    assert [f.seq for f in sink.frames] == [6, 7, 8, 9]


def test_latency_stats_record_end_to_end_and_lateness():
    stats = LatencyStats(FakeClock())
    clock, _, scheduler = setup(stats=stats)
    for seq in range(5):
        scheduler.submit(make_frame(seq))
    scheduler.flush()
    summary = stats.summary()
    assert summary["end_to_end"]["count"] == 5
    assert summary["end_to_end"]["p50"] == pytest.approx(LATENCY_S * 1000)
    assert summary["release_lateness"]["max"] == pytest.approx(0.0, abs=1e-9)


def test_60fps_interleaves_exact_slerp_midpoints():
    _, sink, scheduler = setup(SchedulerConfig(output_fps=60.0))
    angles = [0.0, 0.4, 1.0, 1.2]
    for seq, angle in enumerate(angles):
        scheduler.submit(make_frame(seq, angle))
    scheduler.flush()
    frames = sink.frames
    assert [f.seq for f in frames] == list(range(7))
    expected_times = [LATENCY_S + k / 60.0 for k in range(7)]
    assert [f.presentation_time for f in frames] == pytest.approx(expected_times, abs=1e-12)
    assert sink.times == pytest.approx(expected_times, abs=1e-12)
    for k in range(len(angles) - 1):
        mid = frames[2 * k + 1]
        axis_angle = quat_to_axis_angle(mid.rotations)  # (J, 3)
        np.testing.assert_allclose(axis_angle[:, 1], (angles[k] + angles[k + 1]) / 2, atol=1e-12)
        np.testing.assert_allclose(mid.root_position, [k + 0.5, 1.0, 0.0], atol=1e-12)
        assert mid.capture_time == pytest.approx((k + 0.5) / FPS)
    np.testing.assert_allclose(frames[2].rotations, make_frame(1, angles[1]).rotations)


def test_60fps_skips_the_midpoint_across_a_sequence_gap():
    _, sink, scheduler = setup(SchedulerConfig(output_fps=60.0))
    for seq in (0, 1, 5):
        scheduler.submit(make_frame(seq))
    scheduler.flush()
    assert [f.seq for f in sink.frames] == [0, 1, 2, 10]


def test_60fps_midpoint_after_a_late_frame_is_a_miss():
    clock, _, scheduler = setup(SchedulerConfig(output_fps=60.0))
    scheduler.submit(make_frame(0))
    clock.advance(LATENCY_S + 1.5 / 60.0)  # past the midpoint's time, before frame 1's
    scheduler.submit(make_frame(1))
    assert scheduler.stats.deadline_misses == 1


def test_config_rejects_unsupported_output_rate():
    with pytest.raises(ValueError):
        SchedulerConfig(output_fps=45.0)


def test_worker_thread_releases_on_time_on_a_fake_clock():
    clock, sink, scheduler = setup()
    all_sent = threading.Event()
    count = 8

    def sink_and_signal(frame: PoseFrame) -> None:
        sink(frame)
        if len(sink.frames) == count:
            all_sent.set()

    scheduler.sink = sink_and_signal
    for seq in range(count):
        scheduler.submit(make_frame(seq))
    worker = SchedulerWorker(scheduler)
    worker.start()
    try:
        assert all_sent.wait(timeout=10.0)
    finally:
        worker.stop()
    assert [f.seq for f in sink.frames] == list(range(count))
    assert sink.times == pytest.approx([seq / FPS + LATENCY_S for seq in range(count)], abs=1e-12)


def test_an_idle_worker_sleeps_until_a_frame_is_submitted_and_stops_at_once():
    """With nothing queued the releaser waits for a submit, not a poll timer; the fake clock shows it: time does
    not move while it is idle, and a frame submitted later is released exactly at its time."""
    clock, sink, scheduler = setup()
    sent = threading.Event()
    scheduler.sink = lambda frame: (sink(frame), sent.set())
    worker = SchedulerWorker(scheduler)
    worker.start()
    try:
        assert not sent.wait(timeout=0.2)
        assert clock.now() == 0.0  # no polling sleeps while idle
        scheduler.submit(make_frame(3))
        assert sent.wait(timeout=10.0)
    finally:
        worker.stop(timeout_s=10.0)
    assert not worker.running  # the idle wait ended on stop
    assert sink.times == pytest.approx([3 / FPS + LATENCY_S], abs=1e-12)


def test_out_of_order_submission_is_refused():
    _, _, scheduler = setup()
    scheduler.submit(make_frame(3))
    with pytest.raises(ValueError):
        scheduler.submit(make_frame(2))


def test_worker_keeps_a_sink_error_for_the_engine():
    _, _, scheduler = setup()
    called = threading.Event()

    def broken_sink(frame: PoseFrame) -> None:
        called.set()
        raise OSError("network unreachable")

    scheduler.sink = broken_sink
    scheduler.submit(make_frame(0))
    worker = SchedulerWorker(scheduler)
    worker.start()
    assert called.wait(timeout=10.0)
    worker.stop(timeout_s=10.0)  # joins the thread, which ends on the error
    assert not worker.running
    assert isinstance(worker.error, OSError)


def test_a_frame_released_late_is_counted_even_when_computed_on_time():
    """Submitted before its deadline (no deadline miss) but released 200 ms late (a starved releaser or a
    blocking bridge): a late release. Within half a frame of its time: on time."""
    clock, _, scheduler = setup(stats=LatencyStats(FakeClock()))
    scheduler.submit(make_frame(0))
    scheduler.submit(make_frame(1))
    clock.advance(LATENCY_S + 0.010)  # frame 0 is 10 ms late: within half a frame
    assert scheduler.pump() == 1
    clock.advance(0.200)
    assert scheduler.pump() == 1
    counters = scheduler.stats.to_dict()
    assert (counters["deadline_misses"], counters["late_releases"]) == (0, 1)


def test_unpaced_frames_are_released_at_once_without_deadline_or_latency_records():
    """`live --pace fast`: presentation times are stream times, not clock times; nothing waits, nothing is
    a deadline miss and no end-to-end time (which would be the clock's uptime) is recorded."""
    stats = LatencyStats(FakeClock())
    clock, sink, scheduler = setup(SchedulerConfig(paced=False), stats)
    clock.advance(3600.0)  # an uptime far past every presentation time
    for seq in range(4):
        scheduler.submit(make_frame(seq))
    assert scheduler.pump() == 4 and [f.seq for f in sink.frames] == [0, 1, 2, 3]
    assert scheduler.stats.deadline_misses == scheduler.stats.late_releases == 0
    assert stats.count("end_to_end") == 0
