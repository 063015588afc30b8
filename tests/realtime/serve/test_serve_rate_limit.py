"""gesturecast serve: a connection over its control-message rate gets an error, its stream goes on, and the stats
count the refusals."""

import asyncio
import json

from websockets.asyncio.client import connect

from gesturecast.message_rate import RateLimits
from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.realtime.serve.server import GestureServer, ServeConfig
from gesturecast.realtime.serve.setup import StreamSessions
from gesturecast.realtime.timing.clock import MonotonicClock
from gesturecast.settings import Settings

SECONDS = 2.0
CHUNK = 8000
DEFAULTS = Settings(steps=2, guidance=1.5, seed=0, audio_guidance=1.0, smoothing=0, gestures=None)
LIMITS = RateLimits(messages_per_s=0.001, message_burst=2)  # two now, the next in about 17 minutes
TIMEOUT_S = 60.0


async def limited_client(url: str, audio) -> tuple[list[dict], list[bytes], dict]:
    async with connect(f"{url}flooder") as websocket:
        await websocket.recv()  # hello
        await websocket.send(json.dumps({"type": "start"}))
        await websocket.recv()  # started
        replies = []
        for _ in range(4):
            await websocket.send(json.dumps({"type": "control", "guidance": 2.0}))
            replies.append(json.loads(await websocket.recv()))
        for start in range(0, len(audio), CHUNK):
            await websocket.send(audio[start : start + CHUNK].astype("<f4").tobytes())
        await websocket.send(json.dumps({"type": "end"}))
        messages = [message async for message in websocket]
    frames = [message for message in messages if isinstance(message, bytes)]
    stats = next(json.loads(m) for m in messages if isinstance(m, str) and json.loads(m)["type"] == "stats")
    return replies, frames, stats


def test_a_connection_over_its_rate_is_refused_and_its_stream_goes_on(bundle, shared_data):
    audio = load_audio(shared_data / "zeggs" / "067_Speech_2_x_1_0.wav")[: int(SECONDS * SAMPLE_RATE)]
    clock = MonotonicClock()
    sessions = StreamSessions(DEFAULTS, bundle, clock, max_streams=2)
    server = GestureServer(sessions, clock, ServeConfig(port=0, max_streams=2, rate_limits=LIMITS)).start()
    try:
        replies, frames, stats = asyncio.run(asyncio.wait_for(limited_client(server.url, audio), TIMEOUT_S))
    finally:
        server.close()
    assert [reply["type"] for reply in replies] == ["ack", "ack", "error", "error"]
    assert "rate limit" in replies[2]["message"] and "the stream goes on" in replies[2]["message"]
    assert len(frames) == int(SECONDS * 30)
    assert stats["rate_limited_messages"] == 2
