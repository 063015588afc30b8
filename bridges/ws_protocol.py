"""WebSocket stream messages: the JSON hello, binary frames and JSON frames.

Binary frame (little-endian, ``BINARY_HEADER`` then quaternions; docs/bridges.md):

======  ====  ===========  =====================================================
offset  size  type         field
======  ====  ===========  =====================================================
0       4     char[4]      magic ``b"GCPF"``
4       4     uint32       seq
8       8     float64      capture time, Unix epoch seconds
16      8     float64      send time, Unix epoch seconds
24      12    float32 × 3  root (Hips) position, selected coordinate frame
36      2     uint16       joint count J (same order as the hello's ``bones``)
38      2     uint16       flags: bit 0 = speaking
40      16·J  float32 × 4  local rotation per joint, XYZW, selected coordinate frame
40+16J  4·V   float32      viseme weights in [0, 1], V = len(hello ``visemes``) (0 without lip sync)
+4V     4·E   float32      face weights in [0, 1], E = len(hello ``face``) (0 with the face off)
======  ====  ===========  =====================================================

The viseme weights are those of ``PoseFrame.visemes`` (vowels a, i, u, e, o), named in the hello by
``visemes`` (VRM 0.x ``A I U E O`` or VRM 1.0 ``aa ih ou ee oh``). Without lip sync the hello's
``visemes`` is empty and frames end after the rotations: byte-identical to format version 1 before
visemes, and a client reading J rotations after the header is unaffected either way. The face weights (blinks and
emotion presets, ``PoseFrame.face``) follow in the same way, named by the hello's ``face``.

The gesture playing (``PoseFrame.gesture``) is the JSON frame's ``gesture`` field ("" when none), and every client,
binary or JSON, gets a ``{"type": "gesture", "playing", "started", "ended", "seq", "capture_time"}`` message before
the first frame of a change (:func:`gesture_message`).
"""

from __future__ import annotations

import json
import struct
from collections.abc import Sequence

import numpy as np

from gesturecast.bridges.coords import CoordinateFrame
from gesturecast.frames import PoseFrame, gesture_names
from gesturecast.models.motion.skeleton import Skeleton

FORMAT_VERSION = 1
FRAME_MAGIC = b"GCPF"
BINARY_HEADER = struct.Struct("<4sIddfffHH")  # 40 bytes
FLAG_SPEAKING = 1
JSON_DECIMALS = 6
UINT32_MODULUS = 2**32


def hello_message(
    skeleton: Skeleton,
    frame: CoordinateFrame,
    fps: float,
    style: str,
    style_choices: Sequence[str],
    control_schema: dict,
    token_required: bool,
    visemes: Sequence[str] = (),
    body_parts: Sequence[str] = (),
    gestures: Sequence[str] = (),
    face: Sequence[str] = (),
) -> str:
    """The first message on every connection: everything a client needs to interpret frames."""
    return json.dumps(
        {
            "type": "hello",
            "format_version": FORMAT_VERSION,
            "bones": list(skeleton.names),
            "parents": list(skeleton.parents),
            "offsets": np.round(frame.position(skeleton.offsets), JSON_DECIMALS).tolist(),
            "fps": fps,
            "coordinate_frame": frame.name,
            "coordinate_description": frame.description,
            "to_internal": frame.to_internal_matrix().tolist(),
            "binary_header": {"magic": FRAME_MAGIC.decode(), "size": BINARY_HEADER.size, "byte_order": "little"},
            "style": style,
            "style_choices": list(style_choices),
            "control_schema": control_schema,
            "token_required": token_required,
            "visemes": list(visemes),
            "face": list(face),  # blink and emotion-preset names of the face weights after the visemes
            "body_parts": list(body_parts),  # what a part_styles control may name
            "gestures": list(gestures),  # what a gesture control may name (the session's lexicon)
        }
    )


def blend_weights(weights: np.ndarray | None, count: int) -> np.ndarray:
    """(count,) the weights a frame sends when the hello names ``count`` of them (0: none; zeros when the frame
    carries none, so every frame of a stream has the same size)."""
    if count == 0 or weights is None:
        return np.zeros(count)
    return np.asarray(weights, dtype=np.float64)


def binary_frame(frame: PoseFrame, coords: CoordinateFrame, capture_unix: float, send_unix: float,
                 viseme_count: int = 0, face_count: int = 0) -> bytes:
    """One binary frame (layout in the module docstring); ``viseme_count`` = len(hello ``visemes``), ``face_count``
    = len(hello ``face``)."""
    rotations = coords.rotation(frame.rotations)  # (J, 4)
    root = coords.position(frame.root_position)  # (3,)
    flags = FLAG_SPEAKING if frame.speaking else 0
    header = BINARY_HEADER.pack(
        FRAME_MAGIC, frame.seq % UINT32_MODULUS, capture_unix, send_unix, *root.tolist(), len(rotations), flags
    )
    weights = np.concatenate([blend_weights(frame.visemes, viseme_count), blend_weights(frame.face, face_count)])
    return header + np.ascontiguousarray(rotations, dtype="<f4").tobytes() + weights.astype("<f4").tobytes()


def json_frame(frame: PoseFrame, coords: CoordinateFrame, capture_unix: float, send_unix: float,
               viseme_count: int = 0, face_count: int = 0) -> str:
    """The same content as :func:`binary_frame`, as JSON (for clients that subscribe to it)."""
    return json.dumps(
        {
            "type": "frame",
            "seq": int(frame.seq),
            "capture_time": capture_unix,
            "send_time": send_unix,
            "root": np.round(coords.position(frame.root_position), JSON_DECIMALS).tolist(),
            "rotations": np.round(coords.rotation(frame.rotations), JSON_DECIMALS).tolist(),
            "speaking": bool(frame.speaking),
            "visemes": np.round(blend_weights(frame.visemes, viseme_count), JSON_DECIMALS).tolist(),
            "face": np.round(blend_weights(frame.face, face_count), JSON_DECIMALS).tolist(),
            "gesture": frame.gesture,  # the lexicon gesture(s) playing ("wave", "wave+bow" while they cross-fade)
        }
    )


def gesture_message(previous: str, current: str, seq: int, capture_unix: float) -> str:
    """The side message sent when the gesture playing changes: what started, what ended, what plays now (also for
    binary subscribers, whose frames have no room for a name)."""
    before, now = gesture_names(previous), gesture_names(current)
    return json.dumps({"type": "gesture", "playing": current, "started": sorted(now - before),
                       "ended": sorted(before - now), "seq": int(seq), "capture_time": capture_unix})


def style_message(style: str) -> str:
    return json.dumps({"type": "style", "style": style})


def error_message(reason: str) -> str:
    return json.dumps({"type": "error", "message": reason})
