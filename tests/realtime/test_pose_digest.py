"""The poses of the bundled model, bit for bit: a held-out gesture story's words over a few seconds of the sample
speech, and the style grid (each judged style, a γ mix and part styles, without the lexicon) over a shorter cut
of it.

The digests were recorded from the code before a refactoring; a change that means to move a pose must record
them again (and say why in its commit). With the generator hearing ``neutral`` (``generator_style``), the poses are
those it gave when that was the default but for the idle motion's amplitudes (recorded again when the idle was sized
to the actress's settled pauses)."""

import hashlib
from pathlib import Path

import numpy as np
import pytest

import gesturecast
from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.models.style.judge import JUDGED_STYLES
from gesturecast.tools.bench.gesture_set.texts import CUED_STORIES
from gesturecast.tools.gestures.speech_act_training import parse_marked

SAMPLE = Path(gesturecast.__file__).parent / "samples" / "sample_speech.wav"
STORY_SECONDS = 5.0
GRID_SECONDS = 1.5
WORD_S = 0.3  # each word of the story, back to back from FIRST_WORD_S
FIRST_WORD_S = 1.0
STORY = "call-centre"
STORY_DIGEST = "e32c312e1381570d"
GRID_DIGESTS = {"angry": "67444340bd9a17f8", "happy": "b9b2250cd06e5360", "happy-sad-mix": "c7c5eee522a0ae82",
                "neutral": "ab6dd3c251772fa4", "old": "ee97e8f932918122", "part-styles": "2df70002db53bf73",
                "proud": "61ac227851be3564", "sad": "b3b8cb4218a90a9e", "tired": "194d054f93600aed"}
NEUTRAL_HEARD_DIGESTS = {"story": "621f93d4a04f3161", "neutral": "2cbaa287c8788011", "angry": "a352e58f35de2c68"}


@pytest.fixture(scope="module")
def speech() -> np.ndarray:
    return load_audio(SAMPLE)


def story_words(seconds: float) -> list[dict]:
    """The first held-out cued story, a word every WORD_S seconds, the words that fit in ``seconds``."""
    tokens = [token for sentence in CUED_STORIES[STORY] for token in parse_marked(sentence)[0]]
    starts = FIRST_WORD_S + WORD_S * np.arange(len(tokens))
    return [{"word": token, "start": float(start), "end": float(start + WORD_S)}
            for token, start in zip(tokens, starts, strict=True) if start + WORD_S <= seconds]


def digest(motion: gesturecast.Motion) -> str:
    """The first 16 hex digits of the SHA-256 of the poses, the face and mouth weights and the gestures named."""
    hashed = hashlib.sha256()
    for array in (motion.rotations, motion.root_positions, motion.visemes, motion.face):
        hashed.update(np.ascontiguousarray(array, np.float64).tobytes())
    hashed.update("|".join(frame.gesture for frame in motion.frames).encode())
    return hashed.hexdigest()[:16]


@pytest.mark.parametrize(("generator_style", "expected"), [("speech", STORY_DIGEST),
                                                           ("neutral", NEUTRAL_HEARD_DIGESTS["story"])])
def test_story_poses_are_those_recorded(speech, generator_style, expected):
    words = story_words(STORY_SECONDS)
    motion = gesturecast.generate(speech[: int(STORY_SECONDS * SAMPLE_RATE)], SAMPLE_RATE, transcript=words,
                                  generator_style=generator_style)
    assert any(frame.gesture for frame in motion.frames)  # the story's speech acts cue the lexicon's gestures
    assert digest(motion) == expected


GRID = {**{style: {"style": style} for style in JUDGED_STYLES},
        "happy-sad-mix": {"style": "happy", "style2": "sad", "gamma": 0.3},
        "part-styles": {"style": "old", "part_styles": {"arms": "happy"}}}


@pytest.mark.parametrize("name", sorted(GRID))
def test_style_grid_poses_are_those_recorded(speech, name):
    motion = gesturecast.generate(speech[: int(GRID_SECONDS * SAMPLE_RATE)], SAMPLE_RATE, gestures=None, **GRID[name])
    assert digest(motion) == GRID_DIGESTS[name]


@pytest.mark.parametrize("name", ["neutral", "angry"])
def test_the_generators_own_neutral_gives_the_poses_it_gave_as_the_default(speech, name):
    motion = gesturecast.generate(speech[: int(GRID_SECONDS * SAMPLE_RATE)], SAMPLE_RATE, gestures=None,
                                  generator_style="neutral", **GRID[name])
    assert digest(motion) == NEUTRAL_HEARD_DIGESTS[name]
