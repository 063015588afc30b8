import struct

import numpy as np
import pytest
from pythonosc.osc_bundle_builder import IMMEDIATELY, OscBundleBuilder
from pythonosc.osc_message_builder import OscMessageBuilder

from gesturecast.bridges.osc_wire import MessageLayout, bundle, osc_string, pack_bundles


@pytest.mark.parametrize(
    ("text", "expected"),
    [("", b"\0\0\0\0"), ("abc", b"abc\0"), ("abcd", b"abcd\0\0\0\0"), ("/VMC/Ext/T", b"/VMC/Ext/T\0\0")],
)
def test_osc_string_padding(text, expected):
    assert osc_string(text) == expected


@pytest.mark.parametrize(
    ("layout", "values", "expected"),
    [
        (MessageLayout("/VMC/Ext/OK", (), "i"), (1,), b"/VMC/Ext/OK\0,i\0\0\0\0\0\1"),
        (MessageLayout("/VMC/Ext/T", (), "f"), (1.5,), b"/VMC/Ext/T\0\0,f\0\0" + b"\x3f\xc0\0\0"),
        (
            MessageLayout("/a", ("Hips",), "fi"),
            (-2.0, 7),
            b"/a\0\0,sfi\0\0\0\0Hips\0\0\0\0" + b"\xc0\0\0\0" + b"\0\0\0\7",
        ),
    ],
)
def test_message_bytes(layout, values, expected):
    assert layout.encode(*values) == expected
    assert layout.size == len(expected)


def test_messages_match_python_osc_builder():
    builder = OscMessageBuilder("/VMC/Ext/Bone/Pos")
    values = [0.1, -0.2, 0.3, 0.0, 0.7071067, 0.0, 0.7071067]
    builder.add_arg("LeftUpperArm")
    for value in values:
        builder.add_arg(value, "f")
    layout = MessageLayout("/VMC/Ext/Bone/Pos", ("LeftUpperArm",), "fffffff")
    assert layout.encode_floats(np.array(values)) == builder.build().dgram
    assert layout.encode(*values) == builder.build().dgram


def test_bundle_matches_python_osc_builder():
    messages = [MessageLayout("/x", (), "i").encode(3), MessageLayout("/y", (), "f").encode(0.25)]
    builder = OscBundleBuilder(IMMEDIATELY)
    for address, tag, value in (("/x", "i", 3), ("/y", "f", 0.25)):
        message = OscMessageBuilder(address)
        message.add_arg(value, tag)
        builder.add_content(message.build())
    theirs = builder.build().dgram
    # python-osc writes "immediately" as 1 too; the element layout (size prefix + message) must match
    assert bundle(messages) == theirs
    assert bundle(messages)[:16] == b"#bundle\0" + struct.pack(">Q", 1)


def test_pack_bundles_respects_size_and_order():
    messages = [MessageLayout(f"/m{i:03d}", (), "ffff").encode(i, 0, 0, 0) for i in range(100)]  # 32 bytes each
    bundles = pack_bundles(messages, max_size=200)
    assert all(len(b) <= 200 for b in bundles)
    assert len(bundles) == 20  # (200 - 16) // (4 + 32) = 5 per bundle, 100 messages
    rejoined = b"".join(b[16:] for b in bundles)
    assert rejoined == b"".join(struct.pack(">i", len(m)) + m for m in messages)


def test_oversized_message_is_refused():
    with pytest.raises(ValueError, match="cannot fit"):
        pack_bundles([b"\0" * 1500])


def test_only_float_and_int_numbers():
    with pytest.raises(ValueError, match="'f' or 'i'"):
        MessageLayout("/x", (), "d")
