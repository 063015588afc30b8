"""``gesturecast bench pipecat``: does a voice agent's avatar gesture on the words it means, whichever way its TTS
service reports the text?

A voice agent's replies (:mod:`gesturecast.tools.bench.gesture_set.texts_agent`, 24 intended cues) are spoken by
espeak-ng and pushed through ``Pipeline([GesturecastProcessor, recorder])`` at a service's pace
(:mod:`gesturecast.tools.bench.agents.tts_feed`), with the text after each sentence's audio, before it, or a word
frame with each word's audio (``--orders``). The stream runs at the product's defaults (``Settings()``) and is paced
as in an agent: a pose is released L after its audio arrived.

**Per intended cue**: the gesture the stream cued near the word (the cue plan's outcome), whether it plays, and its
stroke − word time; *hit* = the intended gesture plays with its stroke within :data:`STROKE_TOLERANCE_S` of the word.
**Also**: cues played where none was intended, and how long the processor held the voice back (each audio frame's
wall time from being queued to leaving the processor, p50/p95/max ms).
"""

from __future__ import annotations

import argparse
import asyncio
import json
import sys
from pathlib import Path

import numpy as np
from loguru import logger
from pipecat.frames.frames import EndFrame, Frame, OutputAudioRawFrame
from pipecat.pipeline.pipeline import Pipeline
from pipecat.pipeline.worker import PipelineWorker
from pipecat.processors.frame_processor import FrameDirection, FrameProcessor
from pipecat.workers.runner import WorkerRunner

from gesturecast.files import write_text_atomic
from gesturecast.realtime.agents.pipecat_processor import GesturecastProcessor
from gesturecast.realtime.agents.sentence_hold import MAX_SENTENCE_HOLD_S
from gesturecast.realtime.cli_flags import add_generation_arguments, settings_from_args
from gesturecast.realtime.gestures.cues import CueOutcome
from gesturecast.realtime.run.stream import Stream
from gesturecast.settings import Settings
from gesturecast.tools.bench.agents.tts_feed import ORDERS, IntendedCue, feed_replies, speak_replies
from gesturecast.tools.bench.gesture_set.stories import CACHE
from gesturecast.tools.bench.gesture_set.texts_agent import AGENT_REPLIES
from gesturecast.tools.bench.gesture_set.word_modes import HELD_OUT_VOICES

STROKE_TOLERANCE_S = 0.5
MATCH_BEFORE_S, MATCH_AFTER_S = 1.5, 2.5  # an outcome of the intended gesture whose cue falls here is the word's
START_TIMEOUT_S = 60.0


class VoiceClock(FrameProcessor):
    """The stage after the processor: the loop time each audio frame reached it."""

    def __init__(self) -> None:
        super().__init__()
        self.passed_at: dict[int, float] = {}

    async def process_frame(self, frame: Frame, direction: FrameDirection) -> None:
        await super().process_frame(frame, direction)
        if isinstance(frame, OutputAudioRawFrame):
            self.passed_at[frame.id] = asyncio.get_running_loop().time()
        await self.push_frame(frame, direction)


def register_bench(bench_subparsers: argparse._SubParsersAction) -> None:
    parser = bench_subparsers.add_parser("pipecat", help="a voice agent's gestures on their words, text after, "
                                         "before or with its audio (Pipecat; JSON)")
    add_generation_arguments(parser)
    parser.add_argument("--orders", default=",".join(ORDERS), help=f"comma-separated, of {', '.join(ORDERS)}")
    parser.add_argument("--hold-s", type=float, default=0.0, help="the processor's hold_s (word frames)")
    parser.add_argument("--sentence-hold-s", type=float, default=MAX_SENTENCE_HOLD_S,
                        help="the processor's sentence_hold_s (0: sentences are not held)")
    parser.add_argument("--voice", default=None, help="the espeak-ng voice (default: its default; held out: "
                        f"{', '.join(HELD_OUT_VOICES)})")
    parser.add_argument("--json", action="store_true", help="print the whole JSON result")
    parser.add_argument("--out", type=Path, default=Path("out/bench/pipecat"), help="folder for the JSON")
    parser.set_defaults(func=run)


async def run_agent(processor: GesturecastProcessor, replies, order: str) -> dict:
    """The replies through ``Pipeline([processor, clock])``; the voice's hold (ms) per audio frame."""
    clock = VoiceClock()
    worker = PipelineWorker(Pipeline([processor, clock]), cancel_on_idle_timeout=False, enable_rtvi=False)
    started, queued_at = asyncio.Event(), {}

    @worker.event_handler("on_pipeline_started")
    async def on_started(_worker, _frame):
        started.set()

    async def feed() -> None:
        await asyncio.wait_for(started.wait(), START_TIMEOUT_S)
        await feed_replies(worker.queue_frames, replies, order, queued_at)
        await worker.queue_frames([EndFrame()])

    runner = WorkerRunner(handle_sigint=False)
    await runner.add_workers(worker)
    await asyncio.gather(runner.run(), feed())
    held = [(clock.passed_at[k] - queued_at[k]) * 1e3 for k in queued_at if k in clock.passed_at]
    return {"audio_frames": len(queued_at), "audio_frames_passed": len(held),
            **{f"voice_held_{name}_ms": round(float(value), 1) for name, value in
               zip(("p50", "p95", "max"), (*np.percentile(held, [50, 95]), max(held)), strict=True)}}


def cue_rows(intended: list[IntendedCue], outcomes: list[CueOutcome], expected: dict[str, str]) -> list[dict]:
    """One row per intended cue: the nearest outcome of its gesture around the word, if any."""
    rows = []
    for cue in intended:
        gesture = expected[cue.intent]
        near = [o for o in outcomes if o.cue.gesture == gesture
                and cue.time - MATCH_BEFORE_S <= o.cue.time <= cue.time + MATCH_AFTER_S]
        outcome = min(near, key=lambda o: abs(o.cue.time - cue.time)) if near else None
        error = None if outcome is None or outcome.stroke_time is None else outcome.stroke_time - cue.time
        rows.append({"reply": cue.reply, "intent": cue.intent, "word": cue.word, "word_s": round(cue.time, 3),
                     "outcome": None if outcome is None else outcome.status,
                     "stroke_error_ms": None if error is None else round(error * 1e3),
                     "hit": error is not None and abs(error) <= STROKE_TOLERANCE_S})
    return rows


def order_result(settings: Settings, replies, intended: list[IntendedCue], order: str, args: argparse.Namespace,
                 expected: dict[str, str]) -> dict:
    processor = GesturecastProcessor(stream=Stream(settings), hold_s=args.hold_s,
                                     sentence_hold_s=args.sentence_hold_s)
    voice = asyncio.run(run_agent(processor, replies, order))
    outcomes = list(processor.session.gestures.cues.outcomes)
    rows = cue_rows(intended, outcomes, expected)
    errors = [abs(r["stroke_error_ms"]) for r in rows if r["hit"]]
    unintended = [o for o in outcomes if o.stroke_time is not None
                  and not any(abs(o.cue.time - c.time) <= MATCH_AFTER_S for c in intended)]
    return {"order": order, "hold_s": args.hold_s, "sentence_hold_s": args.sentence_hold_s,
            "alignments": processor.session.gestures.alignments.to_dict(), "intended": len(rows),
            "hits": sum(r["hit"] for r in rows),
            "hit_rate": round(sum(r["hit"] for r in rows) / len(rows), 3),
            "played": sum(r["outcome"] not in (None, "dropped") for r in rows),
            "stroke_error_abs_ms_p50": round(float(np.median(errors))) if errors else None,
            "unintended_played": len(unintended), "unintended": [o.describe() for o in unintended], **voice,
            "cues": rows}


def quiet_pipecat() -> None:
    """Pipecat's own log (loguru) at warnings only: its debug lines would bury the result."""
    logger.remove()
    logger.add(sys.stderr, level="WARNING")


def run(args: argparse.Namespace) -> int:
    quiet_pipecat()
    settings = settings_from_args(args)
    orders = [order for order in args.orders.split(",") if order]
    if unknown := [order for order in orders if order not in ORDERS]:
        raise SystemExit(f"unknown order {unknown[0]!r}: use {', '.join(ORDERS)}")
    replies, intended = speak_replies(AGENT_REPLIES, CACHE, args.voice)
    probe = Stream(settings, paced=False)
    expected = {c.intent: probe.session.gestures.phrases.gesture_of(c.intent) for c in intended}
    probe.close()
    results = [order_result(settings, replies, intended, order, args, expected) for order in orders]
    result = {"voice": args.voice, "replies": len(replies), "intended": len(intended), "orders": results}
    text = json.dumps(result, indent=2) + "\n"
    args.out.mkdir(parents=True, exist_ok=True)
    write_text_atomic(args.out / "pipecat.json", text)
    brief = [{k: v for k, v in r.items() if k not in ("cues", "unintended")} for r in results]
    sys.stdout.write(text if args.json else json.dumps(brief) + "\n")
    return 0
