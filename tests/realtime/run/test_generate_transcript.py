"""``generate --transcript``: trigger words cue the bundled lexicon's gestures, named in the pose JSON; the same
bits as the library call; bad transcripts are one line."""

import json

import numpy as np
import pytest
import soundfile

import gesturecast
from gesturecast.models.audio.files import PACKAGED_SAMPLE, SAMPLE_RATE, load_audio

WORDS = [{"word": "Hello", "start": 1.5, "end": 1.9}, {"word": "everyone", "start": 1.9, "end": 2.4},
         {"word": "thank", "start": 8.0, "end": 8.2}, {"word": "you", "start": 8.2, "end": 8.4}]


@pytest.fixture(scope="module")
def talk(tmp_path_factory):
    folder = tmp_path_factory.mktemp("transcript")
    soundfile.write(folder / "talk.wav", load_audio(PACKAGED_SAMPLE)[: 12 * SAMPLE_RATE], SAMPLE_RATE)
    (folder / "words.json").write_text(json.dumps(WORDS))
    return folder


def test_generate_with_a_transcript_waves_at_hello_and_bows_at_thank_you(talk, cli_here):
    result = cli_here("generate", "talk.wav", "--transcript", "words.json", "-o", "talk.bvh",
                      "--json", "talk.json", cwd=talk)
    assert result.returncode == 0, result.stderr
    frames = json.loads((talk / "talk.json").read_text())["frames"]
    named = {frame.get("gesture") for frame in frames} - {None}
    assert named == {"wave", "bow"}
    first = {name: min(f["seq"] for f in frames if f.get("gesture") == name) / 30 for name in named}
    assert first["wave"] < 1.5 < first["wave"] + 4 and first["bow"] < 8.0 < first["bow"] + 5
    motion = gesturecast.generate(talk / "talk.wav", transcript=WORDS)
    assert np.allclose(motion.rotations, np.array([f["rotations"] for f in frames]), atol=1e-7)  # JSON: 7 decimals


@pytest.mark.parametrize("transcript, words", [
    ('[{"word": "hi", "start": -1}]', "bad.json[0].start must be within [0, 1e+06], got -1"),
    ("not json", "not a JSON word list"),
])
def test_a_bad_transcript_is_one_line(talk, transcript, words, cli_here):
    (talk / "bad.json").write_text(transcript)
    result = cli_here("generate", "talk.wav", "--transcript", "bad.json", "-o", "bad.bvh", cwd=talk)
    assert result.returncode == 2 and words in result.stderr and "Traceback" not in result.stderr
    assert not (talk / "bad.bvh").exists()


def test_a_transcript_with_gestures_off_is_refused(talk, cli_here):
    result = cli_here("generate", "talk.wav", "--transcript", "words.json", "--gestures", "off",
                      "-o", "x.bvh", cwd=talk)
    assert result.returncode == 2 and "--gestures is off" in result.stderr
