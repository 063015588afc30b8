"""gesturecast serve: batched streams equal solo runs, disconnects are isolated, token rules, bad input replies."""

import asyncio
import json
import threading
from contextlib import contextmanager

import numpy as np
import pytest
from websockets.asyncio.client import connect

from gesturecast.errors import UserError
from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.models.generator.diffusion import SamplerConfig
from gesturecast.models.generator.style_prompt import StylePrompt, parse_part_styles
from gesturecast.models.motion.root_anchor import RootMode
from gesturecast.realtime.audio.sources import AudioChunk
from gesturecast.realtime.generation.generator import Generator, GeneratorSettings
from gesturecast.realtime.pose.session import GestureSession, SessionConfig
from gesturecast.realtime.pose.style_hearing import StyleState
from gesturecast.realtime.run.engine_setup import style_hearing
from gesturecast.realtime.serve.server import GestureServer, ServeConfig
from gesturecast.realtime.serve.setup import StreamSessions
from gesturecast.realtime.timing.clock import FakeClock, MonotonicClock
from gesturecast.realtime.timing.latency import LatencyBudget
from gesturecast.settings import LATENCY_SETTINGS, Settings
from gesturecast.tools.bench.serve_client import stream_audio

SECONDS = 2.0
CHUNK = 8000  # 0.5 s per message: few messages, sent as fast as possible
DEFAULTS = Settings(steps=2, guidance=1.5, seed=0, audio_guidance=1.0, smoothing=0, gestures=None)  # L: δa, 100 ms
TIMEOUT_S = 60.0  # a broken server fails the test instead of hanging it


def run(coroutine):
    return asyncio.run(asyncio.wait_for(coroutine, TIMEOUT_S))


@pytest.fixture(scope="module")
def speech(shared_data):
    audio = load_audio(shared_data / "zeggs" / "067_Speech_2_x_1_0.wav")
    return [audio[(3 + 5 * i) * SAMPLE_RATE :][: int(SECONDS * SAMPLE_RATE)] for i in range(3)]


def budget(bundle) -> LatencyBudget:
    return LatencyBudget(bundle.frames_per_latent, bundle.audio_lookahead, 100.0)


@contextmanager
def running_server(bundle, **config):
    clock = MonotonicClock()
    sessions = StreamSessions(DEFAULTS, bundle, clock, max_streams=4)
    server = GestureServer(sessions, clock, ServeConfig(port=0, max_streams=4, **config)).start()
    try:
        yield server
    finally:
        server.close()


def solo_poses(bundle, audio, style="neutral", guidance=1.5, seed=0, root="bounded", latency=None,
               part_styles=None) -> np.ndarray:
    """The same stream through one session alone, as the float32 the wire carries."""
    lookahead = None if latency is None else LATENCY_SETTINGS[latency].lookahead_for(bundle.audio_lookahead)
    # as every door's sessions: the stylizer styles, the generator hears what the default hearing makes of it
    hearing = style_hearing(DEFAULTS, bundle)
    state = StyleState(StylePrompt("label", style), part_styles=parse_part_styles(part_styles or {}))
    heard = hearing.heard(state)
    settings = GeneratorSettings(SamplerConfig("ddim", 2), guidance, heard.style, seed=seed, lookahead=lookahead,
                                 part_styles=heard.part_styles, style_strength=heard.strength)
    session = GestureSession(bundle, Generator(bundle, settings), budget(bundle), FakeClock(),
                             SessionConfig(root_mode=RootMode(root), style=state, hearing=hearing))
    frames = session.push(AudioChunk(audio, 0, 0.0)) + session.finish()
    return np.stack([np.concatenate([f.rotations.ravel(), f.root_position]) for f in frames]).astype(np.float32)


def test_concurrent_streams_equal_each_stream_served_alone(bundle, speech):
    starts = [{"seed": 1, "latency": "low", "part_styles": {"arms": "happy"}},
              {"seed": 2, "style": "old", "root": "free"},
              {"seed": 3, "guidance": 1.0, "root": "locked", "latency": "balanced"}]

    async def clients(url):
        return await asyncio.gather(*[stream_audio(f"{url}s{i}", audio, CHUNK, paced=False, start=start)
                                      for i, (audio, start) in enumerate(zip(speech, starts, strict=True))])

    with running_server(bundle) as server:
        results = run(clients(server.url))
        calls = server.sessions.batcher.stats.calls
    assert calls > 0
    for result, audio, start in zip(results, speech, starts, strict=True):
        assert result.errors == [] and result.stats["error"] is None
        assert result.stats["late_releases"] >= 0  # reported (its value depends on the machine's load)
        assert [result.stats[name] for name in ("outbox_drops", "slow_client_skips", "nonfinite_poses")] == [0, 0, 0]
        assert result.hello["stream"] == result.stats["stream"]
        assert result.hello["body_parts"] == ["arms", "torso", "legs"]
        np.testing.assert_array_equal(result.poses(), solo_poses(bundle, audio, **start))
        assert [f.seq for f in result.frames] == list(range(len(result.frames)))
    budgets = [next(m for m in result.messages if m["type"] == "started")["latency_budget_ms"] for result in results]
    assert budgets[0] < budgets[2] < budgets[1] == pytest.approx(results[1].hello["latency_budget_ms"])


def test_a_client_leaving_mid_stream_does_not_disturb_another(bundle, speech, wait_until):
    async def leaver(url):
        async with connect(f"{url}leaver") as websocket:
            await websocket.recv()  # hello
            await websocket.send(speech[1][:CHUNK].astype("<f4").tobytes())
            await websocket.send(speech[1][CHUNK : 2 * CHUNK].astype("<f4").tobytes())
        # closed without "end": the server must free the stream

    async def both(url):
        return await asyncio.gather(stream_audio(f"{url}stayer", speech[0], CHUNK, paced=False), leaver(url))

    with running_server(bundle) as server:
        stayer, _ = run(both(server.url))
        # the server notices the leaver's dropped connection on its own thread, maybe after the clients return
        assert wait_until(lambda: server.active_streams() == 0)
        finished = {s["stream"]: s for s in server.finished}
    np.testing.assert_array_equal(stayer.poses(), solo_poses(bundle, speech[0]))
    assert set(finished) == {"stayer", "leaver"}
    assert finished["leaver"]["audio_seconds"] <= 2 * CHUNK / SAMPLE_RATE


async def exchange(websocket, message) -> dict:
    await websocket.send(message)
    return json.loads(await websocket.recv())


TOKEN = "correct-horse-battery-staple"  # wrong, weak and non-ASCII tokens: test_serve_access.py


def test_token_is_required_when_set_and_exposure_needs_one(bundle, speech):
    with pytest.raises(UserError, match="token"):
        GestureServer(None, MonotonicClock(), ServeConfig(host="0.0.0.0", port=0))

    async def session(url):
        async with connect(f"{url}guarded") as websocket:
            hello = json.loads(await websocket.recv())
            audio_first = await exchange(websocket, speech[0][:CHUNK].astype("<f4").tobytes())
            right = await exchange(websocket, json.dumps({"type": "start", "token": TOKEN}))
            return hello, audio_first, right

    with running_server(bundle, token=TOKEN) as server:
        hello, audio_first, right = run(session(server.url))
    assert hello["token_required"] is True
    assert audio_first["type"] == "error" and "token" in audio_first["message"]
    assert right["type"] == "started" and right["stream"] == "guarded"


BAD_MESSAGES = [
    (np.zeros(3, np.uint8).tobytes(), "multiple of 4 bytes"),
    (np.array([0.1, np.nan], "<f4").tobytes(), "NaN"),
    ("not json", "not JSON"),
    (json.dumps({"type": "dance"}), "unknown message type"),
    (json.dumps({"type": "control", "style": "motion:/etc/passwd"}), "motion prompts"),
    (json.dumps({"type": "control", "guidance": "loud"}), "finite number"),
    (json.dumps({"type": "start"}), "already started"),
    (json.dumps({"type": "control", "part_styles": {"tail": "happy"}}), "unknown body part 'tail'"),
    (json.dumps({"type": "control", "part_styles": "happy"}), "must be an object"),
    (json.dumps({"type": "words", "words": [{"word": "hi", "start": -1}]}), "words[0].start must be within"),
    (json.dumps({"type": "words", "words": [{"word": "hello", "start": 1.0}]}), "no gesture lexicon"),  # none here
]


def test_bad_messages_get_a_one_line_error_and_the_stream_goes_on(bundle, speech):
    async def session(url):
        async with connect(f"{url}messy") as websocket:
            await websocket.recv()  # hello
            started = await exchange(websocket, json.dumps({"type": "start", "style": "old"}))
            replies = [await exchange(websocket, message) for message, _ in BAD_MESSAGES]
            for start in range(0, len(speech[0]), CHUNK):
                await websocket.send(speech[0][start : start + CHUNK].astype("<f4").tobytes())
            await websocket.send(json.dumps({"type": "end"}))
            frames = [m async for m in websocket if isinstance(m, bytes)]
            return started, replies, frames

    async def unknown_path(url):
        async with connect(url.replace("/stream/", "/elsewhere")) as websocket:
            return json.loads(await websocket.recv())

    with running_server(bundle) as server:
        started, replies, frames = run(session(server.url))
        refused = run(unknown_path(server.url))
    assert started["type"] == "started" and started["style"] == "old"
    for reply, (_, expected) in zip(replies, BAD_MESSAGES, strict=True):
        assert reply["type"] == "error" and expected in reply["message"] and "\n" not in reply["message"]
    assert len(frames) == int(SECONDS * 30)
    assert refused["type"] == "error" and "unknown path" in refused["message"]


def test_closed_streams_leave_nothing_behind(bundle, speech, wait_until):
    """Start and close streams one after another: no stream object, session or thread outlives its stream
    (a guard for `serve`'s memory under churn; see also `gesturecast bench serve --churn`)."""
    import gc
    import weakref

    from gesturecast.realtime.serve.stream import ServeStream

    async def one_after_another(url, first, count):
        for i in range(first, first + count):
            result = await stream_audio(f"{url}churn-{i}", speech[0][: SAMPLE_RATE // 2], CHUNK, paced=False)
            assert result.errors == []

    with running_server(bundle) as server:
        run(one_after_another(server.url, 0, 1))  # warm-up: the event loop's worker threads start
        assert wait_until(lambda: server.active_streams() == 0)
        run(one_after_another(server.url, 1, 5))
        assert wait_until(lambda: server.active_streams() == 0)
        streams = [weakref.ref(o) for o in gc.get_objects() if type(o) is ServeStream]
        assert wait_until(lambda: gc.collect() >= 0 and all(ref() is None for ref in streams))
        assert wait_until(lambda: not stream_threads()), stream_threads()  # the event loop's pool may grow


def stream_threads() -> list[str]:
    """Names of live per-stream threads (session worker, frame releaser)."""
    return [t.name for t in threading.enumerate() if t.name.startswith(("stream-", "frame-scheduler"))]
