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
    assert ring.stats().dropped_samples == 0


def test_overrun_drops_oldest_and_counts():
    ring = RingBuffer(8)
    ring.write(np.arange(5, dtype=np.float32), 0.0)
    ring.write(np.arange(5, 10, dtype=np.float32), 0.1)  # 2 too many
    ring.write(np.arange(10, 30, dtype=np.float32), 0.2)  # larger than the ring
    read = ring.read(100)
    assert read.samples.tolist() == list(range(22, 30)) and read.start_index == 22
    stats = ring.stats()
    assert (stats.written_samples, stats.dropped_samples, stats.overruns) == (30, 22, 2)


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
