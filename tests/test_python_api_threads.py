"""gesturecast.Stream used from several threads at once: pushes (and words) are taken one at a time, so the stream
is never corrupted (before: "pop from an empty deque", "frames from 8 were already dropped", then close() raised)."""

from __future__ import annotations

import threading

import pytest

import gesturecast
from gesturecast.errors import UserError
from gesturecast.models.audio.files import PACKAGED_SAMPLE, SAMPLE_RATE, load_audio

THREADS = 4
BLOCK = 640  # 40 ms blocks, pushed as fast as each thread can
BLOCKS_PER_THREAD = 60


def test_pushes_and_words_from_several_threads_at_once_leave_the_stream_whole():
    audio = load_audio(PACKAGED_SAMPLE)[: THREADS * BLOCKS_PER_THREAD * BLOCK]  # (n,)
    errors: list[BaseException] = []
    with gesturecast.Stream(paced=False, warm=False) as stream:
        start = threading.Barrier(THREADS)

        def pusher(index: int) -> None:
            start.wait()
            try:
                for block in range(BLOCKS_PER_THREAD):
                    offset = (block * THREADS + index) * BLOCK
                    stream.push(audio[offset : offset + BLOCK], SAMPLE_RATE)
                    if block % 10 == 0:
                        stream.words([{"word": "hello", "start": stream.audio_seconds + 1.0}])
            except BaseException as error:  # noqa: BLE001 - any failure in a thread fails the test below
                errors.append(error)

        threads = [threading.Thread(target=pusher, args=(index,)) for index in range(THREADS)]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
        assert errors == []
        frames = stream.close()
        report = stream.report()
    assert report.audio_seconds == len(audio) / SAMPLE_RATE
    assert report.frames == round(len(audio) / SAMPLE_RATE * 30) and len(frames) > 0


def test_words_far_ahead_of_the_stream_are_refused_in_one_line():
    with gesturecast.Stream(paced=False, warm=False) as stream:
        stream.push(load_audio(PACKAGED_SAMPLE)[:SAMPLE_RATE], SAMPLE_RATE)
        with pytest.raises(UserError, match=r"is .* s ahead of the stream"):
            stream.words([{"word": "hello", "start": 1e6}])
        assert stream.words([{"word": "hello", "start": 2.0}]) == 1
