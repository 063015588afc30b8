"""The words' work on the words worker: the stream's thread hands it over and generates on, never waiting; what was
decided is placed at a later latent (late, when its window was already generated)."""

import threading
from unittest import mock

import numpy as np

import gesturecast
from gesturecast.models.audio.files import SAMPLE_RATE
from gesturecast.realtime.gestures.director import GestureDirector
from gesturecast.realtime.words.worker import WordsWorker

BLOCK_S = 30.0  # the worker's blocking job gives up after this: a push that waited for it would see it done
WORDS = [{"word": "Hello", "start": 0.5, "end": 0.8}, {"word": "everyone.", "start": 0.8, "end": 1.2}]


def test_frames_are_generated_while_the_worker_is_busy(monkeypatch):
    placed = mock.MagicMock(wraps=GestureDirector.place_word_cues)
    monkeypatch.setattr(GestureDirector, "place_word_cues", lambda self, *args: placed(self, *args))
    gate, blocked_job_done = threading.Event(), threading.Event()

    def busy() -> None:
        gate.wait(BLOCK_S)
        blocked_job_done.set()

    with gesturecast.Stream(paced=False, warm=False) as stream:
        director = stream.session.gestures
        director.start_worker()
        director.worker.submit(busy)
        stream.control(words=WORDS)  # applied at the next latent, on the stream's thread
        frames = stream.push(np.zeros(2 * SAMPLE_RATE, np.float32), SAMPLE_RATE)
        assert frames and not blocked_job_done.is_set()  # generated without waiting for the worker
        assert not [call for call in placed.call_args_list if call.args[1] or call.args[2]]
        gate.set()
        director.worker.submit(lambda: None).result()  # the worker has decided the words by now
        stream.push(np.zeros(SAMPLE_RATE // 2, np.float32), SAMPLE_RATE)
        sources = [cue.source for call in placed.call_args_list for cue in (*call.args[1], *call.args[2])]
    assert sources == ["Hello"]


def test_a_full_worker_refuses_a_job_at_once():
    worker = WordsWorker(max_jobs=1)
    gate, started = threading.Event(), threading.Event()
    worker.submit(lambda: (started.set(), gate.wait(BLOCK_S)))
    started.wait(BLOCK_S)  # running: the queue is empty again
    worker.submit(lambda: None)  # queued: the queue is full
    refused = worker.submit(lambda: None)
    assert worker.refused == 1 and isinstance(refused.exception(timeout=0), RuntimeError)
    gate.set()
    worker.close()
