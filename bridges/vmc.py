"""VMC protocol over OSC/UDP (receivers: VSeeFace, Warudo, EVMC4U in Unity, VMC4UE in Unreal).

Per frame, in this order (docs/architecture.md, "VMC protocol essentials"):

- ``/VMC/Ext/Root/Pos`` (s "root", f px py pz, f qx qy qz qw): the avatar root, Unity space.
  It carries the Hips displacement from its rest position, with identity rotation; the Hips
  rotation carries the facing. So root + Hips rest offset = the frame's Hips position.
- ``/VMC/Ext/Bone/Pos`` (s HumanBodyBones name, f px py pz, f qx qy qz qw) per canonical bone:
  local position = the bone's rest offset, local rotation; both in Unity space.
- ``/VMC/Ext/Blend/Val`` (s name, f weight) per viseme and per face blend shape, then one
  ``/VMC/Ext/Blend/Apply`` (no arguments), when the frame carries those weights and names were configured
  (``--lipsync vrm0``: A I U E O; ``vrm1``: aa ih ou ee oh; ``--face``: Blink Blink_L Blink_R Joy Angry Sorrow Fun
  Surprised, or the VRM 1.0 names with ``vrm1``; case-sensitive in receivers).
- ``/VMC/Ext/OK`` (i 1) and ``/VMC/Ext/T`` (f seconds since the stream started).

In the Assistant role (:mod:`gesturecast.bridges.vmc_roles`) the root, OK and T messages are left out and only
the selected bones are sent.

Messages are grouped into bundles that cross a 1500-byte Ethernet MTU unfragmented: at most 1472 bytes of
UDP payload to an IPv4 receiver, 1452 to an IPv6 one (chosen by the resolved address family of the target);
only ``s``, ``f`` and ``i`` are sent.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from gesturecast.bridges.coords import UNITY
from gesturecast.bridges.osc_wire import (
    MAX_DATAGRAM_SIZE,
    MessageLayout,
    encode_float_rows,
    encode_weight_groups,
    pack_bundles,
)
from gesturecast.bridges.transport import RateLimiter, UdpSender, UdpTarget
from gesturecast.bridges.vmc_roles import DEFAULT_PORTS, MARIONETTE
from gesturecast.frames import PoseFrame
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS, Skeleton

VMC_DEFAULT_PORT = DEFAULT_PORTS[MARIONETTE]
VMC_ROOT_NAME = "root"
VMC_LOADED = 1
NO_RECEIVER_HINT = "start VSeeFace, Warudo or EVMC4U there, or send elsewhere with --vmc HOST:PORT"
POSITION_AND_QUATERNION = "f" * 7


@dataclass(frozen=True)
class VmcConfig:
    host: str = "127.0.0.1"
    port: int = VMC_DEFAULT_PORT
    send_rate: float = 30.0
    max_bundle_size: int | None = None  # None: by the target's address family (1472 IPv4, 1452 IPv6)
    viseme_names: tuple[str, ...] = ()  # VISEME_NAMES[mode], or () to send no visemes
    face_names: tuple[str, ...] = ()  # FACE_NAMES[mode], or () to send no blinks and expressions
    bones: tuple[str, ...] | None = None  # bones to send (None: all of the skeleton)
    assistant: bool = False  # Assistant role: no root, OK or T messages


class VmcEncoder:
    """Pure encoder: PoseFrame → OSC bundles (bytes), each at most ``max_bundle_size`` (None: the IPv4 limit,
    1472 bytes; :class:`VmcBridge` sets it from the target's address family)."""

    def __init__(self, skeleton: Skeleton = CANONICAL_WITH_HANDS, config: VmcConfig = VmcConfig()) -> None:
        self.skeleton = skeleton
        self.config = config
        bones = skeleton.names if config.bones is None else config.bones
        self._bone_index = np.array([skeleton.index(name) for name in bones], int)  # (B,)
        self._root = MessageLayout("/VMC/Ext/Root/Pos", (VMC_ROOT_NAME,), POSITION_AND_QUATERNION)
        self._bones = [MessageLayout("/VMC/Ext/Bone/Pos", (name,), POSITION_AND_QUATERNION) for name in bones]
        self._visemes = [MessageLayout("/VMC/Ext/Blend/Val", (name,), "f") for name in config.viseme_names]
        self._face = [MessageLayout("/VMC/Ext/Blend/Val", (name,), "f") for name in config.face_names]
        self._apply = MessageLayout("/VMC/Ext/Blend/Apply")
        self._ok = MessageLayout("/VMC/Ext/OK", (), "i")
        self._time = MessageLayout("/VMC/Ext/T", (), "f")
        self._rest_unity = UNITY.position(skeleton.offsets)[self._bone_index]  # (B, 3)
        self._hips_rest = skeleton.offsets[0]  # (3,) internal
        self.max_bundle_size = config.max_bundle_size or MAX_DATAGRAM_SIZE

    def encode(self, frame: PoseFrame, stream_time: float) -> list[bytes]:
        """Bundles for one frame; ``stream_time`` (s) goes to ``/VMC/Ext/T``."""
        rotations = UNITY.rotation(np.asarray(frame.rotations)[self._bone_index])  # (B, 4)
        messages = [] if self.config.assistant else [self._root_message(frame)]
        messages += encode_float_rows(self._bones, np.concatenate([self._rest_unity, rotations], axis=1))
        messages += self._blend_messages(frame)
        if not self.config.assistant:
            messages += [self._ok.encode(VMC_LOADED), self._time.encode(float(stream_time))]
        return pack_bundles(messages, self.max_bundle_size)

    def _root_message(self, frame: PoseFrame) -> bytes:
        root_unity = UNITY.position(np.asarray(frame.root_position) - self._hips_rest)  # (3,)
        return self._root.encode_floats(np.concatenate([root_unity, [0.0, 0.0, 0.0, 1.0]]))  # (7,)

    def _blend_messages(self, frame: PoseFrame) -> list[bytes]:
        """One Val per viseme and face name with the frame's weight, then one Apply; none without names or
        weights."""
        messages = encode_weight_groups(((self._visemes, frame.visemes), (self._face, frame.face)))
        return [*messages, self._apply.encode()] if messages else []


class VmcBridge:
    """Sends PoseFrames to one VMC receiver at ``send_rate``; a missing receiver never raises."""

    name = "vmc"

    def __init__(self, config: VmcConfig = VmcConfig(), skeleton: Skeleton = CANONICAL_WITH_HANDS) -> None:
        self.config = config
        self.limiter = RateLimiter(config.send_rate)
        self.sender = UdpSender(UdpTarget(config.host, config.port), "VMC", NO_RECEIVER_HINT)
        size = config.max_bundle_size or self.sender.max_datagram_size  # IPv6 headers are 20 bytes longer
        self.encoder = VmcEncoder(skeleton, replace(config, max_bundle_size=size))
        self._start_time: float | None = None

    def send(self, frame: PoseFrame) -> None:
        if not self.limiter.admit(frame.presentation_time):
            return
        if self._start_time is None:
            self._start_time = frame.presentation_time
        self.sender.send_all(self.encoder.encode(frame, frame.presentation_time - self._start_time))

    def counters(self) -> dict[str, int]:
        """Datagrams that did not reach the receiver (nobody listening, or another send error)."""
        return {f"vmc_{name}": n for name, n in self.sender.counters().items()}

    def close(self) -> None:
        self.sender.close()
