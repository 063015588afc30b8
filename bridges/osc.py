"""Plain OSC for Unreal's OSC plugin, TouchDesigner and similar receivers.

Address scheme (all arguments float32 ``f`` or int32 ``i``), per frame, in this order:

- ``/gesturecast/frame``        i seq, f time (s of capture time since the stream's first frame; float32 keeps
  1 ms steps for the first 2.3 hours, where seconds since boot step 15.6 ms after 2 days of uptime)
- ``/gesturecast/root``         f x y z   Hips position, in the selected coordinate frame
- ``/gesturecast/bone/<Name>``  f qx qy qz qw   local rotation of each canonical bone
  (Unity HumanBodyBones names: Hips, Spine, ..., RightToes), in the selected frame
- ``/gesturecast/viseme/<Name>`` f weight   per viseme (``--lipsync vrm0``: A I U E O; ``vrm1``: aa ih ou ee
  oh), mouth-shape weights in [0, 1] of the frame's audio instant; absent with ``--lipsync off``
- ``/gesturecast/face/<Name>`` f weight   per blink and emotion preset (``--face``: Blink Blink_L Blink_R Joy Angry
  Sorrow Fun Surprised, VRM 1.0 names with ``--lipsync vrm1``), weights in [0, 1]; absent with ``--face off``

and, before the frame's messages when a lexicon gesture starts or ends (``PoseFrame.gesture``):
``/gesturecast/gesture/start`` s name and ``/gesturecast/gesture/end`` s name.

The coordinate frame is ``unity``, ``unreal`` (Z-up, centimetres) or ``internal``
(right-handed Y-up, metres); see :mod:`gesturecast.bridges.coords`. Messages go out grouped in
bundles that cross a 1500-byte Ethernet MTU unfragmented (at most 1472 bytes of UDP payload to an IPv4
receiver, 1452 to an IPv6 one), or one datagram per message with ``bundled=False`` for
receivers that do not unpack bundles.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from gesturecast.bridges.coords import coordinate_frame
from gesturecast.bridges.osc_wire import (
    MAX_DATAGRAM_SIZE,
    MessageLayout,
    encode_float_rows,
    encode_weight_groups,
    pack_bundles,
)
from gesturecast.bridges.transport import RateLimiter, UdpSender, UdpTarget
from gesturecast.frames import PoseFrame, gesture_names
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS, Skeleton

OSC_DEFAULT_PORT = 9000
NO_RECEIVER_HINT = "start the OSC receiver (Unreal, TouchDesigner) there, or send elsewhere with --osc HOST:PORT"
ADDRESS_PREFIX = "/gesturecast"
GESTURE_START = f"{ADDRESS_PREFIX}/gesture/start"
GESTURE_END = f"{ADDRESS_PREFIX}/gesture/end"


@dataclass(frozen=True)
class OscConfig:
    host: str = "127.0.0.1"
    port: int = OSC_DEFAULT_PORT
    send_rate: float = 30.0
    coordinate_frame: str = "unity"
    bundled: bool = True
    max_bundle_size: int | None = None  # None: by the target's address family (1472 IPv4, 1452 IPv6)
    viseme_names: tuple[str, ...] = ()  # VISEME_NAMES[mode], or () to send no visemes
    face_names: tuple[str, ...] = ()  # FACE_NAMES[mode], or () to send no blinks and expressions


def bone_address(name: str) -> str:
    return f"{ADDRESS_PREFIX}/bone/{name}"


class OscEncoder:
    """Pure encoder: PoseFrame → datagrams (bundles, or single messages when not ``bundled``)."""

    def __init__(self, config: OscConfig = OscConfig(), skeleton: Skeleton = CANONICAL_WITH_HANDS) -> None:
        self.frame = coordinate_frame(config.coordinate_frame)
        self.bundled = config.bundled
        self.max_bundle_size = config.max_bundle_size or MAX_DATAGRAM_SIZE  # OscBridge sets it by address family
        self._frame_number = MessageLayout(f"{ADDRESS_PREFIX}/frame", (), "if")
        self._root = MessageLayout(f"{ADDRESS_PREFIX}/root", (), "fff")
        self._bones = [MessageLayout(bone_address(name), (), "ffff") for name in skeleton.names]
        self._visemes = [MessageLayout(f"{ADDRESS_PREFIX}/viseme/{name}", (), "f") for name in config.viseme_names]
        self._face = [MessageLayout(f"{ADDRESS_PREFIX}/face/{name}", (), "f") for name in config.face_names]

    def encode(self, frame: PoseFrame, stream_time: float, previous_gesture: str = "") -> list[bytes]:
        """Datagrams for one frame; ``stream_time`` (s since the first frame) goes to ``/gesturecast/frame``;
        the gestures that start or end against ``previous_gesture`` (the last frame sent) go first."""
        messages = gesture_changes(previous_gesture, frame.gesture) + [
            self._frame_number.encode(int(frame.seq), float(stream_time)),
            self._root.encode_floats(self.frame.position(frame.root_position)),
        ]
        messages += encode_float_rows(self._bones, self.frame.rotation(frame.rotations))
        messages += encode_weight_groups(((self._visemes, frame.visemes), (self._face, frame.face)))
        return pack_bundles(messages, self.max_bundle_size) if self.bundled else messages


def gesture_changes(previous: str, current: str) -> list[bytes]:
    """``/gesturecast/gesture/start`` and ``/gesturecast/gesture/end`` (s name) for each gesture that starts or
    ends between two frames' ``gesture`` fields ("wave" → "wave+bow" starts the bow)."""
    before, now = gesture_names(previous), gesture_names(current)
    return ([MessageLayout(GESTURE_START, (name,)).encode() for name in sorted(now - before)]
            + [MessageLayout(GESTURE_END, (name,)).encode() for name in sorted(before - now)])


class OscBridge:
    """Sends PoseFrames as plain OSC to one receiver; a missing receiver never raises."""

    name = "osc"

    def __init__(self, config: OscConfig = OscConfig(), skeleton: Skeleton = CANONICAL_WITH_HANDS) -> None:
        self.config = config
        self.limiter = RateLimiter(config.send_rate)
        self.sender = UdpSender(UdpTarget(config.host, config.port), "OSC", NO_RECEIVER_HINT)
        size = config.max_bundle_size or self.sender.max_datagram_size  # IPv6 headers are 20 bytes longer
        self.encoder = OscEncoder(replace(config, max_bundle_size=size), skeleton)
        self._start_time: float | None = None  # capture time of the first frame sent
        self._gesture = ""  # the gesture the last frame sent named

    def send(self, frame: PoseFrame) -> None:
        if not self.limiter.admit(frame.presentation_time):
            return
        if self._start_time is None:
            self._start_time = frame.capture_time
        self.sender.send_all(self.encoder.encode(frame, frame.capture_time - self._start_time, self._gesture))
        self._gesture = frame.gesture

    def counters(self) -> dict[str, int]:
        """Datagrams that did not reach the receiver (nobody listening, or another send error)."""
        return {f"osc_{name}": n for name, n in self.sender.counters().items()}

    def close(self) -> None:
        self.sender.close()
