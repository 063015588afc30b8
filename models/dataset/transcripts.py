"""Word-timed transcripts of the paired takes, for re-speaking them in other voices (models/dataset/respeak.py).

The ZeroEGGS and BEAT2 takes ship without transcripts. PocketSphinx (CMU; its en-us acoustic model, language
model and dictionary ship inside the ``pocketsphinx`` wheel, so nothing is downloaded) decodes each take once and
its word segmentation (start and end of every word, 10 ms frames) is cached beside the take in the dataset cache
as ``NAME.words.json``. The words need not be right: a re-spoken copy only has to put speech where the take has
speech, word by word, so that the motion it is paired with stays in time.
"""

from __future__ import annotations

import json
import re
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from gesturecast.errors import UserError
from gesturecast.models.audio.files import SAMPLE_RATE

SPHINX_FRAMES_PER_S = 100  # PocketSphinx's frame rate (10 ms frames)
ALTERNATE_PRONUNCIATION = re.compile(r"\(\d+\)$")  # "nice(2)": the dictionary's second pronunciation


@dataclass(frozen=True)
class RecognisedWord:
    text: str
    start_s: float
    end_s: float


def _decoder():
    try:
        from pocketsphinx import Decoder
    except ImportError as error:  # a train extra: the runtime never transcribes
        raise UserError("re-spoken voice copies need pocketsphinx (pip install 'gesturecast[train]')") from error
    return Decoder(samprate=SAMPLE_RATE, loglevel="FATAL")  # the project's audio rate


def transcribe(audio: np.ndarray) -> list[RecognisedWord]:
    """(N,) 16 kHz mono float audio → its words in time order (fillers, silences and noises left out)."""
    decoder = _decoder()
    pcm = (np.clip(audio, -1.0, 1.0) * 32767.0).astype(np.int16).tobytes()
    decoder.start_utt()
    decoder.process_raw(pcm, full_utt=True)
    decoder.end_utt()
    words = []
    for segment in decoder.seg():
        text = ALTERNATE_PRONUNCIATION.sub("", segment.word)
        if text.isalpha() or "'" in text:  # not <s>, </s>, <sil>, [NOISE], ...
            words.append(RecognisedWord(text, segment.start_frame / SPHINX_FRAMES_PER_S,
                              (segment.end_frame + 1) / SPHINX_FRAMES_PER_S))
    return words


def words_path(cache_dir: Path, record: dict) -> Path:
    return (cache_dir / record["file"]).with_suffix(".words.json")


def cached_words(cache_dir: Path, record: dict, audio: np.ndarray) -> list[RecognisedWord]:
    """The take's words: read from the cache, or transcribed once and written there."""
    path = words_path(cache_dir, record)
    if path.is_file():
        return [RecognisedWord(**word) for word in json.loads(path.read_text())]
    words = transcribe(audio)
    path.write_text(json.dumps([asdict(word) for word in words]))
    return words
