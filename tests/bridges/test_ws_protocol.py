"""The WebSocket frame encoders: visemes appended after the rotations, nothing appended without lip sync."""

from __future__ import annotations

import dataclasses
import json
import struct

import numpy as np
from bridge_test_frames import moving_frame

from gesturecast.bridges.coords import INTERNAL, UNITY
from gesturecast.bridges.ws_protocol import BINARY_HEADER, FRAME_MAGIC, binary_frame, gesture_message, json_frame
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS

J = CANONICAL_WITH_HANDS.num_joints
WEIGHTS = np.array([0.8, 0.0, 0.25, 0.5, 1.0])  # a i u e o
CAPTURE_UNIX, SEND_UNIX = 1_700_000_000.25, 1_700_000_000.5


def parse_binary(payload: bytes, viseme_count: int) -> dict:
    """Decode a binary frame the way a client does (docs/bridges.md), independently of the encoder."""
    magic, seq, capture, send, x, y, z, joints, flags = struct.unpack_from("<4sIddfffHH", payload)
    rotations = np.frombuffer(payload, dtype="<f4", count=4 * joints, offset=40).reshape(joints, 4)
    visemes = np.frombuffer(payload, dtype="<f4", count=viseme_count, offset=40 + 16 * joints)
    assert len(payload) == 40 + 16 * joints + 4 * viseme_count
    return {"magic": magic, "seq": seq, "root": (x, y, z), "rotations": rotations, "visemes": visemes}


def test_binary_frame_round_trip_with_visemes():
    frame = dataclasses.replace(moving_frame(7), visemes=WEIGHTS)
    decoded = parse_binary(binary_frame(frame, UNITY, CAPTURE_UNIX, SEND_UNIX, viseme_count=5), viseme_count=5)
    assert decoded["magic"] == FRAME_MAGIC and decoded["seq"] == 7
    np.testing.assert_allclose(decoded["rotations"], UNITY.rotation(frame.rotations), atol=1e-6)
    np.testing.assert_allclose(decoded["visemes"], WEIGHTS, atol=1e-7)


def test_a_frame_without_lip_sync_is_header_and_rotations_only():
    frame = dataclasses.replace(moving_frame(3), visemes=WEIGHTS)  # weights present, but the hello names none
    header = BINARY_HEADER.pack(FRAME_MAGIC, 3, CAPTURE_UNIX, SEND_UNIX, *frame.root_position.tolist(), J, 0)
    before_visemes = header + frame.rotations.astype("<f4").tobytes()  # the format as it was before visemes
    assert binary_frame(frame, INTERNAL, CAPTURE_UNIX, SEND_UNIX) == before_visemes
    assert binary_frame(moving_frame(3), INTERNAL, CAPTURE_UNIX, SEND_UNIX) == before_visemes


def test_lip_sync_frames_keep_their_size_when_a_frame_carries_no_weights():
    decoded = parse_binary(binary_frame(moving_frame(2), INTERNAL, CAPTURE_UNIX, SEND_UNIX, viseme_count=5), 5)
    np.testing.assert_array_equal(decoded["visemes"], np.zeros(5))


def test_json_frame_lists_the_weights():
    frame = dataclasses.replace(moving_frame(4), visemes=WEIGHTS)
    assert json.loads(json_frame(frame, INTERNAL, CAPTURE_UNIX, SEND_UNIX, viseme_count=5))["visemes"] == list(WEIGHTS)
    assert json.loads(json_frame(frame, INTERNAL, CAPTURE_UNIX, SEND_UNIX))["visemes"] == []


def test_the_gesture_message_names_what_starts_and_ends():
    message = json.loads(gesture_message("wave", "wave+bow", 7, 12.5))
    assert message == {"type": "gesture", "playing": "wave+bow", "started": ["bow"], "ended": [], "seq": 7,
                       "capture_time": 12.5}
