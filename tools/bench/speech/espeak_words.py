"""espeak-ng speech with exact word times, through the library's own word events (``libespeak-ng.so.1``, ctypes).

The command line cannot report when each word starts; the library's synthesis callback can: every
``espeakEVENT_WORD`` carries the word's character position in the text and its start in the audio (ms). The audio
(22,050 Hz int16) is resampled to 16 kHz. Results are cached as ``.wav`` + ``.json`` pairs, keyed by the text.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import hashlib
import json
import wave
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import numpy as np

from gesturecast.errors import UserError
from gesturecast.models.audio.files import load_audio

LIBRARY_SONAME = "libespeak-ng.so.1"
AUDIO_OUTPUT_SYNCHRONOUS = 2
CHARS_UTF8 = 1
EVENT_WORD = 1
EVENT_LIST_TERMINATED = 0
POSITION_CHARACTER = 1
DEFAULT_VOICE = "en"  # what espeak_Initialize selects


class _EventId(ctypes.Union):
    _fields_ = [("number", ctypes.c_int), ("name", ctypes.c_char_p), ("string", ctypes.c_char * 8)]


class _Event(ctypes.Structure):
    """``espeak_EVENT`` of speak_lib.h."""

    _fields_ = [("type", ctypes.c_int), ("unique_identifier", ctypes.c_uint), ("text_position", ctypes.c_int),
                ("length", ctypes.c_int), ("audio_position", ctypes.c_int), ("sample", ctypes.c_int),
                ("user_data", ctypes.c_void_p), ("id", _EventId)]


CALLBACK = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.POINTER(ctypes.c_short), ctypes.c_int, ctypes.POINTER(_Event))


@dataclass(frozen=True)
class TimedWord:
    text: str
    start: float  # seconds from the start of the utterance's audio


def _load_library() -> ctypes.CDLL:
    """libespeak-ng by its soname, else wherever the linker finds it; UserError when neither loads."""
    for name in filter(None, (LIBRARY_SONAME, ctypes.util.find_library("espeak-ng"))):
        try:
            return ctypes.CDLL(name)
        except OSError:
            continue
    raise UserError("libespeak-ng is not installed (apt-get install espeak-ng)")


class _Espeak:
    """The loaded library, initialised once for synchronous synthesis into memory."""

    def __init__(self) -> None:
        self.lib = _load_library()
        self.rate = self.lib.espeak_Initialize(AUDIO_OUTPUT_SYNCHRONOUS, 0, None, 0)
        if self.rate <= 0:
            raise UserError("libespeak-ng failed to initialise (is espeak-ng-data installed?)")
        self.lib.espeak_Synth.argtypes = [ctypes.c_char_p, ctypes.c_size_t, ctypes.c_uint, ctypes.c_int,
                                          ctypes.c_uint, ctypes.c_uint, ctypes.c_void_p, ctypes.c_void_p]

    def speak(self, text: str, voice: str | None = None) -> tuple[np.ndarray, list[tuple[int, int, int]]]:
        """(int16 samples at :attr:`rate`, [(character position from 1, length, start ms)] of the words) in
        ``voice`` (an espeak-ng voice name with an optional ``+variant``, e.g. ``en-us+f3``; None: the default)."""
        if self.lib.espeak_SetVoiceByName((voice or DEFAULT_VOICE).encode()) != 0:
            raise UserError(f"espeak-ng has no voice {voice!r} (espeak-ng --voices=en lists them)")
        chunks: list[np.ndarray] = []
        events: list[tuple[int, int, int]] = []

        def collect(wav, count: int, event_list) -> int:  # the synthesis callback: audio and events so far
            if count > 0:
                chunks.append(np.ctypeslib.as_array(wav, shape=(count,)).copy())
            index = 0
            while event_list[index].type != EVENT_LIST_TERMINATED:
                event = event_list[index]
                if event.type == EVENT_WORD:
                    events.append((event.text_position, event.length, event.audio_position))
                index += 1
            return 0

        callback = CALLBACK(collect)  # kept alive for the call
        self.lib.espeak_SetSynthCallback(callback)
        data = text.encode()
        self.lib.espeak_Synth(data, len(data) + 1, 0, POSITION_CHARACTER, 0, CHARS_UTF8, None, None)
        self.lib.espeak_Synchronize()
        return (np.concatenate(chunks) if chunks else np.zeros(0, np.int16)), events


@cache
def _engine() -> _Espeak:
    """The library, initialised once per process (espeak-ng keeps its state globally)."""
    return _Espeak()


def words_at(text: str, events: list[tuple[int, int, int]], duration: float) -> list[TimedWord]:
    """The whitespace-separated tokens of ``text``, each with its start: the word event whose character position
    falls inside the token (a position that drifted, as after "so" in "thanks so much", goes to the next token
    without one), in order; events of length 0 (punctuation pauses) are skipped. A token without an event (espeak-ng
    speaks "for the" as one word) is placed by its characters between its neighbours' starts."""
    offsets, spans = 0, []
    for token in text.split():
        first = text.index(token, offsets)
        spans.append((first, first + len(token)))
        offsets = first + len(token)
    starts: list[float | None] = [None] * len(spans)
    last = -1
    for position, length, ms in events:
        if length <= 0:
            continue
        index = next((k for k, (a, b) in enumerate(spans) if a <= position - 1 < b), None)
        index = last + 1 if index is None or index <= last else index
        if index >= len(spans):
            break
        starts[index], last = ms / 1000, index
    known = [(spans[k][0], t) for k, t in enumerate(starts) if t is not None] + [(len(text), duration)]
    if len(known) == 1:
        raise UserError(f"espeak-ng reported no word times for {text!r}")
    x, y = zip(*known, strict=True)
    return [TimedWord(token, float(t) if t is not None else float(np.interp(span[0], x, y)))
            for token, t, span in zip(text.split(), starts, spans, strict=True)]


def spoken(text: str, cache: Path, voice: str | None = None) -> tuple[np.ndarray, list[TimedWord]]:
    """(16 kHz audio (n,), each token's start) of ``text`` spoken by espeak-ng in ``voice`` (None: its default;
    cached)."""
    key = hashlib.sha1(text.encode() if voice is None else f"{voice}\n{text}".encode()).hexdigest()[:16]
    wav_path, words_path = cache / f"{key}.words.wav", cache / f"{key}.words.json"
    if not (wav_path.is_file() and words_path.is_file()):
        engine = _engine()
        samples, events = engine.speak(text, voice)
        timed = words_at(text, events, len(samples) / engine.rate)
        cache.mkdir(parents=True, exist_ok=True)
        with wave.open(str(wav_path), "wb") as out:
            out.setnchannels(1)
            out.setsampwidth(2)
            out.setframerate(engine.rate)
            out.writeframes(samples.astype("<i2").tobytes())
        words_path.write_text(json.dumps([[w.text, w.start] for w in timed]))
    return load_audio(wav_path), [TimedWord(text_, start) for text_, start in json.loads(words_path.read_text())]
