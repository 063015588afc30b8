"""OSC input: /gesturecast/gesture NAME becomes a gesture control; the rest is dropped and counted; beyond loopback
the token is the second string; a port in use is one line."""

import socket
import struct
import time

import pytest

from gesturecast.bridges.osc_in import (
    GESTURE_ADDRESS,
    INTENSITY_ADDRESS,
    PAUSE_ADDRESS,
    OscControlListener,
    OscFormatError,
    OscInConfig,
    parse_datagram,
)
from gesturecast.bridges.osc_wire import bundle, osc_string
from gesturecast.controls import Gesture, StyleChange
from gesturecast.errors import UserError


def message(address: str, *strings: str) -> bytes:
    return osc_string(address) + osc_string("," + "s" * len(strings)) + b"".join(osc_string(s) for s in strings)


def test_messages_and_bundles_decode():
    numbers = osc_string("/x") + osc_string(",if") + struct.pack(">if", 7, 0.5)
    assert parse_datagram(message(GESTURE_ADDRESS, "wave")) == [(GESTURE_ADDRESS, ["wave"])]
    assert parse_datagram(bundle([message("/a", "b"), numbers])) == [("/a", ["b"]), ("/x", [7, 0.5])]
    for bad in (b"no-slash\x00\x00\x00\x00", b"/x\x00\x00,q\x00\x00", b"/unterminated", bundle([b"/a"])[:-2]):
        with pytest.raises(OscFormatError):
            parse_datagram(bad)


def received(listener: OscControlListener, *datagrams: bytes) -> None:
    for datagram in datagrams:
        listener.handle(datagram)


def test_a_gesture_message_becomes_a_control_and_the_rest_is_counted():
    controls = []
    listener = OscControlListener(OscInConfig(port=0), controls.append)
    try:
        received(listener, message(GESTURE_ADDRESS, "wave"), message("/other", "x"), b"junk",
                 message(GESTURE_ADDRESS, "wave", "extra"), bundle([message(GESTURE_ADDRESS, "bow")]))
    finally:
        listener.close()
    assert controls == [(Gesture("wave"),), (Gesture("bow"),)]
    assert listener.counts == {"received": 5, "controls": 2, "other_address": 1, "malformed": 1, "bad_arguments": 1}


def test_gesture_size_and_pause_messages_become_their_controls():
    controls = []
    listener = OscControlListener(OscInConfig(port=0), controls.append)
    size = osc_string(INTENSITY_ADDRESS) + osc_string(",f") + struct.pack(">f", 0.5)
    pause, resume = (osc_string(PAUSE_ADDRESS) + osc_string(",i") + struct.pack(">i", on) for on in (1, 0))
    toggle = osc_string(PAUSE_ADDRESS) + osc_string(",f") + struct.pack(">f", 1.0)
    too_big = osc_string(INTENSITY_ADDRESS) + osc_string(",f") + struct.pack(">f", 3.0)
    try:
        received(listener, size, pause, resume, toggle, too_big, message(PAUSE_ADDRESS, "yes"))
    finally:
        listener.close()
    assert controls == [(StyleChange(intensity=0.5),), (StyleChange(pause=True),), (StyleChange(pause=False),),
                        (StyleChange(pause=True),)]
    assert listener.counts == {"received": 6, "controls": 4, "refused": 2}


def test_over_udp_from_another_program():
    controls = []
    listener = OscControlListener(OscInConfig(port=0), controls.append).start()
    try:
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sender:
            sender.sendto(message(GESTURE_ADDRESS, "raise-both"), ("127.0.0.1", listener.port))
        deadline = time.monotonic() + 5
        while not controls and time.monotonic() < deadline:
            time.sleep(0.01)
    finally:
        listener.close()
    assert controls == [(Gesture("raise-both"),)]


def test_beyond_loopback_the_token_is_needed_and_checked():
    with pytest.raises(UserError, match="token"):
        OscControlListener(OscInConfig(host="0.0.0.0", port=0), print)
    token = "correct-horse-battery-staple"
    controls = []
    listener = OscControlListener(OscInConfig(host="0.0.0.0", port=0, token=token), controls.append)
    try:
        received(listener, message(GESTURE_ADDRESS, "wave"), message(GESTURE_ADDRESS, "wave", "wrong-token-here"),
                 message(GESTURE_ADDRESS, "wave", token))
    finally:
        listener.close()
    assert controls == [(Gesture("wave"),)] and listener.counts["wrong_token"] == 1


def test_a_refused_gesture_is_counted_and_a_port_in_use_is_one_line():
    def refuse(control):
        raise UserError("unknown gesture 'wav'")

    listener = OscControlListener(OscInConfig(port=0), refuse)
    try:
        received(listener, message(GESTURE_ADDRESS, "wav"))
        assert listener.counts["refused"] == 1
        with pytest.raises(UserError, match=f"--osc-in 127.0.0.1:{listener.port}: cannot listen there"):
            OscControlListener(OscInConfig(port=listener.port), print)
    finally:
        listener.close()


def free_udp_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def test_live_waves_when_an_osc_gesture_arrives(cli_process, tmp_path):
    import soundfile

    from gesturecast.models.audio.files import PACKAGED_SAMPLE, SAMPLE_RATE, load_audio

    soundfile.write(tmp_path / "talk.wav", load_audio(PACKAGED_SAMPLE)[: 6 * SAMPLE_RATE], SAMPLE_RATE)
    port = free_udp_port()
    live = cli_process(["live", "--input", str(tmp_path / "talk.wav"), "--bvh", str(tmp_path / "take.bvh"),
                        "--osc-in", str(port)])
    live.wait_for_stderr("controls by OSC on", 120)
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sender:
        sender.sendto(message(GESTURE_ADDRESS, "wave"), ("127.0.0.1", port))
    code, _, _ = live.wait(60)
    assert code == 0
    assert live.wait_for_stderr("gesture wave (control) on time, stroke at", 1)
