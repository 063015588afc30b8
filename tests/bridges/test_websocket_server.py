import dataclasses
import json
import logging
import socket
import struct
import time
import urllib.request

import numpy as np
import pytest
from bridge_test_frames import CAPTURE_AGE_S, moving_frame
from websockets.exceptions import ConnectionClosed, InvalidStatus
from websockets.sync.client import connect

from gesturecast.bridges.coords import UNREAL
from gesturecast.bridges.websocket_server import WebSocketBridge, WebSocketConfig
from gesturecast.bridges.ws_protocol import BINARY_HEADER
from gesturecast.controls import StyleChange
from gesturecast.errors import UserError
from gesturecast.message_rate import RateLimits
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS

TIMEOUT_S = 5.0
J = CANONICAL_WITH_HANDS.num_joints
SLOW_CLIENT_CLOSE_S = 0.2


@pytest.fixture
def controls() -> list[dict]:
    return []


@pytest.fixture
def bridge(controls):
    server = WebSocketBridge(WebSocketConfig(port=0), on_control=controls.append).start()
    yield server
    server.close()


def ws_url(bridge: WebSocketBridge) -> str:
    return f"ws://127.0.0.1:{bridge.port}/"


def hello_of(client) -> dict:
    hello = json.loads(client.recv(TIMEOUT_S))
    assert hello["type"] == "hello"
    return hello


def next_binary(client) -> bytes:
    while isinstance(message := client.recv(TIMEOUT_S), str):
        pass
    return message


def wait_for_clients(bridge: WebSocketBridge, count: int) -> None:
    deadline = time.monotonic() + TIMEOUT_S
    while bridge.client_count() != count:
        assert time.monotonic() < deadline, "clients never registered"
        time.sleep(0.01)


def test_hello_describes_the_stream(bridge):
    with connect(ws_url(bridge)) as client:
        hello = hello_of(client)
    assert hello["format_version"] == 1
    assert hello["bones"] == list(CANONICAL_WITH_HANDS.names)
    assert hello["parents"] == list(CANONICAL_WITH_HANDS.parents)
    np.testing.assert_allclose(hello["offsets"], CANONICAL_WITH_HANDS.offsets, atol=1e-6)
    assert hello["fps"] == 30.0 and hello["coordinate_frame"] == "internal"
    assert hello["token_required"] is False


def test_binary_frames_to_many_clients():
    bridge = WebSocketBridge(WebSocketConfig(port=0, coordinate_frame="unreal")).start()
    try:
        with connect(ws_url(bridge)) as a, connect(ws_url(bridge)) as b:
            hello_of(a), hello_of(b)
            wait_for_clients(bridge, 2)
            frame = moving_frame(12)
            bridge.send(frame)
            payloads = [next_binary(a), next_binary(b)]
    finally:
        bridge.close()
    assert payloads[0] == payloads[1]
    assert len(payloads[0]) == BINARY_HEADER.size + 16 * J
    magic, seq, capture, sent, x, y, z, count, flags = BINARY_HEADER.unpack_from(payloads[0])
    assert (magic, seq, count, flags) == (b"GCPF", 12, J, 1)
    assert 0.0 <= sent - capture - CAPTURE_AGE_S < 1.0
    np.testing.assert_allclose([x, y, z], UNREAL.position(frame.root_position), atol=1e-4)
    quats = np.frombuffer(payloads[0], dtype="<f4", offset=BINARY_HEADER.size).reshape(J, 4)
    np.testing.assert_allclose(quats, UNREAL.rotation(frame.rotations), atol=1e-6)


def test_json_frames_on_request_and_style_announcement(bridge):
    with connect(ws_url(bridge)) as client:
        hello_of(client)
        client.send(json.dumps({"type": "subscribe", "format": "json"}))
        assert json.loads(client.recv(TIMEOUT_S)) == {"type": "subscribed", "format": "json"}
        bridge.send(moving_frame(3, style="happy"))
        style, frame = json.loads(client.recv(TIMEOUT_S)), json.loads(client.recv(TIMEOUT_S))
    assert style == {"type": "style", "style": "happy"}
    assert frame["type"] == "frame" and frame["seq"] == 3
    np.testing.assert_allclose(frame["rotations"], moving_frame(3).rotations, atol=1e-6)


def test_control_reaches_engine_and_garbage_is_answered(bridge, controls, caplog):
    garbage = ["not json", "[1, 2]", '{"type": "dance"}', '{"type": "control", "guidance": 99}', b"\x00\x01"]
    with caplog.at_level(logging.WARNING), connect(ws_url(bridge)) as client:
        hello_of(client)
        replies = []
        for message in garbage:
            client.send(message)
            replies.append(json.loads(client.recv(TIMEOUT_S)))
        client.send(json.dumps({"type": "control", "style": "angry", "guidance": 2.5}))
        ack = json.loads(client.recv(TIMEOUT_S))
        bridge.send(moving_frame(1))  # the stream still flows to this client
        assert next_binary(client)[:4] == b"GCPF"
    assert [r["type"] for r in replies] == ["error"] * len(garbage)
    assert "within [0, 10]" in replies[3]["message"]
    assert ack == {"type": "ack", "applied": {"style": "angry", "guidance": 2.5}}
    assert controls == [(StyleChange(style="angry", guidance=2.5),)]
    rejected = [r for r in caplog.records if "control message rejected" in r.getMessage()]
    assert len(rejected) == 1  # one clear line, not one per garbage message


TOKEN = "correct-horse-battery-staple"


def test_token_is_required_when_configured_or_exposed(controls):
    with pytest.raises(UserError, match="give a token"):
        WebSocketBridge(WebSocketConfig(host="0.0.0.0", port=0))
    with pytest.raises(UserError, match="too weak"):
        WebSocketBridge(WebSocketConfig(port=0, token="s3cret"))
    bridge = WebSocketBridge(WebSocketConfig(port=0, token=TOKEN), on_control=controls.append).start()
    try:
        with connect(ws_url(bridge)) as client:
            assert hello_of(client)["token_required"] is True
            client.send(json.dumps({"type": "control", "style": "sad"}))
            missing = json.loads(client.recv(TIMEOUT_S))
            client.send(json.dumps({"type": "control", "style": "sad", "token": TOKEN}))
            accepted = json.loads(client.recv(TIMEOUT_S))
        with connect(ws_url(bridge)) as guesser:
            hello_of(guesser)
            guesser.send(json.dumps({"type": "control", "style": "sad", "token": "guess"}))
            wrong = json.loads(guesser.recv(TIMEOUT_S))
            with pytest.raises(ConnectionClosed) as closed:
                guesser.recv(TIMEOUT_S)
    finally:
        bridge.close()
    assert missing["type"] == "error" and "needs a token" in missing["message"]
    assert accepted["type"] == "ack" and controls == [(StyleChange(style="sad"),)]
    assert wrong == {"type": "error", "message": "wrong token; closing the connection"}
    assert closed.value.rcvd.code == 1008


def test_port_in_use_is_one_line_user_error_naming_the_live_flag():
    with socket.socket() as holder:
        holder.bind(("127.0.0.1", 0))
        holder.listen()
        port = holder.getsockname()[1]
        with pytest.raises(UserError) as error:
            WebSocketBridge(WebSocketConfig(port=port)).start()
    assert str(error.value) == f"port {port} on 127.0.0.1 is in use; pick another with --ws"


def test_only_the_viewers_own_origin_may_connect(bridge):
    own = [None, f"http://127.0.0.1:{bridge.port}", f"http://localhost:{bridge.port}"]
    hellos = []
    for origin in own:
        with connect(ws_url(bridge), origin=origin) as client:
            hellos.append(hello_of(client)["type"])
    with pytest.raises(InvalidStatus) as refused:
        connect(ws_url(bridge), origin="https://evil.example")
    assert hellos == ["hello"] * len(own)
    assert refused.value.response.status_code == 403


def test_hello_names_the_style_before_the_first_frame():
    bridge = WebSocketBridge(WebSocketConfig(port=0, style="happy")).start()
    try:
        with connect(ws_url(bridge)) as client:
            style = hello_of(client)["style"]
    finally:
        bridge.close()
    assert style == "happy"


def test_hostile_json_is_answered_and_the_connection_stays(bridge, controls):
    hostile = ["[" * 30000 + "]" * 30000, '{"type": "control", "guidance": ' + "9" * 5000 + "}"]
    with connect(ws_url(bridge)) as client:
        hello_of(client)
        replies = []
        for message in hostile:
            client.send(message)
            replies.append(json.loads(client.recv(TIMEOUT_S)))
        client.send(json.dumps({"type": "control", "guidance": 2.0}))
        ack = json.loads(client.recv(TIMEOUT_S))
    assert [r["type"] for r in replies] == ["error", "error"]
    assert "nested too deeply" in replies[0]["message"] and "too many digits" in replies[1]["message"]
    assert ack["type"] == "ack" and controls == [(StyleChange(guidance=2.0),)]


def test_client_vanishing_mid_stream_leaves_stream_running(bridge):
    with connect(ws_url(bridge)) as survivor, connect(ws_url(bridge)) as vanishing:
        hello_of(survivor), hello_of(vanishing)
        wait_for_clients(bridge, 2)
        bridge.send(moving_frame(0))
        next_binary(vanishing)
        vanishing.socket.close()  # no closing handshake: the TCP connection just dies
        seqs = [struct.unpack_from("<I", next_binary(survivor), 4)[0]]
        for seq in range(1, 30):
            bridge.send(moving_frame(seq))
            seqs.append(struct.unpack_from("<I", next_binary(survivor), 4)[0])
        wait_for_clients(bridge, 1)
    assert seqs == list(range(30))
    assert bridge.client_count() <= 1


def test_slow_client_is_skipped_not_buffered():
    bridge = WebSocketBridge(WebSocketConfig(port=0, slow_client_buffer_bytes=4096)).start()
    sock = socket.socket()
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    sock.connect(("127.0.0.1", bridge.port))
    try:
        # stops reading after a frame or two; on leaving it waits only briefly for the server's close frame, which
        # sits behind the frames it never read (the default 10 s wait is no part of what is tested)
        with connect(ws_url(bridge), sock=sock, max_queue=1, close_timeout=SLOW_CLIENT_CLOSE_S) as slow:
            hello_of(slow)
            wait_for_clients(bridge, 1)
            (connection,) = bridge._clients
            server_socket = connection.transport.get_extra_info("socket")
            server_socket.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, 4096)  # a slow network link
            for seq in range(3000):
                bridge.send(moving_frame(seq))
                if seq % 8 == 0:
                    time.sleep(0.001)  # let the server loop drain the pending slot
            time.sleep(0.2)
            (state,) = bridge._clients.values()
            buffered = connection.transport.get_write_buffer_size()
    finally:
        bridge.close()
    assert state.skipped_frames > 0
    assert bridge.counters()["slow_client_skips"] == state.skipped_frames  # reported beyond the client's life
    assert buffered <= 4096 + BINARY_HEADER.size + 16 * J + 64


def test_viewer_page_is_served_over_http(bridge):
    with urllib.request.urlopen(f"http://127.0.0.1:{bridge.port}/", timeout=TIMEOUT_S) as response:
        page = response.read().decode()
        assert response.headers["Content-Type"].startswith("text/html")
    assert '<canvas id="stage"' in page and "viewer.js" in page
    with urllib.request.urlopen(f"http://127.0.0.1:{bridge.port}/viewer.js", timeout=TIMEOUT_S) as response:
        assert "forwardKinematics" in response.read().decode()


def test_lip_sync_names_the_visemes_in_the_hello_and_frames_carry_them():
    weights = np.array([0.1, 0.2, 0.3, 0.4, 0.5])
    server = WebSocketBridge(WebSocketConfig(port=0, lipsync=True, viseme_names=("aa", "ih", "ou", "ee", "oh")))
    server.start()
    try:
        with connect(ws_url(server)) as client:
            hello = hello_of(client)
            wait_for_clients(server, 1)
            server.send(dataclasses.replace(moving_frame(1), visemes=weights))
            payload = next_binary(client)
    finally:
        server.close()
    assert hello["visemes"] == ["aa", "ih", "ou", "ee", "oh"]
    assert len(payload) == BINARY_HEADER.size + 16 * J + 4 * len(weights)
    np.testing.assert_allclose(np.frombuffer(payload, dtype="<f4", offset=BINARY_HEADER.size + 16 * J), weights)


def test_without_lip_sync_the_hello_names_no_visemes(bridge):
    with connect(ws_url(bridge)) as client:
        assert hello_of(client)["visemes"] == []


def test_clients_see_the_gesture_playing_in_json_frames_and_a_side_message_on_each_change(bridge):
    with connect(ws_url(bridge)) as binary, connect(ws_url(bridge)) as client:
        hello_of(binary)
        hello_of(client)
        client.send(json.dumps({"type": "subscribe", "format": "json"}))
        json.loads(client.recv(TIMEOUT_S))
        wait_for_clients(bridge, 2)
        for seq, gesture in enumerate(["", "wave", "wave", ""]):
            bridge.send(dataclasses.replace(moving_frame(seq), gesture=gesture))
        texts = [json.loads(client.recv(TIMEOUT_S)) for _ in range(7)]  # style, 4 frames, 2 gesture messages
        side = [m for m in (binary.recv(TIMEOUT_S) for _ in range(7)) if isinstance(m, str)]
    frames = [m for m in texts if m["type"] == "frame"]
    changes = [(m["started"], m["ended"], m["seq"]) for m in texts if m["type"] == "gesture"]
    assert [f["gesture"] for f in frames] == ["", "wave", "wave", ""]
    assert changes == [(["wave"], [], 1), ([], ["wave"], 3)]
    assert [json.loads(m)["playing"] for m in side if json.loads(m)["type"] == "gesture"] == ["wave", ""]


def test_a_client_over_its_message_rate_is_told_so_and_its_stream_goes_on(controls):
    limits = RateLimits(messages_per_s=0.001, message_burst=2)  # two now, the next in about 17 minutes
    bridge = WebSocketBridge(WebSocketConfig(port=0, rate_limits=limits), on_control=controls.append).start()
    try:
        with connect(ws_url(bridge)) as client, connect(ws_url(bridge)) as other:
            hello_of(client)
            hello_of(other)
            replies = []
            for _ in range(3):
                client.send(json.dumps({"type": "control", "guidance": 2.0}))
                replies.append(json.loads(client.recv(TIMEOUT_S)))
            other.send(json.dumps({"type": "control", "guidance": 3.0}))  # each connection has its own limit
            other_reply = json.loads(other.recv(TIMEOUT_S))
            bridge.send(moving_frame(1))
            assert next_binary(client)[:4] == b"GCPF"  # the limited client still gets the stream
    finally:
        bridge.close()
    assert [reply["type"] for reply in replies] == ["ack", "ack", "error"]
    assert "rate limit" in replies[2]["message"] and "the stream goes on" in replies[2]["message"]
    assert other_reply["type"] == "ack"
    assert len(controls) == 3
