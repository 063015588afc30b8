import struct
from dataclasses import replace

import numpy as np
import pytest
from bridge_test_frames import moving_frame
from pythonosc.osc_packet import OscPacket

from gesturecast.bridges.coords import FRAMES
from gesturecast.bridges.osc import OscBridge, OscConfig, OscEncoder
from gesturecast.frames import VISEME_NAMES, PoseFrame
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS as SKELETON  # what the session sends

FLOAT32_TOLERANCE = 1e-4  # centimetre-scaled Unreal positions are ~100x larger
IPV4_PAYLOAD_LIMIT = 1500 - 20 - 8  # an Ethernet MTU less the IPv4 and UDP headers
IPV6_PAYLOAD_LIMIT = 1500 - 40 - 8


def decode(datagrams: list[bytes]) -> dict[str, list]:
    return {m.message.address: m.message.params for d in datagrams for m in OscPacket(d).messages}


def test_frame_message_bytes():
    frame = PoseFrame(42, 1.5, 1.6, SKELETON.offsets[0], np.tile([0.0, 0.0, 0.0, 1.0], (SKELETON.num_joints, 1)))
    datagrams = OscEncoder(OscConfig(bundled=False)).encode(frame, 1.5)
    assert datagrams[0] == b"/gesturecast/frame\0\0,if\0" + struct.pack(">if", 42, 1.5)
    assert datagrams[2] == b"/gesturecast/bone/Hips\0\0,ffff\0\0\0" + struct.pack(">4f", 0, 0, 0, 1)


@pytest.mark.parametrize("frame_name", sorted(FRAMES))
def test_address_scheme_and_values_per_coordinate_frame(frame_name):
    frame = moving_frame(9)
    coords = FRAMES[frame_name]
    values = decode(OscEncoder(OscConfig(coordinate_frame=frame_name)).encode(frame, 0.0))
    bones = [f"/gesturecast/bone/{n}" for n in SKELETON.names]
    assert list(values) == ["/gesturecast/frame", "/gesturecast/root", *bones]
    assert values["/gesturecast/frame"][0] == 9
    root = coords.position(frame.root_position)
    np.testing.assert_allclose(values["/gesturecast/root"], root, atol=FLOAT32_TOLERANCE)
    for j, name in enumerate(SKELETON.names):
        expected = coords.rotation(frame.rotations[j])
        np.testing.assert_allclose(values[f"/gesturecast/bone/{name}"], expected, atol=FLOAT32_TOLERANCE)


def test_bundled_and_unbundled_carry_the_same_messages():
    frame = moving_frame(3)
    bundled = OscEncoder(OscConfig(bundled=True)).encode(frame, 0.0)
    single = OscEncoder(OscConfig(bundled=False)).encode(frame, 0.0)
    assert all(len(d) <= IPV4_PAYLOAD_LIMIT for d in bundled)
    assert len(single) == 2 + SKELETON.num_joints
    assert decode(bundled) == decode(single)


def test_receiver_not_running_is_survivable():
    bridge = OscBridge(OscConfig(port=9, send_rate=60.0))  # discard port: nothing listens here
    for seq in range(5):
        bridge.send(moving_frame(seq, fps=60.0, clock_now=seq / 60.0))
    bridge.close()
    per_frame = len(bridge.encoder.encode(moving_frame(0), 0.0))  # bundles of one frame (3 with the fingers)
    assert bridge.sender.sent_datagrams + bridge.sender.refused + bridge.sender.errors.count == 5 * per_frame
    assert bridge.counters() == {"osc_refused_datagrams": bridge.sender.refused,
                                 "osc_failed_datagrams": bridge.sender.errors.count}


TWO_DAYS_S = 2 * 24 * 3600.0


def test_frame_time_keeps_frame_steps_after_two_days_of_uptime():
    """Over real UDP on loopback: the float32 frame time counts from the stream's first frame, so 30 fps frames
    stay 33.3 ms apart; as seconds since boot they would step 0 or 31.25 ms after 2 days of uptime."""
    import socket

    receiver = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    receiver.bind(("127.0.0.1", 0))
    receiver.settimeout(5.0)
    bridge = OscBridge(OscConfig(port=receiver.getsockname()[1], send_rate=30.0))
    frames = 10
    try:
        for seq in range(frames):
            bridge.send(moving_frame(seq, clock_now=TWO_DAYS_S + seq / 30.0))
        times = []
        while len(times) < frames:
            values = decode([receiver.recv(65536)])
            if "/gesturecast/frame" in values:
                times.append(values["/gesturecast/frame"][1])
    finally:
        bridge.close()
        receiver.close()
    np.testing.assert_allclose(np.diff(times), 1 / 30.0, atol=1e-6)
    assert times[0] == 0.0


@pytest.mark.parametrize("mode", sorted(VISEME_NAMES))
def test_visemes_go_out_under_their_names(mode):
    weights = np.array([0.5, 0.0, 0.25, 0.125, 0.0625], np.float32)
    frame = replace(moving_frame(3), visemes=weights)
    values = decode(OscEncoder(OscConfig(viseme_names=VISEME_NAMES[mode])).encode(frame, 0.0))
    sent = {address.rsplit("/", 1)[1]: params for address, params in values.items() if "/viseme/" in address}
    assert sent == {name: [float(w)] for name, w in zip(VISEME_NAMES[mode], weights, strict=True)}
    assert not [a for a in decode(OscEncoder().encode(frame, 0.0)) if "/viseme/" in a]  # no names: no visemes


@pytest.mark.parametrize(("host", "limit"), [("127.0.0.1", IPV4_PAYLOAD_LIMIT), ("::1", IPV6_PAYLOAD_LIMIT)])
def test_bundles_cross_a_1500_mtu_unfragmented_by_address_family(host, limit):
    """Frame, root, 52 bones and 5 visemes: every bundle within the target family's unfragmented payload
    (the largest was 1492 bytes, fragmented on a LAN)."""
    try:
        bridge = OscBridge(OscConfig(host=host, port=9, viseme_names=VISEME_NAMES["vrm1"]))
    except OSError:
        pytest.skip(f"no {host} here")
    frame = replace(moving_frame(3), visemes=np.ones(5, np.float32))
    datagrams = bridge.encoder.encode(frame, 0.0)
    bridge.close()
    assert max(len(d) for d in datagrams) <= limit
    assert len(decode(datagrams)) == 2 + SKELETON.num_joints + 5


def test_gesture_start_and_end_go_out_when_the_frames_gesture_changes():
    encoder = OscEncoder(OscConfig(bundled=False))
    messages = [m.message for d in encoder.encode(replace(moving_frame(3), gesture="wave+bow"), 0.1, "wave")
                for m in OscPacket(d).messages]
    assert [(m.address, m.params) for m in messages[:1]] == [("/gesturecast/gesture/start", ["bow"])]
    ended = decode(encoder.encode(replace(moving_frame(4), gesture=""), 0.2, "bow"))
    assert ended["/gesturecast/gesture/end"] == ["bow"] and "/gesturecast/gesture/start" not in ended
    assert not [a for a in decode(encoder.encode(moving_frame(5), 0.3, "")) if "/gesture/" in a]
