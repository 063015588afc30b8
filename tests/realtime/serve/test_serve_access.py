"""Protocol abuse against a running ``gesturecast serve`` (real server on a free loopback port, real clients):
bad control values, browser origins, tokens (wrong, weak, from env/file, non-ASCII), hostile JSON, limits."""

import asyncio
import json
import logging
import os
import re
import subprocess
import sys
from contextlib import contextmanager
from pathlib import Path

import pytest
from websockets.asyncio.client import connect
from websockets.exceptions import ConnectionClosed, InvalidStatus

from gesturecast.bridges.ws_access import MAX_TOKEN_FAILURES, TOKEN_ENV_VAR, TOKEN_FAILURE_WINDOW_S
from gesturecast.errors import UserError
from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.realtime.serve.server import GestureServer, ServeConfig
from gesturecast.realtime.serve.setup import StreamSessions
from gesturecast.realtime.timing.clock import FakeClock, MonotonicClock
from gesturecast.settings import Settings

TOKEN = "correct-horse-battery-staple"
UNICODE_TOKEN = "pässwörd-日本語-токен-✓"
DEFAULTS = Settings(steps=2, guidance=1.5, seed=0, audio_guidance=1.0, smoothing=0, gestures=None)  # L: δa, 100 ms
TIMEOUT_S = 60.0  # a broken server fails the test instead of hanging it
SECONDS = 1.0
CHUNK = 8000
CLI_START_TIMEOUT_S = 120.0


def run(coroutine):
    return asyncio.run(asyncio.wait_for(coroutine, TIMEOUT_S))


@pytest.fixture(scope="module")
def speech(shared_data):
    audio = load_audio(shared_data / "zeggs" / "067_Speech_2_x_1_0.wav")
    return audio[3 * SAMPLE_RATE :][: int(SECONDS * SAMPLE_RATE)]


@contextmanager
def serving(bundle, clock=None, max_streams: int = 4, **config):
    clock = clock or MonotonicClock()
    sessions = StreamSessions(DEFAULTS, bundle, clock, max_streams=max_streams)
    server = GestureServer(sessions, clock, ServeConfig(**{"port": 0, "max_streams": max_streams, **config})).start()
    try:
        yield server
    finally:
        server.close()


async def exchange(websocket, message) -> dict:
    await websocket.send(message)
    return json.loads(await websocket.recv())


async def close_code(websocket) -> int:
    """Read until the server closes; the close code it sent."""
    try:
        while True:
            await websocket.recv()
    except ConnectionClosed as closed:
        return closed.rcvd.code


BAD_CONTROLS = [
    ({"style": "hapy"}, "unknown style 'hapy'"),
    ({"style": "happy, sweeping gestures"}, "unknown style"),  # the viewer's placeholder, sent as a label
    ({"style2": "nope"}, "unknown style 'nope'"),
    ({"style": "text:  "}, "empty style prompt"),
    ({"guidance": 10**400}, "finite number"),  # an int beyond float range
    ({"part_styles": {"arms": "hapy"}}, "unknown style 'hapy'"),  # resolved before the ack, like "style"
]
LONE_SURROGATE = '{"type": "control", "prompt": "calm \\ud800"}'


def test_bad_control_values_are_refused_before_the_ack_and_the_stream_goes_on(bundle, speech):
    async def session(url):
        async with connect(f"{url}controls") as websocket:
            await websocket.recv()  # hello
            await exchange(websocket, json.dumps({"type": "start"}))
            replies = [await exchange(websocket, json.dumps({"type": "control", **c})) for c, _ in BAD_CONTROLS]
            replies.append(await exchange(websocket, LONE_SURROGATE))
            good = await exchange(websocket, json.dumps({"type": "control", "style": "old", "prompt": "calm"}))
            for start in range(0, len(speech), CHUNK):
                await websocket.send(speech[start : start + CHUNK].astype("<f4").tobytes())
            await websocket.send(json.dumps({"type": "end"}))
            messages = [m async for m in websocket]
            return replies, good, messages

    with serving(bundle) as server:
        replies, good, messages = run(session(server.url))
    expected = [reason for _, reason in BAD_CONTROLS] + ["lone surrogate"]
    for reply, reason in zip(replies, expected, strict=True):
        assert reply["type"] == "error" and reason in reply["message"], reply
    assert good == {"type": "ack", "applied": {"style": "old", "prompt": "calm"}}
    stats = json.loads(messages[-1])
    assert stats["type"] == "stats" and stats["error"] is None
    assert sum(isinstance(m, bytes) for m in messages) == int(SECONDS * 30)


def test_only_the_servers_own_and_allowed_browser_origins_may_connect(bundle):
    async def hello_type(url, origin):
        async with connect(url, origin=origin) as websocket:
            return json.loads(await websocket.recv())["type"]

    async def refused_status(url, origin):
        with pytest.raises(InvalidStatus) as refused:
            await hello_type(url, origin)
        return refused.value.response.status_code

    with serving(bundle, allow_origins=("http://localhost:3000",)) as server:
        port = server.port
        accepted = [run(hello_type(server.url, origin)) for origin in
                    (None, f"http://127.0.0.1:{port}", f"http://localhost:{port}", "http://localhost:3000")]
        refused = [run(refused_status(server.url, origin)) for origin in
                   ("https://evil.example", "http://localhost:3001", "null", f"http://evil.example:{port}")]
    assert accepted == ["hello"] * 4
    assert refused == [403] * 4


def test_a_wrong_token_closes_the_connection_and_the_address_is_rate_limited(bundle):
    clock = FakeClock()

    async def guess(url, token):
        async with connect(url) as websocket:
            await websocket.recv()  # hello
            reply = await exchange(websocket, json.dumps({"type": "start", "token": token}))
            return reply, await close_code(websocket)

    async def status_of_next_connection(url):
        with pytest.raises(InvalidStatus) as refused:
            await guess(url, TOKEN)
        return refused.value.response.status_code

    async def right(url):
        async with connect(url) as websocket:
            await websocket.recv()  # hello
            return await exchange(websocket, json.dumps({"type": "start", "token": TOKEN}))

    with serving(bundle, clock=clock, token=TOKEN) as server:
        guesses = [run(guess(server.url, f"guess-{i}")) for i in range(MAX_TOKEN_FAILURES)]
        blocked = run(status_of_next_connection(server.url))
        clock.advance(TOKEN_FAILURE_WINDOW_S)
        after_window = run(right(server.url))
    assert guesses == [({"type": "error", "message": "wrong token; closing the connection"}, 1008)] * MAX_TOKEN_FAILURES
    assert blocked == 429
    assert after_window["type"] == "started"


def test_missing_token_is_answered_and_the_connection_stays(bundle, speech):
    async def session(url):
        async with connect(url) as websocket:
            hello = json.loads(await websocket.recv())
            audio_first = await exchange(websocket, speech[:CHUNK].astype("<f4").tobytes())
            no_token = await exchange(websocket, json.dumps({"type": "start"}))
            started = await exchange(websocket, json.dumps({"type": "start", "token": UNICODE_TOKEN}))
            return hello, audio_first, no_token, started

    with serving(bundle, token=UNICODE_TOKEN) as server:
        hello, audio_first, no_token, started = run(session(server.url))
    assert hello["token_required"] is True
    assert audio_first["type"] == "error" and "token" in audio_first["message"]
    assert no_token["type"] == "error" and "needs a token" in no_token["message"]
    assert started["type"] == "started"  # a non-ASCII token works


@pytest.mark.parametrize("token", ["s3cret", "a" * 40, "abcabcabcabcabcabc"])
def test_weak_tokens_are_refused_at_startup(token):
    with pytest.raises(UserError, match="at least 16 characters"):
        GestureServer(None, MonotonicClock(), ServeConfig(port=0, token=token))


def serve_command(tiny_bundle: Path, *flags: str) -> list[str]:
    return [sys.executable, "-m", "gesturecast.cli", "serve", "--model", str(tiny_bundle), "--steps", "2",
            "--port", "0", *flags]


@pytest.mark.parametrize("source", ["env", "file"])
def test_cli_reads_the_token_from_the_environment_or_a_file(tiny_model, tmp_path, source):
    env = {key: value for key, value in os.environ.items() if key != TOKEN_ENV_VAR}
    flags = ()
    if source == "env":
        env[TOKEN_ENV_VAR] = UNICODE_TOKEN
    else:
        (tmp_path / "token").write_text(UNICODE_TOKEN + "\n", encoding="utf-8")
        flags = ("--token-file", str(tmp_path / "token"))

    async def starts(url):
        async with connect(f"{url}cli") as websocket:
            hello = json.loads(await websocket.recv())
            return hello["token_required"], await exchange(websocket, json.dumps({"type": "start",
                                                                                   "token": UNICODE_TOKEN}))

    process = subprocess.Popen(serve_command(tiny_model[1], *flags), env=env, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    try:
        url = wait_for_stream_url(process)
        required, started = run(starts(url))
    finally:
        process.terminate()
        process.communicate(timeout=TIMEOUT_S)
    assert required is True and started["type"] == "started"


def wait_for_stream_url(process: subprocess.Popen) -> str:
    """The ``ws://…/stream/`` URL the server prints once it listens."""
    for line in process.stdout:
        if match := re.search(r"(ws://\S+/stream/)<id>", line):
            return match.group(1)
    raise AssertionError(f"serve exited without listening: {process.stderr.read()}")


def test_cli_refuses_a_weak_token_in_one_line(tiny_model):
    result = subprocess.run(serve_command(tiny_model[1], "--token", "s3cret"), capture_output=True, text=True,
                            timeout=CLI_START_TIMEOUT_S)
    assert result.returncode == 2
    assert result.stderr.strip().splitlines() == [
        "gesturecast serve: error: the token is too weak: use at least 16 characters with at least 8 different "
        "ones (e.g. python3 -c 'import secrets; print(secrets.token_urlsafe(24))')"
    ]


HOSTILE_JSON = [
    ("[" * 30000 + "]" * 30000, "nested too deeply"),
    ('{"type": "control", "guidance": ' + "7" * 5000 + "}", "too many digits"),
    ('{"type": "start", "seed": ' + "1" * 5000 + "}", "too many digits"),
]


def test_hostile_json_gets_an_error_reply_not_a_1011(bundle, caplog):
    async def session(url):
        async with connect(f"{url}hostile") as websocket:
            await websocket.recv()  # hello
            replies = [await exchange(websocket, text) for text, _ in HOSTILE_JSON]
            started = await exchange(websocket, json.dumps({"type": "start"}))
            return replies, started

    with caplog.at_level(logging.DEBUG), serving(bundle) as server:
        replies, started = run(session(server.url))
    for reply, (_, reason) in zip(replies, HOSTILE_JSON, strict=True):
        assert reply["type"] == "error" and reason in reply["message"]
    assert started["type"] == "started"  # the connection is still open
    assert not [r for r in caplog.records if r.exc_info], "a traceback was logged"


def test_max_streams_refuses_at_connection_time_with_1013(bundle):
    async def crowd(url):
        async with connect(f"{url}a") as first, connect(f"{url}b") as second:
            hellos = [json.loads(await first.recv()), json.loads(await second.recv())]
            for websocket in (first, second):  # started streams hold the slots
                assert (await exchange(websocket, json.dumps({"type": "start"})))["type"] == "started"
            refusals = []
            for name in ("c", "d"):
                async with connect(f"{url}{name}") as extra:
                    refusals.append((json.loads(await extra.recv()), await close_code(extra)))
            return hellos, refusals

    with serving(bundle, max_streams=2) as server:
        hellos, refusals = run(crowd(server.url))
    assert [h["type"] for h in hellos] == ["hello", "hello"]
    assert refusals == [({"type": "error", "message": "server full (2 streams)"}, 1013)] * 2


def test_connections_that_never_start_hold_no_stream_slot_and_are_closed_after_the_start_timeout(bundle):
    """Idle connections (no start, no audio) neither keep a starting client out nor stay open for ever: they hold no
    --max-streams slot, the one that waited longest makes room when ``max_unstarted`` wait, and each is closed with
    a reason after the pre-start timeout."""
    async def crowd(url):
        idle = [await connect(f"{url}idle-{i}") for i in range(2)]
        hellos = [json.loads(await websocket.recv())["type"] for websocket in idle]
        async with connect(f"{url}worker") as worker:
            await worker.recv()  # hello: the oldest idle connection made room
            evicted = json.loads(await idle[0].recv()), await close_code(idle[0])
            started = await exchange(worker, json.dumps({"type": "start"}))
            async with connect(f"{url}late") as late:  # the one slot is the worker's now
                full = json.loads(await late.recv()), await close_code(late)
            timed_out = json.loads(await idle[1].recv()), await close_code(idle[1])
        return hellos, evicted, started, full, timed_out

    with serving(bundle, max_streams=1, start_timeout_s=2.0, max_unstarted=2) as server:
        hellos, evicted, started, full, timed_out = run(crowd(server.url))
    assert hellos == ["hello", "hello"]
    assert evicted[1] == 1013 and "waited longest" in evicted[0]["message"]
    assert started["type"] == "started"  # the idle connection left holds no --max-streams slot
    assert full == ({"type": "error", "message": "server full (1 streams)"}, 1013)
    assert timed_out == ({"type": "error", "message": "no start message or audio within 2 s"}, 1008)


def test_start_fields_of_another_json_type_get_an_error_reply_not_a_1011(bundle, caplog):
    bad_starts = [{"audio_format": []}, {"audio_format": {}}, {"latency": []}, {"latency": {"a": 1}}]

    async def session(url):
        async with connect(f"{url}typed") as websocket:
            await websocket.recv()  # hello
            replies = [await exchange(websocket, json.dumps({"type": "start", **bad})) for bad in bad_starts]
            started = await exchange(websocket, json.dumps({"type": "start", "latency": "low"}))
            return replies, started

    with caplog.at_level(logging.DEBUG), serving(bundle) as server:
        replies, started = run(session(server.url))
    assert [r["message"] for r in replies] == [
        "audio_format must be one of f32le, s16le, got a JSON array",
        "audio_format must be one of f32le, s16le, got a JSON object",
        "latency must be one of low, balanced, quality, got a JSON array",
        "latency must be one of low, balanced, quality, got a JSON object",
    ]
    assert started["type"] == "started"  # the connection is still open
    assert not [r for r in caplog.records if r.exc_info], "a traceback was logged"


def test_a_duplicate_stream_id_gets_an_error_then_a_close(bundle):
    async def twice(url):
        async with connect(f"{url}same") as first:
            await first.recv()  # hello
            async with connect(f"{url}same") as second:
                return json.loads(await second.recv()), await close_code(second)

    with serving(bundle) as server:
        reply, code = run(twice(server.url))
    assert reply == {"type": "error", "message": "stream id 'same' is in use"}
    assert code == 1008

