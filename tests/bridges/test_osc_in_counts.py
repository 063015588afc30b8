"""OSC input's drops reach the run's summary line (a real `live` process): before, they were counted and never
shown."""

import socket

import soundfile

from gesturecast.bridges.osc_in import GESTURE_ADDRESS
from gesturecast.bridges.osc_wire import osc_string
from gesturecast.models.audio.files import PACKAGED_SAMPLE, SAMPLE_RATE, load_audio


def message(address: str, *strings: str) -> bytes:
    return osc_string(address) + osc_string("," + "s" * len(strings)) + b"".join(osc_string(s) for s in strings)


def test_the_summary_line_shows_the_osc_messages_dropped(cli_process, tmp_path):
    soundfile.write(tmp_path / "talk.wav", load_audio(PACKAGED_SAMPLE)[: 4 * SAMPLE_RATE], SAMPLE_RATE)
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    live = cli_process(["live", "--input", str(tmp_path / "talk.wav"), "--bvh", str(tmp_path / "take.bvh"),
                        "--osc-in", str(port)])
    live.wait_for_stderr("controls by OSC on", 120)
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sender:
        for datagram in (b"\x00garbage", message("/other/address", "x"), message("/other/address", "y"),
                         message(GESTURE_ADDRESS, "no-such-gesture")):
            sender.sendto(datagram, ("127.0.0.1", port))
    code, _, stdout = live.wait(60)
    assert code == 0
    for shown in ("osc in malformed 1", "osc in other address 2", "osc in refused 1"):
        assert shown in stdout, stdout
