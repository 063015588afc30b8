import logging
import socket
import struct
import threading
from dataclasses import replace

import numpy as np
import pytest
from bridge_test_frames import moving_frame
from pythonosc.dispatcher import Dispatcher
from pythonosc.osc_packet import OscPacket
from pythonosc.osc_server import BlockingOSCUDPServer

from gesturecast.bridges.coords import UNITY
from gesturecast.bridges.osc_wire import MAX_DATAGRAM_SIZE
from gesturecast.bridges.output_settings import Outputs, parse_host_port
from gesturecast.bridges.transport import LOG_EVERY_N_ERRORS
from gesturecast.bridges.vmc import VmcBridge, VmcConfig, VmcEncoder
from gesturecast.frames import VISEME_NAMES, PoseFrame
from gesturecast.models.motion.rotations import quat_from_axis_angle
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS, Skeleton

RECEIVE_TIMEOUT_S = 5.0
FLOAT32_TOLERANCE = 1e-6
ETHERNET_MTU = 1500
IPV4_PAYLOAD_LIMIT = ETHERNET_MTU - 20 - 8  # 1472: IPv4 and UDP headers; more is fragmented on a LAN
IPV6_PAYLOAD_LIMIT = ETHERNET_MTU - 40 - 8  # 1452


def rest_frame(rotations=None, root=None) -> PoseFrame:
    q = np.tile([0.0, 0.0, 0.0, 1.0], (CANONICAL_WITH_HANDS.num_joints, 1)) if rotations is None else rotations
    return PoseFrame(0, 0.0, 0.0, CANONICAL_WITH_HANDS.offsets[0].copy() if root is None else root, q)


def parse(bundles: list[bytes]) -> list[tuple[str, list]]:
    return [(m.message.address, m.message.params) for b in bundles for m in OscPacket(b).messages]


def type_tags(bundle: bytes) -> list[str]:
    """The type-tag string of every element of a bundle, read from the raw bytes."""
    tags, position = [], 16
    while position < len(bundle):
        (size,) = struct.unpack(">i", bundle[position : position + 4])
        element = bundle[position + 4 : position + 4 + size]
        tag_start = element.index(b",")
        tags.append(element[tag_start : element.index(b"\0", tag_start)].decode())
        position += 4 + size
    return tags


def test_root_message_bytes_at_rest():
    bundles = VmcEncoder().encode(rest_frame(), stream_time=0.0)
    expected_root = b"/VMC/Ext/Root/Pos\0\0\0,sfffffff\0\0\0root\0\0\0\0" + struct.pack(">7f", 0, 0, 0, 0, 0, 0, 1)
    assert bundles[0][:16] == b"#bundle\0" + struct.pack(">Q", 1)
    assert bundles[0][16:20] == struct.pack(">i", len(expected_root))
    assert bundles[0][20 : 20 + len(expected_root)] == expected_root


# bone, internal local rotation (axis-angle), expected Unity XYZW
BONE_CASES = [
    ("LeftUpperArm", [0.0, 0.0, -0.5], UNITY.rotation(quat_from_axis_angle(np.array([0.0, 0.0, -0.5])))),
    ("Head", [0.3, 0.0, 0.0], [np.sin(0.15), 0.0, 0.0, np.cos(0.15)]),  # nod: x kept
    ("Hips", [0.0, 0.4, 0.0], [0.0, -np.sin(0.2), 0.0, np.cos(0.2)]),  # yaw: y flips
]


@pytest.mark.parametrize(("bone", "axis_angle", "unity_q"), BONE_CASES)
def test_bone_message_bytes(bone, axis_angle, unity_q):
    rotations = np.tile([0.0, 0.0, 0.0, 1.0], (CANONICAL_WITH_HANDS.num_joints, 1))
    rotations[CANONICAL_WITH_HANDS.index(bone)] = quat_from_axis_angle(np.array(axis_angle))
    bundles = VmcEncoder().encode(rest_frame(rotations), stream_time=0.0)
    offset = UNITY.position(CANONICAL_WITH_HANDS.offsets[CANONICAL_WITH_HANDS.index(bone)])
    name = bone.encode() + b"\0" * (4 - len(bone) % 4)
    expected = (
        b"/VMC/Ext/Bone/Pos\0\0\0,sfffffff\0\0\0" + name + struct.pack(">7f", *offset, *unity_q)
    )
    assert any(expected in b for b in bundles)


def test_frame_layout_order_types_and_sizes():
    bundles = VmcEncoder().encode(moving_frame(5), stream_time=2.5)
    assert all(len(b) <= IPV4_PAYLOAD_LIMIT for b in bundles)
    messages = parse(bundles)
    addresses = [a for a, _ in messages]
    bones = ["/VMC/Ext/Bone/Pos"] * CANONICAL_WITH_HANDS.num_joints
    assert addresses == ["/VMC/Ext/Root/Pos", *bones, "/VMC/Ext/OK", "/VMC/Ext/T"]
    assert [p[0] for a, p in messages if a == "/VMC/Ext/Bone/Pos"] == list(CANONICAL_WITH_HANDS.names)
    assert messages[-2][1] == [1] and messages[-1][1] == [2.5]
    assert {tag for b in bundles for tag in type_tags(b)} == {",sfffffff", ",i", ",f"}


def test_root_carries_hips_displacement():
    root = CANONICAL_WITH_HANDS.offsets[0] + np.array([0.1, 0.02, -0.3])
    (address, params), *_ = parse(VmcEncoder().encode(rest_frame(root=root), stream_time=0.0))
    np.testing.assert_allclose(params[1:4], [-0.1, 0.02, -0.3], atol=FLOAT32_TOLERANCE)  # Unity: x flips


class Collector:
    """python-osc's own UDP server + dispatcher on one thread, collecting datagrams in arrival order."""

    def __init__(self) -> None:
        self.messages: list[tuple[str, tuple]] = []
        self.done = threading.Event()
        dispatcher = Dispatcher()
        dispatcher.set_default_handler(self.handle)
        self.server = BlockingOSCUDPServer(("127.0.0.1", 0), dispatcher)
        self.port = self.server.server_address[1]
        self.thread = threading.Thread(target=self.server.serve_forever, daemon=True)

    def handle(self, address: str, *args) -> None:
        self.messages.append((address, args))
        if address == "/VMC/Ext/T":
            self.done.set()

    def __enter__(self):
        self.thread.start()
        return self

    def __exit__(self, *exc) -> None:
        self.server.shutdown()
        self.server.server_close()


def test_loopback_python_osc_server_parses_our_bundles():
    frame = moving_frame(7)
    with Collector() as collector:
        bridge = VmcBridge(VmcConfig(port=collector.port))
        bridge.send(frame)
        assert collector.done.wait(RECEIVE_TIMEOUT_S)
        bridge.close()
    bones = {args[0]: np.array(args[1:]) for address, args in collector.messages if address == "/VMC/Ext/Bone/Pos"}
    assert list(bones) == list(CANONICAL_WITH_HANDS.names)
    expected_q = UNITY.rotation(frame.rotations)  # (J, 4)
    expected_p = UNITY.position(CANONICAL_WITH_HANDS.offsets)  # (J, 3)
    for j, name in enumerate(CANONICAL_WITH_HANDS.names):
        np.testing.assert_allclose(bones[name][:3], expected_p[j], atol=FLOAT32_TOLERANCE)
        np.testing.assert_allclose(bones[name][3:], expected_q[j], atol=FLOAT32_TOLERANCE)
    ok = [args for address, args in collector.messages if address == "/VMC/Ext/OK"]
    assert ok == [(1,)]


def test_send_rate_30_drops_every_other_60fps_frame():
    with Collector() as collector:
        bridge = VmcBridge(VmcConfig(port=collector.port, send_rate=30.0))
        sent = 0
        for seq in range(10):
            before = bridge.sender.sent_datagrams
            bridge.send(moving_frame(seq, fps=60.0, clock_now=seq / 60.0))
            sent += bridge.sender.sent_datagrams > before
        bridge.close()
    assert sent == 5


MAX_REFUSED_FRAMES = 20_000  # a bound: on loopback about every other datagram is refused


def closed_udp_port() -> int:
    """A loopback UDP port nothing listens on (bound, then released)."""
    probe = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    probe.bind(("127.0.0.1", 0))
    free_port = probe.getsockname()[1]
    probe.close()
    return free_port


def test_receiver_not_running_never_raises_and_logs_once(caplog):
    bridge = VmcBridge(VmcConfig(port=closed_udp_port(), send_rate=60.0))
    with caplog.at_level(logging.WARNING):
        for seq in range(20):
            bridge.send(moving_frame(seq, fps=60.0, clock_now=seq / 60.0))
    bridge.close()
    assert bridge.sender.refused > 0  # ConnectionRefused really happened
    warnings = [r for r in caplog.records if r.levelno >= logging.WARNING]
    assert len(warnings) == 1
    assert "nobody is listening" in warnings[0].getMessage()


def test_nobody_listening_is_said_once_with_a_hint_and_then_only_counted(caplog):
    """More refused sends than the error throttle's period (a demo with no VSeeFace running): one line that names
    the address and what to do, and every refused datagram in the bridge's counters."""
    port = closed_udp_port()
    bridge = VmcBridge(VmcConfig(port=port, send_rate=60.0))
    per_frame = len(bridge.encoder.encode(moving_frame(0), 0.0))
    frames = 0
    with caplog.at_level(logging.WARNING):
        while bridge.sender.refused <= LOG_EVERY_N_ERRORS and frames < MAX_REFUSED_FRAMES:
            bridge.send(moving_frame(frames, fps=60.0, clock_now=frames / 60.0))
            frames += 1
    bridge.close()
    assert bridge.sender.refused > LOG_EVERY_N_ERRORS
    assert bridge.counters() == {"vmc_refused_datagrams": bridge.sender.refused, "vmc_failed_datagrams": 0}
    assert bridge.sender.sent_datagrams + bridge.sender.refused == frames * per_frame
    messages = [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING]
    assert messages == [f"nobody is listening on 127.0.0.1:{port} (VMC); start VSeeFace, Warudo or EVMC4U there, or "
                        "send elsewhere with --vmc HOST:PORT (said once; the stream keeps going)"]


def speaking_frame(weights=(0.1, 0.2, 0.3, 0.15, 0.05)) -> PoseFrame:
    rest = rest_frame()
    return replace(rest, visemes=np.array(weights, np.float32))


@pytest.mark.parametrize("mode", sorted(VISEME_NAMES))
def test_visemes_go_out_as_blend_values_and_one_apply(mode):
    frame = speaking_frame()
    bundles = VmcEncoder(config=VmcConfig(viseme_names=VISEME_NAMES[mode])).encode(frame, stream_time=0.0)
    assert all(len(b) <= MAX_DATAGRAM_SIZE for b in bundles)
    messages = parse(bundles)
    blends = [(params[0], params[1]) for address, params in messages if address == "/VMC/Ext/Blend/Val"]
    assert [name for name, _ in blends] == list(VISEME_NAMES[mode])
    np.testing.assert_allclose([value for _, value in blends], frame.visemes, atol=FLOAT32_TOLERANCE)
    addresses = [address for address, _ in messages]
    assert addresses.count("/VMC/Ext/Blend/Apply") == 1
    assert addresses.index("/VMC/Ext/Blend/Apply") > max(i for i, a in enumerate(addresses) if a.endswith("Val"))


def test_no_blend_shapes_without_names_or_weights():
    silent_config = VmcEncoder(config=VmcConfig(viseme_names=VISEME_NAMES["vrm0"]))
    for encoder, frame in ((VmcEncoder(), speaking_frame()), (silent_config, rest_frame())):
        assert not [a for a, _ in parse(encoder.encode(frame, 0.0)) if a.startswith("/VMC/Ext/Blend")]


def test_assistant_sends_no_root_and_only_its_bones():
    config = VmcConfig(viseme_names=VISEME_NAMES["vrm1"], bones=("LeftUpperArm", "RightHand"), assistant=True)
    addresses = [(a, p[0] if p else None) for a, p in parse(VmcEncoder(config=config).encode(speaking_frame(), 0.0))]
    assert [name for a, name in addresses if a == "/VMC/Ext/Bone/Pos"] == ["LeftUpperArm", "RightHand"]
    assert not {a for a, _ in addresses} & {"/VMC/Ext/Root/Pos", "/VMC/Ext/OK", "/VMC/Ext/T"}
    assert [name for a, name in addresses if a == "/VMC/Ext/Blend/Val"] == ["aa", "ih", "ou", "ee", "oh"]


def test_assistant_with_no_bones_sends_visemes_only():
    config = VmcConfig(viseme_names=VISEME_NAMES["vrm0"], bones=(), assistant=True)
    addresses = {a for a, _ in parse(VmcEncoder(config=config).encode(speaking_frame(), 0.0))}
    assert addresses == {"/VMC/Ext/Blend/Val", "/VMC/Ext/Blend/Apply"}


def full_frame(seq: int = 5) -> PoseFrame:
    """Every bone moving, the root displaced, every viseme at full weight."""
    return replace(moving_frame(seq), visemes=np.ones(5, np.float32))


def long_named(extra: int) -> Skeleton:
    """The 52-bone skeleton with ``extra`` characters added to every bone name (each OSC string padding)."""
    names = tuple(name + "X" * extra for name in CANONICAL_WITH_HANDS.names)
    return Skeleton(names, CANONICAL_WITH_HANDS.parents, CANONICAL_WITH_HANDS.offsets)


@pytest.mark.parametrize("extra", range(8))
@pytest.mark.parametrize("mode", sorted(VISEME_NAMES))
def test_every_datagram_of_a_full_frame_crosses_a_1500_mtu_unfragmented(mode, extra):
    """Root, 52 bones, 5 blend shapes + Apply, OK and T: no bundle over 1472 bytes (it was 1500: 1528 on the wire)."""
    skeleton = long_named(extra)
    bundles = VmcEncoder(skeleton, VmcConfig(viseme_names=VISEME_NAMES[mode])).encode(full_frame(), 1.0)
    assert max(len(b) for b in bundles) <= IPV4_PAYLOAD_LIMIT
    addresses = [address for address, _ in parse(bundles)]
    assert addresses.count("/VMC/Ext/Bone/Pos") == 52 and addresses[-2:] == ["/VMC/Ext/OK", "/VMC/Ext/T"]
    assert addresses.count("/VMC/Ext/Blend/Val") == 5


def received_sizes(family: int, host: str, config: VmcConfig) -> tuple[list[int], int]:
    """Sizes of the datagrams one full frame puts on a real UDP socket of ``family`` at ``host``, and how many
    the bridge sent."""
    with socket.socket(family, socket.SOCK_DGRAM) as receiver:
        receiver.bind((host, 0))
        receiver.settimeout(RECEIVE_TIMEOUT_S)
        address = f"[{host}]" if family == socket.AF_INET6 else host  # as given to --vmc HOST:PORT
        target, port = parse_host_port(f"{address}:{receiver.getsockname()[1]}", "--vmc")
        bridge = VmcBridge(replace(config, host=target, port=port))
        bridge.send(full_frame())
        bridge.close()
        return [len(receiver.recv(65536)) for _ in range(bridge.sender.sent_datagrams)], bridge.sender.sent_datagrams


def ipv6_loopback() -> bool:
    try:
        with socket.socket(socket.AF_INET6, socket.SOCK_DGRAM) as probe:
            probe.bind(("::1", 0))
    except OSError:
        return False
    return True


@pytest.mark.parametrize("assistant", [False, True])
def test_an_ipv6_receiver_gets_datagrams_of_at_most_1452_bytes(assistant):
    """The limit follows the target's address family: 20 bytes less over IPv6 ([::1]:PORT), 1472 over IPv4."""
    if not ipv6_loopback():
        pytest.skip("no IPv6 loopback here")
    config = VmcConfig(viseme_names=VISEME_NAMES["vrm0"], assistant=assistant)
    sizes6, sent6 = received_sizes(socket.AF_INET6, "::1", config)
    sizes4, sent4 = received_sizes(socket.AF_INET, "127.0.0.1", config)
    assert sent6 >= 3 and max(sizes6) <= IPV6_PAYLOAD_LIMIT
    assert sent4 >= 3 and IPV6_PAYLOAD_LIMIT < max(sizes4) <= IPV4_PAYLOAD_LIMIT  # IPv4 is not held to IPv6's limit
    assert sum(sizes6) == sum(sizes4) + 16 * (sent6 - sent4)  # the same messages, more bundle headers


@pytest.mark.parametrize(("vmc", "role", "address"), [
    ("[::1]", "marionette", ("::1", 39539)), ("[::1]", "assistant", ("::1", 39540)),
    ("[::1]:4000", "marionette", ("::1", 4000)), ("::1:4000", "marionette", ("::1", 4000)),
    ("192.168.1.20", "marionette", ("192.168.1.20", 39539)),
])
def test_an_ipv6_vmc_host_is_written_in_brackets(vmc, role, address):
    assert Outputs(vmc=vmc, vmc_role=role).vmc_address() == address
