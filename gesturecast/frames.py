"""What flows from the generator to the bridges: one pose per motion frame, with timestamps."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

VISEME_VOWELS = ("a", "i", "u", "e", "o")
VISEME_NAMES = {
    "vrm0": ("A", "I", "U", "E", "O"),  # VRM 0.x blend shape presets (case-sensitive in VMC)
    "vrm1": ("aa", "ih", "ou", "ee", "oh"),  # VRM 1.0 expression presets
}
EXPRESSION_PRESETS = ("happy", "angry", "sad", "relaxed", "surprised")  # the emotion presets, VRM 1.0 names
FACE_NAMES = {  # blinks, then the emotion presets (the order of PoseFrame.face)
    "vrm0": ("Blink", "Blink_L", "Blink_R", "Joy", "Angry", "Sorrow", "Fun", "Surprised"),
    "vrm1": ("blink", "blinkLeft", "blinkRight", *EXPRESSION_PRESETS),
}


@dataclass(frozen=True)
class PoseFrame:
    """One canonical pose.

    seq: frame number in the stream (0, 1, 2, ...).
    capture_time: when the audio this frame answers was heard, seconds on the stream's clock (``time.monotonic``
        by default; stream seconds when unpaced, as in ``generate``).
    presentation_time: capture_time + the fixed latency L, on the same clock: the outputs (and ``Stream.frames()``)
        get the frame at this time.
    root_position: (3,) Hips position, metres, internal frame (right-handed, Y-up, faces +Z).
    rotations: (J, 4) local XYZW rotations; the session sends J = 52 on ``CANONICAL_WITH_HANDS`` (22 body
        joints, then 15 finger joints per hand), the bridges' default skeleton.
    style: the style prompt in effect (for display).
    speaking: the voice-activity decision of this frame's own audio instant (on with the voice, off 267 ms after
        it); not the idle cross-fade's decision, which looks ahead and holds for 1 s.
    visemes: (5,) mouth-shape weights in [0, 1] of the vowels ``VISEME_VOWELS`` at this frame's audio
        instant, or None when lip sync is off. Bridges name them per ``VISEME_NAMES`` (VRM 0.x or 1.0).
    gesture: the lexicon gesture(s) being carried out at this frame ("wave", "bow+guide"), "" when none.
    face: (8,) weights in [0, 1] of both eyes' blink, each eye's blink and the emotion presets, in the order of
        ``FACE_NAMES`` (VRM 0.x or 1.0 names), or None when the face is off (realtime/pose/face.py).
    """

    seq: int
    capture_time: float
    presentation_time: float
    root_position: np.ndarray
    rotations: np.ndarray
    style: str = ""
    speaking: bool = False
    visemes: np.ndarray | None = None
    gesture: str = ""
    face: np.ndarray | None = None


def gesture_names(gesture: str) -> set[str]:
    """The lexicon gestures a frame's ``gesture`` names ("wave+bow" while they cross-fade → {"wave", "bow"})."""
    return set(gesture.split("+")) - {""}
