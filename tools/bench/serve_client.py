"""A ``gesturecast serve`` client: streams audio over one WebSocket and collects the pose frames.

Used by ``gesturecast bench serve`` (many of them at once, at real-time pace) and by the tests; a flooding
client (``flood_words``) also sends ``words`` control messages back to back while it streams. The
client measures its own end-to-end latency per frame: receive time minus the time the frame's first
audio sample was "captured" on the client (``t0 + seq / fps`` for audio sent at real-time pace).
"""

from __future__ import annotations

import asyncio
import json
import time
from dataclasses import dataclass, field

import numpy as np
from websockets.asyncio.client import ClientConnection, connect

from gesturecast.bridges.ws_protocol import BINARY_HEADER, FRAME_MAGIC
from gesturecast.models.audio.files import SAMPLE_RATE

QUATERNION = 4
FLOOD_WORDS = ("hello", "thank", "you", "so", "much", "goodbye", "look", "at", "this", "hooray")
FLOOD_WORD_S = 0.3  # stream seconds per flooded word


@dataclass(frozen=True)
class ReceivedFrame:
    seq: int
    received: float  # client monotonic time
    root: np.ndarray  # (3,) float32
    rotations: np.ndarray  # (J, 4) float32


@dataclass
class ClientResult:
    hello: dict
    frames: list[ReceivedFrame] = field(default_factory=list)
    messages: list[dict] = field(default_factory=list)  # every JSON message after the hello
    stats: dict | None = None
    origin: float = 0.0  # client time of audio sample 0

    flood_sent: int = 0  # words messages sent by a flooding client

    @property
    def errors(self) -> list[str]:
        return [m["message"] for m in self.messages if m.get("type") == "error"]

    def poses(self) -> np.ndarray:
        """(T, J*4 + 3) float32: rotations then root, as sent."""
        return np.stack([np.concatenate([f.rotations.ravel(), f.root]) for f in self.frames])

    def latencies_s(self) -> np.ndarray:
        """Client-side end-to-end latency per frame: receipt − capture of its first audio sample (seq counts
        frames at the stream's output rate, 30 or 60 fps, as the hello says)."""
        fps = float(self.hello["fps"])
        return np.array([f.received - (self.origin + f.seq / fps) for f in self.frames])


def parse_frame(data: bytes, received: float) -> ReceivedFrame:
    magic, seq, _capture, _send, x, y, z, joints, _flags = BINARY_HEADER.unpack_from(data)
    if magic != FRAME_MAGIC:
        raise ValueError(f"not a pose frame (magic {magic!r})")
    rotations = np.frombuffer(data, "<f4", joints * QUATERNION, BINARY_HEADER.size).reshape(joints, QUATERNION)
    return ReceivedFrame(seq, received, np.array([x, y, z], np.float32), rotations)


async def _receive(websocket: ClientConnection, result: ClientResult) -> None:
    async for message in websocket:
        if isinstance(message, bytes):
            result.frames.append(parse_frame(message, time.monotonic()))
            continue
        decoded = json.loads(message)
        result.messages.append(decoded)
        if decoded.get("type") == "stats":
            result.stats = decoded


async def _send_audio(websocket: ClientConnection, audio: np.ndarray, chunk: int, paced: bool,
                      result: ClientResult) -> None:
    result.origin = time.monotonic()
    for start in range(0, len(audio), chunk):
        block = audio[start : start + chunk]
        if paced:  # a chunk leaves when its last sample would have been recorded
            await asyncio.sleep(max(0.0, result.origin + (start + len(block)) / SAMPLE_RATE - time.monotonic()))
        await websocket.send(np.ascontiguousarray(block, "<f4").tobytes())


def words_message(count: int, start_s: float) -> str:
    """A ``words`` control message of ``count`` words timed from ``start_s`` stream seconds on."""
    words = [{"word": FLOOD_WORDS[i % len(FLOOD_WORDS)], "start": start_s + i * FLOOD_WORD_S,
              "end": start_s + (i + 1) * FLOOD_WORD_S} for i in range(count)]
    return json.dumps({"type": "words", "words": words})


async def flood_words(websocket: ClientConnection, result: ClientResult, words_per_message: int) -> None:
    """Send ``words`` messages as fast as the socket takes them until cancelled (each waits only for the send)."""
    while True:
        elapsed = time.monotonic() - result.origin
        await websocket.send(words_message(words_per_message, elapsed))
        result.flood_sent += 1
        await asyncio.sleep(0)  # let the audio sender and the receiver run between messages


async def stream_audio(url: str, audio: np.ndarray, chunk_samples: int = 512, paced: bool = True,
                       start: dict | None = None, flood_words_per_message: int = 0) -> ClientResult:
    """Connect, optionally send ``start`` fields, stream float32 audio (flooding ``words`` messages of
    ``flood_words_per_message`` words meanwhile, when not 0), send end, collect until close."""
    async with connect(url, max_size=None) as websocket:
        result = ClientResult(hello=json.loads(await websocket.recv()))
        if start is not None or flood_words_per_message:  # a flooder starts its stream before its first words
            await websocket.send(json.dumps({"type": "start", **(start or {})}))
        receiver = asyncio.create_task(_receive(websocket, result))
        flooder = (asyncio.create_task(flood_words(websocket, result, flood_words_per_message))
                   if flood_words_per_message else None)
        await _send_audio(websocket, audio, chunk_samples, paced, result)
        if flooder is not None:
            flooder.cancel()
        await websocket.send(json.dumps({"type": "end"}))
        await receiver
    return result
