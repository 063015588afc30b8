"""A robot loop on the paced form of ``gesturecast.Stream``: each pose is applied when ``stream.frames()`` hands it
over, at its presentation time; prints JSON of how far from that time each pose arrived (``time.monotonic``), and,
for comparison, when ``push`` returned the same poses (before they are due: not paced).

    python examples/paced_robot.py SPEECH.wav

A thread pushes the file in 0.1 s blocks at real-time pace, as a microphone would deliver them, then closes the
stream; the main thread applies the poses.
"""

from __future__ import annotations

import json
import sys
import threading
import time

import numpy as np
import soundfile

import gesturecast

BLOCK_S = 0.1


def feed(stream: gesturecast.Stream, samples: np.ndarray, rate: int, returned: list[float]) -> None:
    """Push the audio as it would be heard, then close the stream (which ends ``stream.frames()``); ``returned``
    gets, for each pose ``push`` returns, the seconds from its presentation time to then."""
    block = int(BLOCK_S * rate)
    start = time.monotonic()
    for index in range(0, len(samples), block):
        time.sleep(max(0.0, start + index / rate - time.monotonic()))
        poses = stream.push(samples[index : index + block], sample_rate=rate)
        returned += [time.monotonic() - pose.presentation_time for pose in poses]
    stream.close()


def summary(seconds: list[float]) -> dict:
    """Milliseconds after the presentation time (negative: early): median, 95th percentile, extremes."""
    ms = np.array(seconds) * 1000.0
    return {"poses": len(ms), "early": int((ms < 0).sum()), "p50": round(float(np.percentile(ms, 50)), 2),
            "p95": round(float(np.percentile(ms, 95)), 2), "min": round(float(ms.min()), 2),
            "max": round(float(ms.max()), 2)}


def main(path: str) -> dict:
    samples, rate = soundfile.read(path, dtype="float32")
    arrivals, returned = [], []  # seconds after its presentation time that each pose arrived (negative: early)
    with gesturecast.Stream(gesturecast.Settings(latency="low")) as stream:
        frames = stream.frames()  # opened before any audio: sees every frame
        pusher = threading.Thread(target=feed, args=(stream, samples, rate, returned))
        pusher.start()
        for frame in frames:  # a robot would move its joints to frame.rotations here
            arrivals.append(time.monotonic() - frame.presentation_time)
        pusher.join()
    return {"latency_ms": round(stream.latency_ms, 1), "frames_ms_after_due": summary(arrivals),
            "push_returned_ms_after_due": summary(returned)}


if __name__ == "__main__":
    print(json.dumps(main(sys.argv[1])))
