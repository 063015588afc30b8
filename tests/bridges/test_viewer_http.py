"""The viewer port's plain HTTP: the avatar is streamed from disk behind the port's access rules, a bounded number
of downloads at a time, and HEAD gets headers without a body (real bridge on a free loopback port, raw sockets)."""

from __future__ import annotations

import socket
import time
from pathlib import Path

import numpy as np
import pytest

from gesturecast.bridges.viewer_http import MAX_AVATAR_TRANSFERS, AvatarServer
from gesturecast.bridges.websocket_server import WebSocketBridge, WebSocketConfig

TIMEOUT_S = 10.0
TOKEN = "correct-horse-battery-staple"
BIG_BYTES = 24 * 1024 * 1024  # more than loopback socket buffers hold: a client that reads nothing stalls it
SMALL_RECEIVE_BUFFER = 4096


@pytest.fixture(scope="module")
def big_avatar(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("avatar") / "big.vrm"
    noise = np.random.default_rng(0).integers(0, 256, BIG_BYTES - 4, dtype=np.uint8).tobytes()
    path.write_bytes(b"glTF" + noise)
    return path


def raw_request(port: int, request: str, read: bool = True, receive_buffer: int | None = None) -> socket.socket | bytes:
    """Send ``request`` on a new connection: the whole answer (head and body) once the server closes, or with
    ``read=False`` the open socket, unread."""
    client = socket.socket()
    if receive_buffer is not None:
        client.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, receive_buffer)
    client.settimeout(TIMEOUT_S)
    client.connect(("127.0.0.1", port))
    client.sendall(request.encode("ascii"))
    if not read:
        return client
    chunks = []
    with client:
        while chunk := client.recv(1 << 20):
            chunks.append(chunk)
    return b"".join(chunks)


def get(path: str, headers: str = "", method: str = "GET") -> str:
    return f"{method} {path} HTTP/1.1\r\nHost: 127.0.0.1\r\n{headers}\r\n"


def split(answer: bytes) -> tuple[int, dict[str, str], bytes]:
    """(status, headers, body) of a raw HTTP answer."""
    head, _, body = answer.partition(b"\r\n\r\n")
    lines = head.decode("latin-1").split("\r\n")
    headers = dict(line.split(": ", 1) for line in lines[1:])
    return int(lines[0].split()[1]), headers, body


@pytest.fixture
def bridge(big_avatar):
    server = WebSocketBridge(WebSocketConfig(port=0, avatar=big_avatar)).start()
    yield server
    server.close()


def wait_for(predicate) -> bool:
    deadline = time.monotonic() + TIMEOUT_S
    while not predicate() and time.monotonic() < deadline:
        time.sleep(0.01)
    return predicate()


def test_the_avatar_is_streamed_whole_and_head_gets_no_body(bridge, big_avatar):
    status, headers, body = split(raw_request(bridge.port, get("/avatar.vrm")))
    assert status == 200 and headers["Content-Type"] == "model/gltf-binary"
    assert int(headers["Content-Length"]) == BIG_BYTES and body == big_avatar.read_bytes()
    status, headers, body = split(raw_request(bridge.port, get("/avatar.vrm", method="HEAD")))
    assert (status, int(headers["Content-Length"]), body) == (200, BIG_BYTES, b"")
    status, headers, body = split(raw_request(bridge.port, get("/viewer.js", method="HEAD")))
    assert status == 200 and int(headers["Content-Length"]) > 0 and body == b""
    status, headers, _ = split(raw_request(bridge.port, get("/avatar.vrm", method="POST")))
    assert status == 405 and headers["Allow"] == "GET, HEAD"


def test_avatar_downloads_are_bounded_and_a_stalled_one_holds_no_file_in_memory(bridge, big_avatar):
    """Clients that never read fill the transfer slots (each held at a chunk plus the socket's buffers, not the
    file); one more gets 503 with Retry-After; once they leave, the next download is whole."""
    stalled = [raw_request(bridge.port, get("/avatar.vrm"), read=False, receive_buffer=SMALL_RECEIVE_BUFFER)
               for _ in range(MAX_AVATAR_TRANSFERS)]
    try:
        assert wait_for(lambda: len(bridge.avatar.transfers) == MAX_AVATAR_TRANSFERS)
        status, headers, _ = split(raw_request(bridge.port, get("/avatar.vrm")))
        assert status == 503 and headers["Retry-After"] == "1"
        buffered = [c.transport.get_write_buffer_size() for c in bridge.avatar.transfers]
        assert max(buffered) < BIG_BYTES // 16  # streamed: what waits for the client is far less than the file
    finally:
        for client in stalled:
            client.close()
    assert wait_for(lambda: not bridge.avatar.transfers)
    status, _, body = split(raw_request(bridge.port, get("/avatar.vrm")))
    assert status == 200 and len(body) == BIG_BYTES


def test_the_avatar_is_behind_the_ports_token_and_origin(vrm_file):
    bridge = WebSocketBridge(WebSocketConfig(port=0, avatar=vrm_file, token=TOKEN)).start()
    try:
        port = bridge.port
        answers = {
            "none": split(raw_request(port, get("/avatar.vrm")))[0],
            "wrong": split(raw_request(port, get("/avatar.vrm", "Authorization: Bearer not-the-token-at-all\r\n")))[0],
            "header": split(raw_request(port, get("/avatar.vrm", f"Authorization: Bearer {TOKEN}\r\n"))),
            "query": split(raw_request(port, get(f"/avatar.vrm?token={TOKEN}")))[0],
            "head": split(raw_request(port, get("/avatar.vrm", method="HEAD"))),
            "origin": split(raw_request(port, get(f"/avatar.vrm?token={TOKEN}", "Origin: https://evil.example\r\n")))[0],
        }
    finally:
        bridge.close()
    assert (answers["none"], answers["wrong"], answers["query"], answers["origin"]) == (401, 403, 200, 403)
    assert answers["header"][0] == 200 and answers["header"][2] == vrm_file.read_bytes()
    assert answers["head"][0] == 401 and answers["head"][2] == b""  # a refused HEAD has no body either


@pytest.fixture
def vrm_file(tmp_path) -> Path:
    path = tmp_path / "mine.vrm"
    path.write_bytes(b"glTF\x02\x00\x00\x00 the rest of a small avatar")
    return path


def test_closing_the_bridge_ends_a_stalled_download(big_avatar):
    bridge = WebSocketBridge(WebSocketConfig(port=0, avatar=big_avatar)).start()
    client = raw_request(bridge.port, get("/avatar.vrm"), read=False, receive_buffer=SMALL_RECEIVE_BUFFER)
    try:
        assert wait_for(lambda: len(bridge.avatar.transfers) == 1)
        bridge.close()  # returns (the download is dropped), instead of waiting for the client
        assert not bridge.avatar.transfers
    finally:
        client.close()


def test_an_avatar_server_only_takes_plain_requests_for_the_avatar():
    from websockets.datastructures import Headers
    from websockets.http11 import Request

    assert AvatarServer.handles(Request("/avatar.vrm?x=1", Headers()))
    assert not AvatarServer.handles(Request("/viewer.js", Headers()))
    assert not AvatarServer.handles(Request("/avatar.vrm", Headers([("Upgrade", "websocket")])))
