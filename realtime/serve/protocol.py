"""Messages of ``gesturecast serve``: one WebSocket per stream, audio in, poses out (docs/serve.md).

Client → server:

- ``{"type": "start", "style"?, "prompt"?, "style2"?, "part_styles"?, "gamma"?, "style_strength"?, "guidance"?,
  "audio_guidance"?, "seed"?, "latency"?, "audio_format"?, "token"?}`` — optional before the first audio (defaults:
  the server's style and latency setting, ``f32le``); ``latency`` is ``low``, ``balanced`` or ``quality``
  (docs/latency.md); carries the token when the server requires one.
- binary messages: raw PCM, 16 kHz mono, ``f32le`` (float32 in [-1, 1]) or ``s16le`` (int16).
- ``{"type": "control", ...}`` and ``{"type": "words", ...}`` — live style / style strength / guidance / audio
  guidance / γ / root changes, gestures and words (:mod:`gesturecast.controls`, checked as every door's are).
- ``{"type": "end"}`` — no more audio: the rest of the poses, then a ``stats`` message, then close.

Server → client: the JSON hello (the viewer's hello plus ``stream``, ``latency_budget_ms``, ``audio``),
``started`` (with the stream's ``latency_budget_ms``), binary pose frames
(:func:`gesturecast.bridges.ws_protocol.binary_frame`), ``ack``,
``error`` (one line; the connection stays open) and ``stats``.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from gesturecast.controls import STYLE_SETTINGS, ControlError, StyleChange, parse_style_change
from gesturecast.models.audio.files import SAMPLE_RATE
from gesturecast.realtime.audio.pcm import PCM16_FULL_SCALE
from gesturecast.settings import LATENCY_SETTINGS

AUDIO_FORMATS = {"f32le": np.dtype("<f4"), "s16le": np.dtype("<i2")}
DEFAULT_AUDIO_FORMAT = "f32le"
MAX_AUDIO_MESSAGE_BYTES = 64 * 1024  # 1 s of float32 audio fits
MAX_SEED = 2**31 - 1
START_FIELDS = frozenset({"type", "token", "seed", "latency", "audio_format", *STYLE_SETTINGS})
STREAM_ID_CHARS = frozenset("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-_.")
MAX_STREAM_ID_CHARS = 64
STREAM_PATH_PREFIX = "/stream/"


@dataclass(frozen=True)
class StreamOptions:
    """What a ``start`` message chose: a style change over the server's defaults, and (None = the server's) the
    seed and latency setting."""

    style: StyleChange = StyleChange()
    seed: int | None = None
    latency: str | None = None  # a LATENCY_SETTINGS name
    audio_format: str = DEFAULT_AUDIO_FORMAT


def start_choice(message: dict, name: str, choices: Iterable[str]) -> str | None:
    """The ``start`` field ``name`` when it is one of ``choices`` (None when absent or null); a one-line
    ControlError for anything else, also for another JSON type (a list or object cannot be looked up by name)."""
    value = message.get(name)
    if value is None:
        return None
    if not isinstance(value, str) or value not in choices:
        shown = repr(value) if isinstance(value, str) else f"a JSON {json_type(value)}"
        raise ControlError(f"{name} must be one of {', '.join(choices)}, got {shown:.60}")
    return value


def json_type(value: object) -> str:
    """The JSON name of a decoded value's type (for messages)."""
    names = {bool: "boolean", int: "number", float: "number", str: "string", list: "array", dict: "object"}
    return names.get(type(value), type(value).__name__)


def parse_start(message: dict) -> StreamOptions:
    unknown = sorted(set(message) - START_FIELDS)
    if unknown:
        raise ControlError(f"unknown start field(s): {', '.join(unknown)}; known: {', '.join(sorted(START_FIELDS))}")
    style = parse_style_change(message)
    audio_format = start_choice(message, "audio_format", AUDIO_FORMATS) or DEFAULT_AUDIO_FORMAT
    seed = message.get("seed")
    if seed is not None and (isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed <= MAX_SEED):
        raise ControlError(f"seed must be an integer in [0, {MAX_SEED}]")
    latency = start_choice(message, "latency", LATENCY_SETTINGS)
    return StreamOptions(style=style, seed=seed, latency=latency, audio_format=audio_format)


def decode_audio(data: bytes, audio_format: str) -> np.ndarray:
    """One binary message → (n,) float32 samples; ControlError for a torn sample or non-finite values."""
    dtype = AUDIO_FORMATS[audio_format]
    if not data or len(data) % dtype.itemsize:
        raise ControlError(f"{audio_format} audio must be a non-empty multiple of {dtype.itemsize} bytes, "
                           f"got {len(data)}")
    samples = np.frombuffer(data, dtype=dtype)  # (n,)
    if dtype.kind == "i":
        return (samples / PCM16_FULL_SCALE).astype(np.float32)
    if not np.isfinite(samples).all():
        raise ControlError("audio contains NaN or infinite samples")
    return samples.astype(np.float32)


def stream_id_from_path(path: str, fallback: str) -> str:
    """``/stream/<id>`` → id; ``/`` or ``/stream`` → ``fallback``; ControlError for any other path."""
    route = path.split("?", 1)[0].rstrip("/")
    if route in ("", STREAM_PATH_PREFIX.rstrip("/")):
        return fallback
    if not route.startswith(STREAM_PATH_PREFIX):
        raise ControlError(f"unknown path {route!r}; connect to {STREAM_PATH_PREFIX}<id>")
    stream_id = route[len(STREAM_PATH_PREFIX):]
    if not stream_id or len(stream_id) > MAX_STREAM_ID_CHARS or not set(stream_id) <= STREAM_ID_CHARS:
        raise ControlError(f"a stream id is 1-{MAX_STREAM_ID_CHARS} characters of A-Z a-z 0-9 - _ .")
    return stream_id


def hello(viewer_hello: str, stream_id: str, latency_budget_ms: float) -> str:
    """The viewer hello (bones, offsets, coordinate frame, control schema, token_required) plus stream fields."""
    message = json.loads(viewer_hello)
    message.update(
        stream=stream_id,
        latency_budget_ms=latency_budget_ms,
        audio={"sample_rate": SAMPLE_RATE, "channels": 1, "formats": list(AUDIO_FORMATS),
               "default_format": DEFAULT_AUDIO_FORMAT, "max_message_bytes": MAX_AUDIO_MESSAGE_BYTES},
    )
    return json.dumps(message)


def started(stream_id: str, style: str, audio_format: str, latency_budget_ms: float) -> str:
    return json.dumps({"type": "started", "stream": stream_id, "style": style, "audio_format": audio_format,
                       "latency_budget_ms": latency_budget_ms})


def stats_message(stats: dict) -> str:
    return json.dumps({"type": "stats", **_finite(stats)})


def _finite(value):
    """NaN/inf → None so the stats are strict JSON."""
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value
