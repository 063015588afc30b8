"""serve protocol: audio decoding, start options, stream paths (pure functions, no server)."""

import numpy as np
import pytest

from gesturecast.controls import ControlError, StyleChange
from gesturecast.realtime.serve.protocol import decode_audio, parse_start, stream_id_from_path


def test_int16_and_float32_audio_decode_to_the_same_float_samples():
    pcm = np.array([-32768, -16384, 0, 16384, 32767], "<i2")
    from_int = decode_audio(pcm.tobytes(), "s16le")
    from_float = decode_audio((pcm / 32768.0).astype("<f4").tobytes(), "f32le")
    assert from_int.dtype == np.float32
    np.testing.assert_array_equal(from_int, from_float)
    assert from_int[0] == -1.0


@pytest.mark.parametrize(
    ("data", "audio_format", "reason"),
    [(b"", "f32le", "non-empty"), (b"\x00" * 3, "s16le", "multiple of 2"),
     (np.array([np.inf], "<f4").tobytes(), "f32le", "infinite")],
)
def test_bad_audio_is_refused_with_a_reason(data, audio_format, reason):
    with pytest.raises(ControlError, match=reason):
        decode_audio(data, audio_format)


def test_start_options_and_their_validation():
    options = parse_start({"type": "start", "prompt": "calm and slow", "style2": "old", "gamma": 0.5, "seed": 7,
                           "audio_format": "s16le", "token": "x"})
    assert options.style == StyleChange(prompt="calm and slow", style2="old", gamma=0.5)
    assert (options.seed, options.audio_format) == (7, "s16le")
    assert parse_start({"type": "start", "root": "free"}).style.root == "free"
    assert parse_start({"type": "start", "latency": "low"}).latency == "low"
    assert parse_start({"type": "start", "style_strength": 0.5}).style.style_strength == 0.5
    assert parse_start({"type": "start"}) == parse_start({"type": "start", "token": "x"})
    assert parse_start({"type": "start"}).latency is None
    for bad, reason in [({"seed": -1}, "seed"), ({"seed": True}, "seed"), ({"audio_format": "mp3"}, "audio_format"),
                        ({"volume": 1}, "unknown start field"), ({"style": "motion:x.bvh"}, "motion prompts"),
                        ({"root": "walk"}, "root must be one of"), ({"latency": "fast"}, "latency must be one of"),
                        ({"style_strength": 2.5}, "style_strength"), ({"gesture": "wave"}, "unknown start field")]:
        with pytest.raises(ControlError, match=reason):
            parse_start({"type": "start", **bad})


def test_stream_ids_come_from_the_path():
    assert stream_id_from_path("/stream/avatar-1", "auto") == "avatar-1"
    assert stream_id_from_path("/stream/a.b_c?x=1", "auto") == "a.b_c"
    assert stream_id_from_path("/", "auto") == stream_id_from_path("/stream", "auto") == "auto"
    for bad in ("/viewer", "/stream/../x", "/stream/" + "a" * 65):
        with pytest.raises(ControlError):
            stream_id_from_path(bad, "auto")


def test_connection_outbox_drops_the_oldest_and_counts_them():
    """A real event loop that is busy (then stopped before it drains): 3x the outbox bound is sent, the oldest
    beyond MAX_OUTGOING_MESSAGES are dropped and counted for the stream's stats."""
    import asyncio
    import threading
    import time

    from gesturecast.realtime.serve.server import MAX_OUTGOING_MESSAGES, LoopSender

    loop = asyncio.new_event_loop()
    thread = threading.Thread(target=loop.run_forever, daemon=True)
    thread.start()
    busy_s = 0.3
    loop.call_soon_threadsafe(time.sleep, busy_s)  # the loop is behind
    loop.call_soon_threadsafe(loop.stop)  # ... and stops before the drain queued below runs
    sender = LoopSender(loop, websocket=None)  # never written to: the loop stops first
    sent = 3 * MAX_OUTGOING_MESSAGES
    for index in range(sent):
        sender.send(f"message {index}")
    thread.join()
    loop.close()
    assert sender.counters() == {"outbox_drops": sent - MAX_OUTGOING_MESSAGES, "slow_client_skips": 0}
