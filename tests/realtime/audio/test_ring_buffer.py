import threading

import numpy as np
import pytest

from gesturecast.realtime.audio.ring_buffer import RingBuffer


def test_fifo_order_and_wraparound():
    ring = RingBuffer(10)
    ring.write(np.arange(6, dtype=np.float32), 1.0)
    assert ring.read(4).samples.tolist() == [0, 1, 2, 3]
    ring.write(np.arange(6, 12, dtype=np.float32), 2.0)
    read = ring.read(100)
    assert read.samples.tolist() == list(range(4, 12)) and read.start_index == 4
    assert ring.stats().skipped_samples == 0


def test_a_write_into_a_full_ring_skips_the_oldest_and_counts_it():
    ring = RingBuffer(8)
    ring.write(np.arange(5, dtype=np.float32), 0.0)
    ring.write(np.arange(5, 10, dtype=np.float32), 0.1)  # 2 too many
    ring.write(np.arange(10, 30, dtype=np.float32), 0.2)  # larger than the ring
    read = ring.read(100)
    assert read.samples.tolist() == list(range(22, 30)) and read.start_index == 22
    stats = ring.stats()
    assert (stats.written_samples, stats.read_samples, stats.skipped_samples, stats.skips) == (30, 8, 22, 2)


def test_skip_passes_over_the_oldest_unread_samples_on_purpose():
    ring = RingBuffer(16)
    ring.write(np.arange(12, dtype=np.float32), 0.0)
    assert ring.skip(9) == 9
    read = ring.read(100)
    assert read.samples.tolist() == [9, 10, 11] and read.start_index == 9
    assert ring.skip(5) == 0  # nothing unread: nothing skipped, no event
    stats = ring.stats()
    assert (stats.read_samples, stats.skipped_samples, stats.skips) == (3, 9, 1)


def test_every_sample_is_read_skipped_or_still_waiting_across_wraparounds():
    ring = RingBuffer(7)
    rng = np.random.default_rng(0)
    received, next_value = [], 0
    for _ in range(300):
        count = int(rng.integers(1, 10))
        ring.write(np.arange(next_value, next_value + count, dtype=np.float32), 0.0)
        next_value += count
        if rng.random() < 0.2:
            ring.skip(int(rng.integers(0, 6)))
        read = ring.read(int(rng.integers(1, 8)))
        indices = range(read.start_index, read.start_index + read.samples.shape[0])
        received.extend(zip(indices, read.samples, strict=True))
        stats = ring.stats()
        assert stats.written_samples == stats.read_samples + stats.skipped_samples + ring.available
    assert all(index == value for index, value in received)  # each sample read at its own stream index
    assert [index for index, _ in received] == sorted({index for index, _ in received})  # in order, never twice


def test_timestamp_anchor_follows_the_latest_write():
    ring = RingBuffer(100)
    ring.write(np.zeros(10, np.float32), 5.0)
    ring.write(np.zeros(10, np.float32), 6.0)
    read = ring.read(20)
    assert (read.time_index, read.write_time) == (10, 6.0)


def test_one_producer_one_consumer_threads_lose_nothing_when_fast_enough():
    ring = RingBuffer(1 << 16)
    blocks = [np.arange(i * 64, (i + 1) * 64, dtype=np.float32) for i in range(500)]

    def produce():
        for block in blocks:
            ring.write(block, 0.0)

    producer = threading.Thread(target=produce)
    producer.start()
    received = []
    while sum(r.shape[0] for r in received) < 500 * 64:
        received.append(ring.read(1000, timeout=0.05).samples)
    producer.join()
    np.testing.assert_array_equal(np.concatenate(received), np.arange(500 * 64, dtype=np.float32))


def test_capacity_must_be_positive():
    with pytest.raises(ValueError):
        RingBuffer(0)


def test_skip_behind_keeps_the_newest_audio_only_past_the_limit():
    ring = RingBuffer(100)
    ring.write(np.arange(40, dtype=np.float32), 0.0)
    assert ring.skip_behind(limit=40, keep=8) == 0  # at the limit: every sample can still be answered
    ring.write(np.arange(40, 50, dtype=np.float32), 0.1)
    assert ring.skip_behind(limit=40, keep=8) == 42
    read = ring.read(100)
    assert read.samples.tolist() == list(range(42, 50)) and read.start_index == 42
    stats = ring.stats()
    assert (stats.written_samples, stats.read_samples, stats.skipped_samples, stats.skips) == (50, 8, 42, 1)
