"""``gesturecast bench gestures``: are cued gestures carried out, on the word, smoothly, and only when cued?

**Stories.** espeak-ng speaks each sentence at run time (deterministic, cached under ``.cache/bench/gestures``);
sentences are joined with :data:`PAUSE_S` of silence. Every trigger phrase opens its sentence, so its start is the
sentence's measured voice onset (first 10 ms frame within 30 dB of the sentence's peak); the other words are
spread over the voiced span. A story without trigger words is the cue-free speech.

**Runs.** Each story is generated twice with the same seed, without and with its transcript (the same session
code as ``generate --transcript``).

**Detector** (independent of the lexicon's stroke rules; joint positions relative to the hips in the body's
facing frame, x left, y up, z forward): a wave or a bye is a wrist above its shoulder for at least 0.25 s with a
lateral swing (two or more turns of at least 2 cm); a raise is the named wrist(s) 5 cm or more above the
shoulder(s) for 0.2 s; a bow or a call (Bandai's call is a shout, leaning forward) is the head at least 12 cm
further forward of the hips than the stream's median for 0.2 s; a guide is an arm held out (85 % of its length,
the wrist within 15 cm of shoulder height and 20 cm in front of it) for 0.3 s. A detection's stroke is the first
frame within 10 % of its signal's peak. A cued gesture is
recognised when the detector fires within [word − 1.5 s, word + 2.5 s]; its stroke is the detector signal's
first arrival near its peak. Detections in the uncued runs are gestures without a cue.

**Measures** (JSON): recognised per gesture type; stroke − word start p50/p95 (ms); the largest jerk within
0.3 s of each clip's start and end over the uncued stream's 95th-percentile jerk; speech following (correlation
of speech energy and body speed, :func:`speech_following`, computed on the whole stream) on the frames outside the
cue windows and :data:`FOLLOWING_MARGIN_S` around them, cued over uncued; compute
seconds per second of audio, cued over uncued; a PNG strip of frames around each cue with its word.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gesturecast.files import write_text_atomic
from gesturecast.frames import PoseFrame
from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.models.evaluation.speech_following import speech_following
from gesturecast.models.motion.motion import MOTION_FPS
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS
from gesturecast.models.runtime.gesture_strokes import body_frame_positions
from gesturecast.realtime.audio.sources import ArraySource
from gesturecast.realtime.cli_flags import add_generation_arguments, settings_from_args
from gesturecast.realtime.engine_cli import frames_to_motion
from gesturecast.realtime.generation.word_cues import Word
from gesturecast.realtime.run.engine import run_offline
from gesturecast.realtime.run.engine_setup import build_session
from gesturecast.realtime.timing.clock import MonotonicClock
from gesturecast.settings import Settings
from gesturecast.tools.bench.speech.lipsync_set import espeak

CACHE = Path(".cache/bench/gestures")
PAUSE_S = 0.8
LEAD_IN_S = 1.5  # silence before the first sentence: room for a gesture whose stroke lands on the first word
ONSET_DB = 30.0  # a sentence's voice starts at its first 10 ms frame within this many dB of its loudest
WINDOW_BEFORE_S, WINDOW_AFTER_S = 1.5, 2.5  # where a cued gesture must show, around its word
SEAM_S = 0.3
FOLLOWING_MARGIN_S = 0.5  # the following measure's smoothing width: a clip's own speed spreads this far past its ends
LEAD_S = 0.8  # the picture starts this long before each word
STORIES: dict[str, tuple[str, ...]] = {
    "greetings": ("Hello everyone, and welcome back to the show.", "Today I want to talk about the weather.",
                  "Thank you so much for watching every week.", "The forecast says rain, then some sun later.",
                  "Hooray, we finally did it!", "It took a long time and a lot of work.",
                  "Goodbye, and see you next time."),
    "pointing": ("Look at this picture of the old harbour.", "The boats leave early in the morning.",
                 "Come on, follow me to the end of the pier.", "The water is calm and very clear today.",
                 "Hi there, nice to meet you!", "Thanks for coming all the way out here."),
    "cue-free": ("Today I want to talk about the weather and the news.", "The forecast says rain in the morning.",
                 "In the afternoon the sun comes back for a while.", "Most people will stay inside and read.",
                 "Tomorrow will be colder, with wind from the north."),
}


@dataclass(frozen=True)
class Story:
    name: str
    audio: np.ndarray  # (n,) 16 kHz
    words: list[Word]


def register_bench(bench_subparsers: argparse._SubParsersAction) -> None:
    parser = bench_subparsers.add_parser("gestures", help="cued gestures: recognised, on the word, smooth, only "
                                         "when cued (espeak-ng stories; JSON + PNG)")
    add_generation_arguments(parser)
    parser.add_argument("--json", action="store_true", help="print the JSON result")
    parser.add_argument("--out", type=Path, default=Path("out/bench/gestures"), help="folder for JSON and PNG")
    parser.set_defaults(func=run)


def sentence_audio(text: str) -> np.ndarray:
    """(n,) 16 kHz speech of one sentence (espeak-ng, cached)."""
    CACHE.mkdir(parents=True, exist_ok=True)
    path = CACHE / f"{hashlib.sha1(text.encode()).hexdigest()[:16]}.wav"  # the same name in every run
    if not path.is_file():
        subprocess.run([espeak(), "-w", str(path), text], check=True, capture_output=True)
    return load_audio(path)


def voiced_span(audio: np.ndarray) -> tuple[float, float]:
    """(onset, offset) seconds of a sentence: its first and last 10 ms frames within ONSET_DB of its peak."""
    hop = SAMPLE_RATE // 100
    frames = audio[: len(audio) // hop * hop].reshape(-1, hop)  # (F, hop)
    level = 10 * np.log10(np.mean(frames**2, axis=1) + 1e-12)  # (F,)
    voiced = np.flatnonzero(level >= level.max() - ONSET_DB)
    return voiced[0] / 100, (voiced[-1] + 1) / 100


def make_story(name: str, sentences: tuple[str, ...]) -> Story:
    """The sentences after LEAD_IN_S of silence, joined with pauses, and their words timed over each voiced span."""
    pieces, words, start = [np.zeros(int(LEAD_IN_S * SAMPLE_RATE), np.float32)], [], LEAD_IN_S
    for text in sentences:
        audio = sentence_audio(text)
        onset, offset = voiced_span(audio)
        tokens = text.split()
        step = (offset - onset) / len(tokens)
        words += [Word(token, start + onset + i * step, start + onset + (i + 1) * step) for i, token in
                  enumerate(tokens)]
        pieces += [audio, np.zeros(int(PAUSE_S * SAMPLE_RATE), np.float32)]
        start += len(audio) / SAMPLE_RATE + PAUSE_S
    return Story(name, np.concatenate(pieces), words)


def generate(settings: Settings, story: Story, cued: bool) -> tuple[list[PoseFrame], list, float]:
    """(frames, placements, compute seconds per audio second) of one run."""
    session = build_session(settings, MonotonicClock())
    placements = session.cue_words(story.words) if cued else []
    frames, report = run_offline(session, ArraySource(story.audio, SAMPLE_RATE))
    return frames, placements, report.rtf


def body_positions(frames: list[PoseFrame]) -> tuple[np.ndarray, tuple[str, ...]]:
    """(T, J, 3) joint positions relative to the hips in the hips' facing frame (x left, y up, z forward)."""
    return body_frame_positions(frames_to_motion(frames)), CANONICAL_WITH_HANDS.names


def runs_of(mask: np.ndarray, min_frames: int) -> list[tuple[int, int]]:
    """[start, stop) of the runs of True at least ``min_frames`` long."""
    edges = np.flatnonzero(np.diff(np.concatenate([[0], mask.astype(int), [0]])))
    return [(a, b) for a, b in zip(edges[::2], edges[1::2], strict=True) if b - a >= min_frames]


def swings(x: np.ndarray, min_swing: float = 0.02) -> int:
    """Turns of a lateral trace (m) whose swing between consecutive extremes is at least ``min_swing``."""
    turns, direction, extreme = 0, 0.0, float(x[0])
    for value in map(float, x[1:]):
        if direction == 0.0:
            if abs(value - extreme) >= min_swing:
                direction, extreme = float(np.sign(value - extreme)), value
        elif (value - extreme) * direction > 0:
            extreme = value
        elif abs(value - extreme) >= min_swing:
            turns, direction, extreme = turns + 1, -direction, value
    return turns


class Detector:
    """The gesture detector over one stream's body-frame positions (rules: module docstring)."""

    def __init__(self, body: np.ndarray, names: tuple[str, ...]) -> None:
        self.body = body
        joint = names.index
        self.wrist = {side: body[:, joint(f"{side}Hand")] for side in ("Left", "Right")}  # (T, 3)
        self.shoulder = {side: body[:, joint(f"{side}UpperArm")] for side in ("Left", "Right")}
        self.arm_length = {side: float(np.median(np.linalg.norm(body[:, joint(f"{side}UpperArm")] - body[:, joint(
            f"{side}LowerArm")], axis=1) + np.linalg.norm(body[:, joint(f"{side}LowerArm")] - self.wrist[side],
            axis=1))) for side in ("Left", "Right")}
        self.head_forward = body[:, joint("Head"), 2]  # (T,)

    def height(self, side: str) -> np.ndarray:
        return self.wrist[side][:, 1] - self.shoulder[side][:, 1]

    def events(self, gesture: str) -> list[tuple[int, int, int]]:
        """(start, stop, stroke frame) of each detection of ``gesture``'s kind."""
        kind = gesture.split("-")[0]
        sides = {"left": ["Left"], "right": ["Right"]}.get(gesture.split("-")[-1], ["Left", "Right"])
        if kind in ("wave", "bye"):
            return [e for side in sides for e in self._waves(side)]
        if kind == "raise":
            heights = np.min([self.height(side) for side in sides], axis=0) if gesture.endswith("both") else \
                np.max([self.height(side) for side in sides], axis=0)
            return self._peaks(heights >= 0.05, heights, 6)
        if kind == "bow":
            forward = self.head_forward - np.median(self.head_forward)
            return self._peaks(forward >= 0.12, forward, 6)
        if kind == "call":  # Bandai's call: hands cupped at the mouth, the body leaning forward
            forward = self.head_forward - np.median(self.head_forward)
            return self._peaks(forward >= 0.12, forward, 6)
        reach = np.max([self._reach(side) for side in sides], axis=0)  # guide: an arm held out
        return self._peaks(reach >= 0.85, reach, 9)

    def _reach(self, side: str) -> np.ndarray:
        """The arm's extension (fraction of its length) where it is held out near shoulder height, else 0."""
        extension = np.linalg.norm(self.wrist[side] - self.shoulder[side], axis=1) / self.arm_length[side]
        held_out = (np.abs(self.height(side)) <= 0.15) & (self.wrist[side][:, 2] - self.shoulder[side][:, 2] >= 0.2)
        return np.where(held_out, extension, 0.0)

    def _waves(self, side: str) -> list[tuple[int, int, int]]:
        height = self.height(side)
        found = []
        for start, stop in runs_of(height >= 0.0, int(0.25 * MOTION_FPS)):
            if swings(self.wrist[side][start:stop, 0]) >= 2:
                found.append((start, stop, arrival(height, start, stop)))
        return found

    @staticmethod
    def _peaks(mask: np.ndarray, signal: np.ndarray, min_frames: int) -> list[tuple[int, int, int]]:
        return [(a, b, arrival(signal, a, b)) for a, b in runs_of(mask, min_frames)]


def arrival(signal: np.ndarray, start: int, stop: int, tolerance: float = 0.1) -> int:
    """The stroke of a detection: the first frame in [start, stop) within ``tolerance`` of the signal's range below
    its peak (a held pose counts from when it is reached)."""
    window = signal[start:stop]
    level = window.max() - tolerance * (window.max() - window.min())
    return start + int(np.flatnonzero(window >= level)[0])


def jerk(body: np.ndarray) -> np.ndarray:
    """(T-3,) mean joint jerk magnitude (m/s³) per frame of the body joints."""
    third = np.diff(body[:, :22], n=3, axis=0) * MOTION_FPS**3  # (T-3, 22, 3)
    return np.linalg.norm(third, axis=-1).mean(axis=1)


def cue_rows(story: Story, frames: list[PoseFrame], placements: list, uncued_body: np.ndarray) -> list[dict]:
    body, names = body_positions(frames)
    detector = Detector(body, names)
    seam_reference = float(np.percentile(jerk(uncued_body), 95))
    stream_jerk = jerk(body)
    rows = []
    for placement in placements:
        word_frame = placement.cue.time * MOTION_FPS
        lo, hi = word_frame - WINDOW_BEFORE_S * MOTION_FPS, word_frame + WINDOW_AFTER_S * MOTION_FPS
        hits = [e for e in detector.events(placement.cue.gesture) if e[0] <= hi and e[1] >= lo]
        clip_start = placement.first * 4
        clip_stop = (placement.last + 1) * 4
        seams = [stream_jerk[max(f - int(SEAM_S * MOTION_FPS), 0): f + int(SEAM_S * MOTION_FPS)].max()
                 for f in (clip_start, clip_stop) if f < len(stream_jerk)]
        stroke = min(hits, key=lambda e: abs(e[2] - word_frame))[2] if hits else None
        rows.append({"story": story.name, "gesture": placement.cue.gesture, "word": placement.cue.source,
                     "word_s": placement.cue.time, "recognised": bool(hits),
                     "stroke_error_ms": None if stroke is None else (stroke - word_frame) / MOTION_FPS * 1e3,
                     "seam_jerk_ratio": max(seams) / seam_reference if seams else None,
                     "frames": (clip_start, clip_stop)})
    return rows


def following(frames: list[PoseFrame], audio: np.ndarray, outside: np.ndarray) -> float:
    """Speech following over the ``outside`` (T,) frames, speed and energy computed on the whole stream."""
    positions = frames_to_motion(frames).positions()[:, :22]  # (T, 22, 3)
    return speech_following(positions, audio, SAMPLE_RATE, MOTION_FPS, kept=outside).best_correlation


def study_story(settings: Settings, story: Story) -> dict:
    uncued, _, rtf_uncued = generate(settings, story, cued=False)
    uncued_body, names = body_positions(uncued)
    spontaneous = {g: len(Detector(uncued_body, names).events(g)) for g in ("wave", "bye", "raise-both", "bow",
                                                                           "guide", "call")}
    result = {"story": story.name, "seconds": len(story.audio) / SAMPLE_RATE, "spontaneous": spontaneous}
    if story.name == "cue-free":
        return result
    cued, placements, rtf_cued = generate(settings, story, cued=True)
    rows = cue_rows(story, cued, placements, uncued_body)
    outside = np.ones(len(cued), bool)
    margin = int(FOLLOWING_MARGIN_S * MOTION_FPS)
    for row in rows:
        outside[max(row["frames"][0] - margin, 0): row["frames"][1] + margin] = False
    return {**result, "cues": rows, "rtf_ratio": rtf_cued / rtf_uncued,
            "following_ratio": following(cued, story.audio, outside) / following(uncued, story.audio, outside),
            "frames_cued": cued}


def summary(stories: list[dict]) -> dict:
    rows = [row for story in stories for row in story.get("cues", [])]
    errors = np.array([r["stroke_error_ms"] for r in rows if r["stroke_error_ms"] is not None])
    by_type: dict[str, list[bool]] = {}
    for row in rows:
        by_type.setdefault(row["gesture"], []).append(row["recognised"])
    return {
        "cues": len(rows),
        "recognised_fraction": float(np.mean([r["recognised"] for r in rows])) if rows else None,
        "recognised_by_gesture": {g: f"{sum(v)}/{len(v)}" for g, v in by_type.items()},
        "stroke_error_ms": {"p50": float(np.percentile(np.abs(errors), 50)),
                            "p95": float(np.percentile(np.abs(errors), 95))} if errors.size else None,
        "seam_jerk_ratio_max": max((r["seam_jerk_ratio"] for r in rows if r["seam_jerk_ratio"]), default=None),
        "following_ratio_min": min(s["following_ratio"] for s in stories if "following_ratio" in s),
        "rtf_ratio_median": float(np.median([s["rtf_ratio"] for s in stories if "rtf_ratio" in s])),
        "gestures_without_cue": {s["story"]: s["spontaneous"] for s in stories},
    }


def run(args: argparse.Namespace) -> int:
    settings = settings_from_args(args)
    stories = [study_story(settings, make_story(name, sentences)) for name, sentences in STORIES.items()]
    args.out.mkdir(parents=True, exist_ok=True)
    picture = plot_cues(stories, args.out / "gestures.png")
    result = {"summary": summary(stories), "picture": str(picture),
              "stories": [{k: v for k, v in s.items() if k != "frames_cued"} for s in stories]}
    text = json.dumps(result, indent=2, default=str) + "\n"
    write_text_atomic(args.out / "gestures.json", text)
    sys.stdout.write(text if args.json else json.dumps(result["summary"], default=str) + "\n")
    return 0


def plot_cues(stories: list[dict], out: Path) -> Path:
    """One row per cue of the first story: frames from LEAD_S before to 1.6 s after the word, titled with it."""
    from gesturecast.tools.render.compare import CompareRow, render_comparison

    story = next(s for s in stories if s.get("cues"))
    frames = story["frames_cued"]
    positions = frames_to_motion(frames).positions()  # (T, J, 3)
    rows = []
    for cue in story["cues"]:
        start = max(int(round((cue["word_s"] - LEAD_S) * MOTION_FPS)), 0)
        rows.append(CompareRow(f'"{cue["word"]}" -> {cue["gesture"]}', positions[start: start + int(2.4 * MOTION_FPS)],
                               CANONICAL_WITH_HANDS.parents, CANONICAL_WITH_HANDS.names))
    return render_comparison(rows, out, MOTION_FPS, start_s=-LEAD_S)  # captions: seconds from the word
