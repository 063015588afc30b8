"""VMC protocol over OSC/UDP (receivers: VSeeFace, Warudo, EVMC4U in Unity, VMC4UE in Unreal).

Per frame, in this order (DESIGN.md "VMC protocol essentials"):

- ``/VMC/Ext/Root/Pos`` (s "root", f px py pz, f qx qy qz qw): the avatar root, Unity space.
  It carries the Hips displacement from its rest position, with identity rotation; the Hips
  rotation carries the facing. So root + Hips rest offset = the frame's Hips position.
- ``/VMC/Ext/Bone/Pos`` (s HumanBodyBones name, f px py pz, f qx qy qz qw) per canonical bone:
  local position = the bone's rest offset, local rotation; both in Unity space.
- ``/VMC/Ext/OK`` (i 1) and ``/VMC/Ext/T`` (f seconds since the stream started).

Messages are grouped into bundles of at most 1500 bytes; only ``s``, ``f`` and ``i`` are sent.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gesturecast.bridges.coords import UNITY
from gesturecast.bridges.osc_wire import MAX_DATAGRAM_SIZE, MessageLayout, encode_float_rows, pack_bundles
from gesturecast.bridges.transport import RateLimiter, UdpSender, UdpTarget
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS, Skeleton
from gesturecast.realtime.timing.frames import PoseFrame

VMC_DEFAULT_PORT = 39539
VMC_ROOT_NAME = "root"
VMC_LOADED = 1
POSITION_AND_QUATERNION = "f" * 7


@dataclass(frozen=True)
class VmcConfig:
    host: str = "127.0.0.1"
    port: int = VMC_DEFAULT_PORT
    send_rate: float = 30.0
    max_bundle_size: int = MAX_DATAGRAM_SIZE


class VmcEncoder:
    """Pure encoder: PoseFrame → OSC bundles (bytes), each at most ``max_bundle_size``."""

    def __init__(self, skeleton: Skeleton = CANONICAL_WITH_HANDS, max_bundle_size: int = MAX_DATAGRAM_SIZE) -> None:
        self.skeleton = skeleton
        self.max_bundle_size = max_bundle_size
        self._root = MessageLayout("/VMC/Ext/Root/Pos", (VMC_ROOT_NAME,), POSITION_AND_QUATERNION)
        self._bones = [MessageLayout("/VMC/Ext/Bone/Pos", (name,), POSITION_AND_QUATERNION) for name in skeleton.names]
        self._ok = MessageLayout("/VMC/Ext/OK", (), "i")
        self._time = MessageLayout("/VMC/Ext/T", (), "f")
        self._rest_unity = UNITY.position(skeleton.offsets)  # (J, 3)
        self._hips_rest = skeleton.offsets[0]  # (3,) internal

    def encode(self, frame: PoseFrame, stream_time: float) -> list[bytes]:
        """Bundles for one frame; ``stream_time`` (s) goes to ``/VMC/Ext/T``."""
        root_unity = UNITY.position(np.asarray(frame.root_position) - self._hips_rest)  # (3,)
        root_row = np.concatenate([root_unity, [0.0, 0.0, 0.0, 1.0]])  # (7,)
        bone_rows = np.concatenate([self._rest_unity, UNITY.rotation(frame.rotations)], axis=1)  # (J, 7)
        messages = [self._root.encode_floats(root_row)]
        messages += encode_float_rows(self._bones, bone_rows)
        messages.append(self._ok.encode(VMC_LOADED))
        messages.append(self._time.encode(float(stream_time)))
        return pack_bundles(messages, self.max_bundle_size)


class VmcBridge:
    """Sends PoseFrames to one VMC receiver at ``send_rate``; a missing receiver never raises."""

    name = "vmc"

    def __init__(self, config: VmcConfig = VmcConfig(), skeleton: Skeleton = CANONICAL_WITH_HANDS) -> None:
        self.config = config
        self.encoder = VmcEncoder(skeleton, config.max_bundle_size)
        self.limiter = RateLimiter(config.send_rate)
        self.sender = UdpSender(UdpTarget(config.host, config.port), "VMC")
        self._start_time: float | None = None

    def send(self, frame: PoseFrame) -> None:
        if not self.limiter.admit(frame.presentation_time):
            return
        if self._start_time is None:
            self._start_time = frame.presentation_time
        self.sender.send_all(self.encoder.encode(frame, frame.presentation_time - self._start_time))

    def close(self) -> None:
        self.sender.close()
