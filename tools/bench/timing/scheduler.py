"""Benchmark: how punctually the scheduler worker releases frames on the real clock (prints JSON).

A simulated generator submits d frames per latent step as soon as the audio for them (plus δa look-ahead)
would have arrived, each with presentation_time = capture_time + L; a :class:`SchedulerWorker` releases
them to a no-op sink. Reports release lateness percentiles (OS wake-up jitter on this machine), deadline
misses and the worker's CPU use.

    python -m gesturecast.tools.bench.timing.scheduler --seconds 10 --output-fps 60
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time

import numpy as np

from gesturecast.frames import PoseFrame
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS
from gesturecast.realtime.timing.clock import MonotonicClock
from gesturecast.realtime.timing.latency import LatencyBudget, LatencyStats
from gesturecast.realtime.timing.scheduler import FrameScheduler, SchedulerConfig, SchedulerWorker

STOP_TIMEOUT_S = 2.0
DRAIN_S = 0.05  # wait past the last presentation time before stopping the worker


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=10.0, help="stream duration")
    parser.add_argument("--latent-frames", type=int, default=4, help="d: motion frames per generator step")
    parser.add_argument("--lookahead", type=int, default=8, help="δa: look-ahead frames")
    parser.add_argument("--margin-ms", type=float, default=100.0, help="compute margin in L")
    parser.add_argument("--compute-ms", type=float, default=20.0, help="simulated generator time per step")
    parser.add_argument("--output-fps", type=float, default=30.0, choices=(30.0, 60.0))
    return parser.parse_args(argv)


def simulate(args: argparse.Namespace) -> dict:
    clock = MonotonicClock()
    budget = LatencyBudget(args.latent_frames, args.lookahead, args.margin_ms)
    stats = LatencyStats(clock)
    scheduler = FrameScheduler(clock, lambda frame: None, SchedulerConfig(output_fps=args.output_fps), stats)
    worker = SchedulerWorker(scheduler)
    rest = np.tile([0.0, 0.0, 0.0, 1.0], (CANONICAL_WITH_HANDS.num_joints, 1))  # (J, 4)
    d, frame_s = args.latent_frames, 1.0 / budget.fps
    cpu_start = time.process_time()  # user + system CPU of the whole process (every platform)
    start = clock.now()
    worker.start()
    for step in range(int(args.seconds * budget.fps) // d):
        audio_ready = start + (step * d + d + args.lookahead) * frame_s
        clock.sleep_until(audio_ready + args.compute_ms / 1000.0)
        for k in range(step * d, step * d + d):
            capture = start + k * frame_s
            scheduler.submit(PoseFrame(k, capture, capture + budget.total_s, CANONICAL_WITH_HANDS.offsets[0], rest))
    last_presentation = start + (step * d + d - 1) * frame_s + budget.total_s
    clock.sleep_until(last_presentation + DRAIN_S)
    worker.stop(STOP_TIMEOUT_S)
    cpu = time.process_time() - cpu_start
    wall = clock.now() - start
    return {
        "latency_budget_ms": budget.total_ms,
        "settings": {**budget.to_dict(), "compute_ms": args.compute_ms, "output_fps": args.output_fps},
        "scheduler": scheduler.stats.to_dict(),
        "release_lateness_ms": stats.stage_summary("release_lateness"),
        "end_to_end_ms": stats.stage_summary("end_to_end"),
        "process_cpu_fraction": cpu / wall,
        "machine": f"{platform.system()} {platform.machine()}, {os.cpu_count()} CPUs",
    }


def main(argv: list[str] | None = None) -> int:
    print(json.dumps(simulate(parse_args(argv)), indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
