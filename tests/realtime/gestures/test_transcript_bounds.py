"""Transcripts are read bounded, from regular files only, and every bad one is a one-line error: huge or
non-finite word times, integers of hundreds or thousands of digits, JSON nested 100k deep, subtitles with too many
words or impossible times, a device or a FIFO named as the transcript (one as a real `generate` process)."""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import soundfile

from gesturecast.controls import MAX_TRANSCRIPT_WORDS
from gesturecast.errors import UserError
from gesturecast.models.audio.files import SAMPLE_RATE
from gesturecast.realtime.gestures.transcripts import read_transcript, words_from_list

FIFO_BOUND_S = 120.0  # generate loads the model, then must refuse the FIFO instead of waiting for a writer


@pytest.mark.parametrize("text, error", [
    ('[{"word": "hi", "start": 1e308}]', r"start must be within \[0, 1e\+06\]"),
    ('[{"word": "hi", "start": 1%s}]' % ("0" * 400), r"start must be a finite number"),
    ('[{"word": "hi", "start": 1%s}]' % ("0" * 5000), "not a JSON word list"),
    ("[" * 100_000 + "]" * 100_000, "not a JSON word list"),
])
def test_bad_json_transcripts_are_one_line(tmp_path, text, error):
    path = tmp_path / "words.json"
    path.write_text(text)
    with pytest.raises(UserError, match=error):
        read_transcript(path)


def test_word_lists_from_python_refuse_huge_times():
    for start in (10**400, 1e308, float("inf")):
        with pytest.raises(UserError, match=r"start must be (within \[0, 1e\+06\]|a finite number)"):
            words_from_list([{"word": "hello", "start": start}], "words")


def test_subtitles_are_capped_and_their_times_checked(tmp_path):
    path = tmp_path / "talk.srt"
    path.write_text("1\n00:00:01,000 --> 00:00:09,000\n" + "word " * (MAX_TRANSCRIPT_WORDS + 1) + "\n")
    with pytest.raises(UserError, match=f"must be a list of 1..{MAX_TRANSCRIPT_WORDS}"):
        read_transcript(path)
    for span, error in [("00:00:05,000 --> 00:00:01,000", r"\[0\].end is before its start"),
                        ("00:61:00,000 --> 00:62:00,000", "minutes or seconds beyond 59")]:
        path.write_text(f"1\n{span}\nhello there\n")
        with pytest.raises(UserError, match=error):
            read_transcript(path)


def test_a_device_is_not_read_as_a_transcript():
    if not os.path.exists("/dev/zero"):
        pytest.skip("no /dev/zero here")
    with pytest.raises(UserError, match="not a regular file"):
        read_transcript(Path("/dev/zero"))


def test_generate_refuses_a_fifo_transcript_instead_of_waiting(tmp_path):
    if not hasattr(os, "mkfifo"):
        pytest.skip("no FIFOs on this platform")
    soundfile.write(tmp_path / "talk.wav", np.zeros(SAMPLE_RATE, np.float32), SAMPLE_RATE)
    os.mkfifo(tmp_path / "words.json")
    result = subprocess.run([sys.executable, "-m", "gesturecast.cli", "generate", "talk.wav", "--transcript",
                             "words.json", "-o", "talk.bvh"], cwd=tmp_path, capture_output=True, text=True,
                            timeout=FIFO_BOUND_S)
    assert result.returncode == 2 and "not a regular file" in result.stderr and "Traceback" not in result.stderr
