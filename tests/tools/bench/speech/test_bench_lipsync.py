"""``bench lipsync`` on a tiny espeak-ng set (one voice, one utterance per vowel) and one real clip."""

import shutil

import pytest

from gesturecast.tools.bench.speech.lipsync import CLASSES, benchmark
from gesturecast.tools.bench.speech.lipsync_set import SILENCE, UNLABELLED, vowel_set

pytestmark = pytest.mark.skipif(shutil.which("espeak-ng") is None, reason="espeak-ng is not installed")
CLIP = "show/conan_115563-00_01_35-00_01_45.wav"


def test_labels_mark_vowel_nuclei_and_surrounding_silence(tmp_path):
    items = vowel_set(("es",), 1, tmp_path)
    assert [item.vowel for item in items] == ["a", "i", "u", "e", "o"]
    for index, item in enumerate(items):
        assert (item.labels == index).sum() >= 5  # a sustained vowel has a nucleus of several frames
        assert item.labels[0] == SILENCE and item.labels[-1] == SILENCE
        assert set(item.labels) == {index, SILENCE, UNLABELLED}


def test_benchmark_measures_accuracy_correlation_and_cost(tmp_path, shared_data):
    result = benchmark(("es",), 1, [shared_data / CLIP], repeats=1, set_dir=tmp_path)
    vowels = result["vowels"]
    assert vowels["confusion"]["classes"] == list(CLASSES)
    assert vowels["vowel_accuracy"] > 0.6 and vowels["silence_accuracy"] > 0.9  # chance is 0.2
    assert set(vowels["per_voice"]) == {"es"}
    (speech,) = result["loudness"]
    assert speech["r_speaking"] > 0.5  # the mouth opens with the voice
    assert result["cost"]["session_burst"]["lipsync_ms_per_frame"] > 0.0
