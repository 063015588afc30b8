"""The face besides the mouth: blink rate, length and placement, expressions from labels and free text, the
modes, and the same face streamed and offline."""

from __future__ import annotations

import numpy as np
import pytest

from gesturecast.frames import EXPRESSION_PRESETS, FACE_NAMES
from gesturecast.models.audio.files import PACKAGED_SAMPLE, SAMPLE_RATE, load_audio
from gesturecast.models.generator.style_prompt import StylePrompt
from gesturecast.models.generator.style_text import StyleTextEmbedder
from gesturecast.realtime.audio.sources import AudioChunk
from gesturecast.realtime.pose.face import BLINK_SHAPES, ExpressionDynamics, Expressions, FaceAnimator
from gesturecast.realtime.run.engine_setup import build_session
from gesturecast.realtime.timing.clock import MonotonicClock
from gesturecast.settings import FACE_BLINK, FACE_FULL, Settings

FPS = 30
MINUTES = 10


def blinks_of(lids: np.ndarray) -> list[tuple[int, int]]:
    """(first, last) frame of each blink in a (T,) lid closure track."""
    closed = np.r_[0, (lids > 0.05).astype(int), 0]
    edges = np.diff(closed)
    return list(zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1, strict=True))


def face_track(speaking: np.ndarray, seed: int = 0, mode: str = FACE_BLINK) -> np.ndarray:
    animator = FaceAnimator(mode, seed, Expressions())
    return animator.frames(np.arange(len(speaking)) / FPS, list(speaking))  # (T, 8)


@pytest.mark.parametrize(("speaking", "low", "high"), [(False, 15, 20), (True, 8, 14)])
def test_blinks_at_a_natural_rate_fewer_while_speaking(speaking, low, high):
    lids = face_track(np.full(MINUTES * 60 * FPS, speaking))[:, 0]
    blinks = blinks_of(lids)
    assert low <= len(blinks) / MINUTES <= high
    lengths = np.array([last - first + 1 for first, last in blinks]) / FPS  # seconds above 5 % closure
    assert lengths.max() <= 0.25  # 100-150 ms blinks, or two of them back to back
    assert np.median([lids[first : last + 1].max() for first, last in blinks]) > 0.95  # the lid shuts


def test_blinks_gather_in_the_pauses_and_both_eyes_move_together():
    phrase = np.r_[np.ones(4 * FPS, bool), np.zeros(FPS, bool)]  # 4 s of speech, 1 s of pause
    speaking = np.tile(phrase, MINUTES * 12)
    face = face_track(speaking, seed=3)
    starts = [first for first, _ in blinks_of(face[:, 0])]
    in_pauses = np.mean([not speaking[start] for start in starts])
    assert in_pauses > 1.5 * (1 - speaking.mean())  # pauses are 20 % of the time and get over 30 % of the blinks
    assert np.array_equal(face[:, 0], face[:, 1]) and np.array_equal(face[:, 0], face[:, 2])
    assert not face[:, BLINK_SHAPES:].any()  # "blink": no expression


def test_labels_and_free_text_give_expressions():
    embedder = StyleTextEmbedder()
    expressions = Expressions(embedder.embed_labels)
    index = {name: k for k, name in enumerate(EXPRESSION_PRESETS)}
    assert np.argmax(expressions.of(StylePrompt("label", "happy"))) == index["happy"]
    assert np.argmax(expressions.of(StylePrompt("label", "angry"))) == index["angry"]
    assert not expressions.of(StylePrompt("label", "neutral")).any()
    assert np.argmax(expressions.of(StylePrompt("text", "cheerful"))) == index["happy"]
    assert np.argmax(expressions.of(StylePrompt("text", "shocked"))) == index["surprised"]
    assert not expressions.of(StylePrompt("text", "a robot")).any()


def test_the_session_eases_into_the_style_expression_and_it_lives_with_the_speech():
    speech = load_audio(PACKAGED_SAMPLE)[: 12 * SAMPLE_RATE]
    session = build_session(Settings(style="happy", face=FACE_FULL), MonotonicClock())
    frames = session.push(AudioChunk(speech, 0, 0.0)) + session.finish()
    happy = np.array([frame.face[BLINK_SHAPES + EXPRESSION_PRESETS.index("happy")] for frame in frames])  # (T,)
    assert happy[0] == 0.0 and happy[FPS:].min() > 0.2  # eased in from neutral, then never gone
    settled = happy[2 * FPS:]
    assert settled.std() > 0.05  # not a preset held still
    assert session.face_names == FACE_NAMES["vrm0"]


def dynamics_track(base: np.ndarray, speaking: np.ndarray, energy: np.ndarray) -> np.ndarray:
    dynamics = ExpressionDynamics()
    return np.stack([dynamics.weights(base, k / FPS, bool(speaking[k]), float(energy[k]))
                     for k in range(len(speaking))])  # (T, 5)


def test_emphasis_raises_the_expression_a_pause_eases_it_and_each_preset_moves_its_own_way():
    index = {name: k for k, name in enumerate(EXPRESSION_PRESETS)}
    base = np.zeros(len(EXPRESSION_PRESETS))
    base[index["happy"]], base[index["angry"]] = 0.5, 0.4
    speaking = np.r_[np.ones(6 * FPS, bool), np.zeros(3 * FPS, bool)]  # a phrase, then a pause
    energy = np.full(len(speaking), -30.0)
    stressed = np.zeros(len(speaking), bool)
    stressed[[2 * FPS + k for k in range(6)] + [4 * FPS + k for k in range(6)]] = True  # two stressed words
    energy[stressed] = -20.0
    track = dynamics_track(base, speaking, energy)
    angry, happy, brows = (track[:, index[name]] for name in ("angry", "happy", "surprised"))
    after = np.flatnonzero(stressed) + 2
    assert angry[after].mean() > 1.2 * angry[FPS: 2 * FPS].mean()  # a frown deepens on a stressed word
    assert brows[after].mean() > brows[FPS: 2 * FPS].mean() + 0.02  # the brows lift on emphasis
    phrase_end = 6 * FPS
    assert happy[phrase_end: phrase_end + FPS // 2].max() > 1.2 * happy[phrase_end - FPS: phrase_end].mean()
    assert happy[-1] < happy[phrase_end - 1]  # the pause eases the smile back down
    assert np.all(np.diff(track[phrase_end + FPS:], axis=0) <= 1e-12)  # ... smoothly, no pop


def test_a_tired_face_blinks_slower_and_longer_than_an_angry_one_stares():
    def blinks(label: str) -> tuple[float, float]:
        animator = FaceAnimator(FACE_BLINK, 0, Expressions())
        animator.set_style(np.zeros(len(EXPRESSION_PRESETS)), 0.0, label)
        lids = animator.frames(np.arange(MINUTES * 60 * FPS) / FPS, [False] * (MINUTES * 60 * FPS))[:, 0]
        found = blinks_of(lids)
        return len(found) / MINUTES, float(np.mean([last - first + 1 for first, last in found]))

    (usual, usual_length), (tired, tired_length), (angry, _) = (blinks(name) for name in ("neutral", "tired", "angry"))
    assert tired < 0.85 * usual and tired_length > 1.4 * usual_length
    assert angry < 0.75 * usual


def test_face_is_the_same_streamed_in_any_chunks_and_off_when_asked():
    speech = load_audio(PACKAGED_SAMPLE)[: 5 * SAMPLE_RATE]
    runs = []
    for block in (SAMPLE_RATE, 333):
        session = build_session(Settings(), MonotonicClock())
        frames = [f for start in range(0, len(speech), block)
                  for f in session.push(AudioChunk(speech[start : start + block], start, start / SAMPLE_RATE))]
        runs.append(np.stack([frame.face for frame in frames + session.finish()]))
    assert np.array_equal(runs[0], runs[1])
    off = build_session(Settings(face="off"), MonotonicClock())
    assert all(frame.face is None for frame in off.push(AudioChunk(speech, 0, 0.0)))
    assert off.face_names == ()
