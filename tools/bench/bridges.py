"""Benchmark: bytes per frame and per-frame send cost of each bridge (prints JSON).

VMC and plain OSC encode + send over UDP to a bound loopback socket; the WebSocket stream
reports binary and JSON frame sizes, their encode cost, the engine-side ``send()`` cost and the
one-way delay to a connected client.

    python -m gesturecast.tools.bench.bridges --frames 600
    gesturecast bench bridges --json
"""

from __future__ import annotations

import argparse
import json
import socket
import sys
import time

import numpy as np
from websockets.sync.client import connect

from gesturecast.bridges.coords import INTERNAL
from gesturecast.bridges.osc import OscBridge, OscConfig
from gesturecast.bridges.vmc import VmcBridge, VmcConfig
from gesturecast.bridges.websocket_server import WebSocketBridge, WebSocketConfig
from gesturecast.bridges.ws_protocol import binary_frame, json_frame
from gesturecast.frames import PoseFrame
from gesturecast.models.motion.rotations import quat_from_axis_angle
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS

FPS = 60.0  # send every frame through the 60 fps limiter
RECV_TIMEOUT_S = 5.0
NS_PER_US = 1000.0
MOTION_SCALE_RAD = 0.5
SKELETON = CANONICAL_WITH_HANDS  # what the session sends: 22 body joints + 30 finger joints


def synthetic_frames(count: int, seed: int = 0) -> list[PoseFrame]:
    rng = np.random.default_rng(seed)
    axis_angles = MOTION_SCALE_RAD * rng.normal(size=(count, SKELETON.num_joints, 3))  # (T, J, 3)
    rotations = quat_from_axis_angle(axis_angles)  # (T, J, 4)
    now = time.monotonic()
    return [
        PoseFrame(i, now + i / FPS, now + i / FPS, SKELETON.offsets[0] + 0.01 * rng.normal(size=3), rotations[i])
        for i in range(count)
    ]


def median_us(samples_ns: list[int]) -> float:
    return round(float(np.median(samples_ns)) / NS_PER_US, 2)


def bench_udp(bridge, frames: list[PoseFrame]) -> dict:
    encode_ns, send_ns, sizes = [], [], []
    for frame in frames:
        start = time.perf_counter_ns()
        datagrams = bridge.encoder.encode(frame, 0.0)
        encode_ns.append(time.perf_counter_ns() - start)
        sizes.append([len(d) for d in datagrams])
        start = time.perf_counter_ns()
        bridge.send(frame)
        send_ns.append(time.perf_counter_ns() - start)
    bridge.close()
    return {
        "bytes_per_frame": sum(sizes[0]),
        "datagrams_per_frame": len(sizes[0]),
        "largest_datagram": max(max(s) for s in sizes),
        "encode_us_median": median_us(encode_ns),
        "encode_and_send_us_median": median_us(send_ns),
    }


def bench_websocket(frames: list[PoseFrame]) -> dict:
    encoders = (("binary", binary_frame), ("json", json_frame))
    encode = {"binary": [], "json": []}
    for frame in frames:
        for name, encoder in encoders:
            start = time.perf_counter_ns()
            payload = encoder(frame, INTERNAL, frame.capture_time, frame.capture_time)
            encode[name].append(time.perf_counter_ns() - start)
    sizes = {name: len(encoder(frames[0], INTERNAL, 0.0, 0.0)) for name, encoder in encoders}
    bridge = WebSocketBridge(WebSocketConfig(port=0)).start()
    send_ns, delivery_ns = [], []
    with connect(f"ws://127.0.0.1:{bridge.port}/") as client:
        client.recv(RECV_TIMEOUT_S)  # hello
        while bridge.client_count() == 0:
            time.sleep(0.01)
        for frame in frames:
            start = time.perf_counter_ns()
            bridge.send(frame)
            send_ns.append(time.perf_counter_ns() - start)
            payload = client.recv(RECV_TIMEOUT_S)
            delivery_ns.append(time.perf_counter_ns() - start)
    bridge.close()
    return {
        "binary_bytes_per_frame": sizes["binary"],
        "json_bytes_per_frame": sizes["json"],
        "binary_encode_us_median": median_us(encode["binary"]),
        "json_encode_us_median": median_us(encode["json"]),
        "engine_send_call_us_median": median_us(send_ns),
        "one_way_delivery_us_median": median_us(delivery_ns),
        "last_payload_bytes": len(payload),
    }


def run(args: argparse.Namespace) -> int:
    frames = synthetic_frames(args.frames)
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sink:
        sink.bind(("127.0.0.1", 0))
        port = sink.getsockname()[1]
        result = {
            "frames": args.frames,
            "joints": SKELETON.num_joints,
            "vmc": bench_udp(VmcBridge(VmcConfig(port=port, send_rate=FPS)), frames),
            "osc": bench_udp(OscBridge(OscConfig(port=port, send_rate=FPS)), frames),
        }
    result["websocket"] = bench_websocket(frames)
    sys.stdout.write(json.dumps(result, indent=None if args.json else 2) + "\n")
    return 0


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--frames", type=int, default=600, help="frames to send per bridge")
    parser.add_argument("--json", action="store_true", help="one-line JSON")
    parser.set_defaults(func=run)


def register_bench(bench_subparsers: argparse._SubParsersAction) -> None:
    add_arguments(bench_subparsers.add_parser("bridges", help="bytes per frame and send cost per bridge"))


if __name__ == "__main__":
    main_parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_arguments(main_parser)
    sys.exit(run(main_parser.parse_args()))
