"""``gesturecast bench gestures``: are intended gestures played on their words, are ordinary words left alone, and is
no cue lost in silence?

**Texts** (:mod:`gesturecast.tools.bench.gesture_set.texts`, held out from the classifier's training): cued stories
whose sentences mark the intended speech acts, and ordinary narration with none, spoken by espeak-ng with exact word
times (:mod:`gesturecast.tools.bench.gesture_set.stories`). ``--stories second`` … ``eighth``
read the later held-out sets (:mod:`gesturecast.tools.bench.gesture_set.texts_second`, ``texts_third``,
``texts_fourth``, ``texts_fifth``, ``texts_sixth``, ``texts_seventh``, ``texts_eighth``) instead.

**Runs.** Each cued story is generated with and without its transcript (the same session code as
``generate --transcript``), the narrations with theirs; one story also without it at the next seed (the seed-to-seed
floor of the variation measure).

**Per intended cue**: the decision (the gesture the session cued at the word, if any), its outcome (on time, late,
blended, merged, dropped: :class:`gesturecast.realtime.gestures.cues.CueOutcome`), and whether the
kinematic detector (:mod:`gesturecast.tools.bench.gesture_set.detector`) sees the gesture within
[word − 1.5 s, word + 2.5 s]: *hit* = played, detected, and the detected stroke within :data:`STROKE_TOLERANCE_S`
of the word; a merged cue (the same gesture already playing) is a hit when the detection spans its word.

**Measures** (JSON): hits / intended, per intent; stroke − word p50/p95 (ms); outcomes; cues played where none was
intended; on the narrations, gestures played per minute and detector events per minute (cued and uncued runs);
silent drops (dropped outcomes without a warning log line, plus cues decided without an outcome); two plays of one
gesture in a stream (over the frames both play, aligned at their strokes) against the seed-to-seed distance of the
uncued speech; the speed of the parts no playing
gesture moves (the torso during a wave), cued over uncued; the largest jerk within 0.3 s of each
clip's ends over the uncued stream's 95th percentile; speech following outside the cue windows, cued over uncued;
a PNG strip of frames around each cue of the first story.

``--words text`` gives the cued runs the story as a plain-text script placed by the sentence aligner (an intended
cue's outcome is then the cue nearest its word within :data:`STROKE_TOLERANCE_S`), ``--words unpunctuated`` the
timed words without punctuation (:mod:`gesturecast.tools.bench.gesture_set.word_modes`); the JSON adds the
alignment outcomes, the aligner's word start error against the TTS's own word times and its CPU against
generation's. ``--voice`` speaks the texts in another espeak-ng voice.

``--decisions-only``: only the speech acts decided on the set's words, without speech or generation
(:mod:`gesturecast.tools.bench.gesture_set.decisions`).
"""

from __future__ import annotations

import argparse
import json
import logging
import sys
import time
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from gesturecast.errors import UserError
from gesturecast.files import write_text_atomic
from gesturecast.frames import PoseFrame, gesture_names
from gesturecast.models.audio.files import SAMPLE_RATE
from gesturecast.models.evaluation.speech_following import speech_following
from gesturecast.models.motion.body_parts import PART_JOINTS
from gesturecast.models.motion.motion import MOTION_FPS
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS
from gesturecast.realtime.audio.sources import ArraySource
from gesturecast.realtime.cli_flags import add_generation_arguments, settings_from_args
from gesturecast.realtime.engine_cli import frames_to_motion
from gesturecast.realtime.gestures.cues import CueOutcome
from gesturecast.realtime.gestures.director import GestureDirector
from gesturecast.realtime.gestures.lexicon import load_lexicon
from gesturecast.realtime.gestures.strokes import body_frame_positions
from gesturecast.realtime.run.engine import run_offline
from gesturecast.realtime.run.engine_setup import build_session
from gesturecast.realtime.timing.clock import MonotonicClock
from gesturecast.realtime.words.punctuation import punctuated_by_pauses
from gesturecast.settings import Settings
from gesturecast.tools.bench.gesture_set.decisions import decisions
from gesturecast.tools.bench.gesture_set.detector import Detector, jerk
from gesturecast.tools.bench.gesture_set.stories import Story, make_story
from gesturecast.tools.bench.gesture_set.texts import CUED_STORIES, NARRATION, NARRATION_FINAL, NARRATION_LATE
from gesturecast.tools.bench.gesture_set.texts_eighth import CUED_STORIES_EIGHTH, NARRATION_EIGHTH
from gesturecast.tools.bench.gesture_set.texts_fifth import CUED_STORIES_FIFTH, NARRATION_FIFTH
from gesturecast.tools.bench.gesture_set.texts_fourth import CUED_STORIES_FOURTH, NARRATION_FOURTH
from gesturecast.tools.bench.gesture_set.texts_second import CUED_STORIES_SECOND, NARRATION_SECOND
from gesturecast.tools.bench.gesture_set.texts_seventh import CUED_STORIES_SEVENTH, NARRATION_SEVENTH
from gesturecast.tools.bench.gesture_set.texts_sixth import CUED_STORIES_SIXTH, NARRATION_SIXTH
from gesturecast.tools.bench.gesture_set.texts_third import CUED_STORIES_THIRD, NARRATION_THIRD
from gesturecast.tools.bench.gesture_set.word_modes import (
    WORD_MODES,
    WordsGiven,
    decision_words,
    story_transcript,
    words_summary,
)

WINDOW_BEFORE_S, WINDOW_AFTER_S = 1.5, 2.5  # where an intended gesture must show, around its word
STROKE_TOLERANCE_S = 0.3
SEAM_S = 0.3
FOLLOWING_MARGIN_S = 0.5  # the following measure's smoothing width: a clip's own speed spreads this far past its ends
LEAD_S = 0.8  # the picture starts this long before each word
KINDS = ("wave", "wave-right", "raise-both", "bow", "guide", "call")  # what the detector counts on narration
STORY_SETS = {  # --stories: (cued stories, named narrations)
    "first": (CUED_STORIES, (("narration", NARRATION), ("narration-late", NARRATION_LATE),
                             ("narration-final", NARRATION_FINAL))),
    "second": (CUED_STORIES_SECOND, (("narration-second", NARRATION_SECOND),)),
    "third": (CUED_STORIES_THIRD, (("narration-third", NARRATION_THIRD),)),
    "fourth": (CUED_STORIES_FOURTH, (("narration-fourth", NARRATION_FOURTH),)),
    "fifth": (CUED_STORIES_FIFTH, (("narration-fifth", NARRATION_FIFTH),)),
    "sixth": (CUED_STORIES_SIXTH, (("narration-sixth", NARRATION_SIXTH),)),
    "seventh": (CUED_STORIES_SEVENTH, (("narration-seventh", NARRATION_SEVENTH),)),
    "eighth": (CUED_STORIES_EIGHTH, (("narration-eighth", NARRATION_EIGHTH),)),
}


@dataclass
class Run:
    frames: list[PoseFrame]
    outcomes: list[CueOutcome]
    decided: int  # cues the session decided from the words (every one must have an outcome)
    warnings: list[str]  # the cue log's warning lines
    rtf: float


class _Lines(logging.Handler):
    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.lines: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.lines.append(record.getMessage())


def register_bench(bench_subparsers: argparse._SubParsersAction) -> None:
    parser = bench_subparsers.add_parser("gestures", help="intended gestures on their words, none on ordinary "
                                         "narration, no silent drops (espeak-ng texts; JSON + PNG)")
    add_generation_arguments(parser)
    parser.add_argument("--json", action="store_true", help="print the JSON result")
    parser.add_argument("--out", type=Path, default=Path("out/bench/gestures"), help="folder for JSON and PNG")
    parser.add_argument("--stories", choices=sorted(STORY_SETS), default="first",
                        help="the held-out text set (default: first; second … eighth: written later, "
                        "see texts_second.py …)")
    parser.add_argument("--words", choices=WORD_MODES, default="timed",
                        help="how the cued runs get their words: timed (the TTS's own word times), text (a plain-text "
                        "script placed by the aligner), unpunctuated (timed, punctuation removed)")
    parser.add_argument("--voice", default=None, help="the espeak-ng voice (default: its default; the held-out "
                        "voices are in gesture_set/word_modes.py)")
    parser.add_argument("--decisions-only", action="store_true",
                        help="only which speech acts are decided on the set's words: no speech, no generation "
                        "(decisions.json; a second)")
    parser.set_defaults(func=run)


def generate(settings: Settings, story: Story, cued: bool, words: WordSource | None = None) -> Run:
    """One run of ``story``, with its words cued (given as ``words`` says; timed by default) or not."""
    session = build_session(settings, MonotonicClock())
    lines = _Lines()
    log = logging.getLogger("gesturecast.realtime.gestures.cues")
    log.addHandler(lines)
    try:
        given = story_transcript(story, words.mode if words else "timed")
        outcomes = given.cue(session.gestures) if cued else []
        if words is not None and cued:
            words.note(story, session.gestures)
        phrases = session.gestures.phrases
        read = punctuated_by_pauses(decision_words(given), ended=True)  # (words, paused) as the session reads them
        decided = len(phrases.cues(*read)) if cued and phrases else len(outcomes)
        started = time.process_time()
        frames, report = run_offline(session, ArraySource(story.audio, SAMPLE_RATE))
        if words is not None and cued:
            words.generate_cpu_s += time.process_time() - started
    finally:
        log.removeHandler(lines)
    return Run(frames, outcomes, decided, lines.lines, report.rtf)


@dataclass
class WordSource:
    """``--words``: how the cued runs get their words, and what that cost (:mod:`.gesture_set.word_modes`)."""

    mode: str
    given: WordsGiven = field(default_factory=WordsGiven)
    generate_cpu_s: float = 0.0

    def note(self, story: Story, gestures: GestureDirector) -> None:
        """What placing the cued run's words cost its session; for scripts, the aligner's errors measured apart."""
        self.given.add_session(gestures)
        if self.mode == "text":
            self.given.add_errors(story)

    @property
    def tolerance_s(self) -> float:
        """How far a cue may sit from its intended word's own time and still be its cue."""
        return 1e-6 if self.mode != "text" else STROKE_TOLERANCE_S


def body_positions(frames: list[PoseFrame]) -> np.ndarray:
    """(T, J, 3) joint positions relative to the hips in the hips' facing frame (x left, y up, z forward)."""
    return body_frame_positions(frames_to_motion(frames))


def outcome_at(run: Run, time: float, tolerance_s: float = 1e-6) -> CueOutcome | None:
    """The cue's outcome nearest stream time ``time``, within ``tolerance_s``."""
    near = [o for o in run.outcomes if abs(o.cue.time - time) < tolerance_s]
    return min(near, key=lambda o: abs(o.cue.time - time)) if near else None


def intended_rows(story: Story, run: Run, detector: Detector, expected: dict[str, str], tolerance_s: float = 1e-6
                  ) -> list[dict]:
    """One row per intended cue (module docstring)."""
    rows = []
    for cue in story.intended:
        gesture = expected[cue.intent]
        outcome = outcome_at(run, cue.time, tolerance_s)
        played = outcome is not None and outcome.cue.gesture == gesture and outcome.stroke_time is not None
        word_frame = cue.time * MOTION_FPS
        lo, hi = word_frame - WINDOW_BEFORE_S * MOTION_FPS, word_frame + WINDOW_AFTER_S * MOTION_FPS
        hits = [e for e in detector.events(gesture) if e[0] <= hi and e[1] >= lo]
        stroke = min(hits, key=lambda e: abs(e[2] - word_frame))[2] if hits else None
        error = None if stroke is None else (stroke - word_frame) / MOTION_FPS
        on_word = error is not None and abs(error) <= STROKE_TOLERANCE_S
        if played and outcome.status == "merged":  # the gesture playing when the word is said counts
            on_word = any(start <= word_frame < stop for start, stop, _ in hits)
        rows.append({"story": story.name, "intent": cue.intent, "gesture": gesture, "word": cue.word,
                     "word_s": round(cue.time, 3), "decided": None if outcome is None else outcome.cue.gesture,
                     "outcome": None if outcome is None else outcome.status, "played": played,
                     "detected": bool(hits), "stroke_error_ms": None if error is None else round(error * 1e3),
                     "hit": bool(played and on_word)})
    return rows


def seams(run: Run, uncued_body: np.ndarray, body: np.ndarray) -> list[float]:
    """The largest jerk within SEAM_S of each played clip's start and stop over the uncued 95th percentile."""
    reference = float(np.percentile(jerk(uncued_body), 95))
    stream = jerk(body)
    width = int(SEAM_S * MOTION_FPS)
    ratios = []
    for frame in clip_edges(run):
        if frame < len(stream):
            ratios.append(float(stream[max(frame - width, 0): frame + width].max()) / reference)
    return ratios


def clip_edges(run: Run) -> list[int]:
    """Frames where a played gesture starts or ends (the frames' gesture names change)."""
    names = [frame.gesture for frame in run.frames]
    return [k for k in range(1, len(names)) if names[k] != names[k - 1]]


def following(frames: list[PoseFrame], audio: np.ndarray, outside: np.ndarray) -> float:
    """Speech following over the ``outside`` (T,) frames, speed and energy computed on the whole stream."""
    positions = frames_to_motion(frames).positions()[:, :22]  # (T, 22, 3)
    return speech_following(positions, audio, SAMPLE_RATE, MOTION_FPS, kept=outside).best_correlation


def following_ratio(cued: Run, uncued: Run, audio: np.ndarray) -> float:
    """Following outside the frames with a gesture (and FOLLOWING_MARGIN_S around them), cued over uncued."""
    gesturing = np.array([bool(f.gesture) for f in cued.frames])
    margin = int(FOLLOWING_MARGIN_S * MOTION_FPS)
    outside = ~np.convolve(gesturing, np.ones(2 * margin + 1), mode="same").astype(bool)
    return following(cued.frames, audio, outside) / following(uncued.frames, audio, outside)


def finite_or_none(value: float) -> float | None:
    """``value`` rounded, or None when it is not finite (no frame left to measure)."""
    return round(value, 3) if np.isfinite(value) else None


def play_distances(run: Run, body: np.ndarray) -> list[dict]:
    """Mean joint distance (m) between consecutive plays of the same gesture in one stream over their played parts
    (:func:`played_spans`), aligned at their strokes: the frames both play, from the later start to the earlier end."""
    strokes: dict[str, list[int]] = {}
    for outcome in run.outcomes:
        if outcome.status in ("on time", "late", "blended"):
            strokes.setdefault(outcome.cue.gesture, []).append(round(outcome.stroke_time * MOTION_FPS))
    names = [gesture_names(frame.gesture) for frame in run.frames[: len(body)]]
    pairs = []
    for gesture, frames in strokes.items():
        spans = played_spans(names, gesture, sorted(frames))
        for (a, a0, a1), (b, b0, b1) in zip(spans, spans[1:], strict=False):
            before, after = min(a - a0, b - b0), min(a1 - a, b1 - b)
            if before + after > 0:
                distance = np.linalg.norm(body[a - before: a + after, :22] - body[b - before: b + after, :22], axis=-1)
                pairs.append({"gesture": gesture, "distance_m": round(float(distance.mean()), 4),
                              "seconds": round((before + after) / MOTION_FPS, 2)})
    return pairs


def played_spans(names: list[set[str]], gesture: str, strokes: list[int]) -> list[tuple[int, int, int]]:
    """(stroke, first, stop) of each play of ``gesture``: the frames around its stroke that name it, no further than
    halfway to the next or previous play's stroke (two plays may touch); strokes outside the stream are left out."""
    spans = []
    for k, stroke in enumerate(strokes):
        if not 0 <= stroke < len(names) or gesture not in names[stroke]:
            continue
        low = (strokes[k - 1] + stroke + 1) // 2 if k else 0
        high = (stroke + strokes[k + 1] + 1) // 2 if k + 1 < len(strokes) else len(names)
        first, stop = stroke, stroke + 1
        while first > low and gesture in names[first - 1]:
            first -= 1
        while stop < high and gesture in names[stop]:
            stop += 1
        spans.append((stroke, first, stop))
    return spans


def idle_part_speed_ratio(run: Run, body: np.ndarray, uncued_body: np.ndarray, parts: dict[str, tuple[str, ...]]
                          ) -> float | None:
    """Mean joint speed of the body parts no playing gesture moves (the torso during a wave), over the frames with a
    gesture, cued ÷ uncued (None when every part is busy, as in a bow)."""
    names = CANONICAL_WITH_HANDS.names
    count = min(len(body), len(uncued_body)) - 1
    cued = np.linalg.norm(np.diff(body[: count + 1], axis=0), axis=-1)  # (T-1, J) metres per frame
    uncued = np.linalg.norm(np.diff(uncued_body[: count + 1], axis=0), axis=-1)
    total_cued = total_uncued = 0.0
    for k, frame in enumerate(run.frames[1: count + 1]):
        busy = {part for name in gesture_names(frame.gesture) for part in parts[name]}
        joints = [names.index(j) for part, js in PART_JOINTS.items() if part not in busy for j in js]
        if busy and joints:
            total_cued += float(cued[k, joints].mean())
            total_uncued += float(uncued[k, joints].mean())
    return total_cued / total_uncued if total_uncued else None


def narration_result(settings: Settings, story: Story, words: WordSource) -> dict:
    """Gestures played per minute on ordinary narration, and detector events per minute with and without words."""
    cued, uncued = generate(settings, story, True, words), generate(settings, story, False)
    played = [o for o in cued.outcomes if o.stroke_time is not None]
    detected = {run_name: sum(len(Detector(body_positions(run.frames), CANONICAL_WITH_HANDS.names).events(kind))
                              for kind in KINDS) for run_name, run in (("cued", cued), ("uncued", uncued))}
    return {"story": story.name, "minutes": round(story.minutes, 2), "played": len(played),
            "played_per_minute": round(len(played) / story.minutes, 2),
            "played_cues": [f"{o.cue.gesture} at {o.cue.source!r} ({o.cue.time:.1f} s)" for o in played],
            "detector_events_per_minute": {k: round(v / story.minutes, 2) for k, v in detected.items()},
            "silent_drops": silent_drops(cued)}


def silent_drops(run: Run) -> int:
    """Dropped cues with no warning line, plus decided cues with no outcome."""
    unlogged = sum(1 for o in run.outcomes if o.status == "dropped" and o.describe() not in run.warnings)
    return unlogged + max(0, run.decided - len(run.outcomes))


def story_result(settings: Settings, story: Story, expected: dict[str, str], parts: dict[str, tuple[str, ...]],
                 words: WordSource) -> dict:
    cued, uncued = generate(settings, story, True, words), generate(settings, story, False)
    body, uncued_body = body_positions(cued.frames), body_positions(uncued.frames)
    detector = Detector(body, CANONICAL_WITH_HANDS.names)
    rows = intended_rows(story, cued, detector, expected, words.tolerance_s)
    intended_times = np.array([c.time for c in story.intended])
    extra = [f"{o.cue.gesture} at {o.cue.source!r}" for o in cued.outcomes
             if o.stroke_time is not None and not np.any(np.abs(intended_times - o.cue.time) < words.tolerance_s)]
    outcomes: dict[str, int] = {}
    for outcome in cued.outcomes:
        outcomes[outcome.status] = outcomes.get(outcome.status, 0) + 1
    return {"story": story.name, "seconds": round(len(story.audio) / SAMPLE_RATE, 2), "cues": rows,
            "outcomes": outcomes, "unintended": extra, "silent_drops": silent_drops(cued),
            "seam_jerk_ratios": [round(r, 2) for r in seams(cued, uncued_body, body)],
            "following_ratio": finite_or_none(following_ratio(cued, uncued, story.audio)),
            "plays": play_distances(cued, body), "rtf_ratio": round(cued.rtf / uncued.rtf, 3),
            "idle_parts_speed_ratio": idle_part_speed_ratio(cued, body, uncued_body, parts),
            "frames_cued": cued.frames, "uncued_body": uncued_body}


def seed_floor(settings: Settings, story: Story, uncued_body: np.ndarray) -> float:
    """Mean joint distance (m) between the uncued runs of ``story`` at two seeds: the variation of beat gestures."""
    other = body_positions(generate(replace(settings, seed=settings.seed + 1), story, False).frames)
    n = min(len(other), len(uncued_body))
    return float(np.linalg.norm(other[:n, :22] - uncued_body[:n, :22], axis=-1).mean())


def summary(stories: list[dict], narrations: list[dict], floor: float) -> dict:
    rows = [row for story in stories for row in story["cues"]]
    errors = np.array([abs(r["stroke_error_ms"]) for r in rows
                       if r["played"] and r["outcome"] != "merged" and r["stroke_error_ms"] is not None])
    by_intent: dict[str, list[bool]] = {}
    for row in rows:
        by_intent.setdefault(row["intent"], []).append(row["hit"])
    outcomes: dict[str, int] = {}
    for story in stories:
        for status, n in story["outcomes"].items():
            outcomes[status] = outcomes.get(status, 0) + n
    plays = [p["distance_m"] for s in stories for p in s["plays"]]
    idle = [s["idle_parts_speed_ratio"] for s in stories if s["idle_parts_speed_ratio"] is not None]
    minutes = sum(n["minutes"] for n in narrations)
    return {
        "intended": len(rows),
        "hit_fraction": round(float(np.mean([r["hit"] for r in rows])), 3),
        "played_fraction": round(float(np.mean([r["played"] for r in rows])), 3),
        "detected_when_played": f"{sum(r['detected'] for r in rows if r['played'])}/{sum(r['played'] for r in rows)}",
        "hits_by_intent": {k: f"{sum(v)}/{len(v)}" for k, v in by_intent.items()},
        "stroke_error_ms": {"p50": float(np.percentile(errors, 50)), "p95": float(np.percentile(errors, 95))}
        if errors.size else None,
        "outcomes": outcomes,
        "unintended_in_stories": sum(len(s["unintended"]) for s in stories),
        "narration_minutes": round(minutes, 2),
        "narration_played_per_minute": {n["story"]: n["played_per_minute"] for n in narrations},
        "narration_played_per_minute_all": round(sum(n["played"] for n in narrations) / minutes, 2),
        "silent_drops": sum(s["silent_drops"] for s in stories) + sum(n["silent_drops"] for n in narrations),
        "repeat_distance_m": {"min": min(plays), "median": float(np.median(plays))} if plays else None,
        "seed_floor_m": round(floor, 4),
        "seam_jerk_ratio_max": max((r for s in stories for r in s["seam_jerk_ratios"]), default=None),
        "following_ratio_min": min((s["following_ratio"] for s in stories if s["following_ratio"] is not None),
                                   default=None),
        "idle_parts_speed_ratio": {"min": min(idle), "median": float(np.median(idle))} if idle else None,
        "rtf_ratio_median": float(np.median([s["rtf_ratio"] for s in stories])),
    }


def run(args: argparse.Namespace) -> int:
    settings = settings_from_args(args)
    probe = build_session(settings, MonotonicClock())
    expected = {intent: probe.gestures.phrases.gesture_of(intent) for intent in ("greeting", "thanks", "farewell",
                                                                         "celebration", "presenting", "calling")}
    parts = {entry.name: entry.parts for entry in load_lexicon(settings.gestures)}
    cued_texts, narration_texts = STORY_SETS[args.stories]
    if args.decisions_only:
        return run_decisions(args, probe.gestures.phrases, cued_texts, narration_texts)
    words = WordSource(args.words)
    stories = [story_result(settings, make_story(name, sentences, voice=args.voice), expected, parts, words)
               for name, sentences in cued_texts.items()]
    narrations = [narration_result(settings, make_story(name, texts, voice=args.voice), words)
                  for name, texts in narration_texts]
    floor = seed_floor(settings, make_story(*next(iter(cued_texts.items())), voice=args.voice),
                       stories[0]["uncued_body"])
    args.out.mkdir(parents=True, exist_ok=True)
    picture = plot_cues(stories[0], args.out / "gestures.png")
    result = {"stories_set": args.stories, "words": args.words, "voice": args.voice,
              "summary": {**summary(stories, narrations, floor), **words_summary(words.given, words.generate_cpu_s)},
              "picture": str(picture),
              "stories": [{k: v for k, v in s.items() if k not in ("frames_cued", "uncued_body")} for s in stories],
              "narrations": narrations}
    text = json.dumps(result, indent=2, default=str) + "\n"
    write_text_atomic(args.out / "gestures.json", text)
    sys.stdout.write(text if args.json else json.dumps(result["summary"], default=str) + "\n")
    return 0


def run_decisions(args: argparse.Namespace, phrases, cued_texts: dict, narration_texts: tuple) -> int:
    """``--decisions-only``: the decisions on the set's words (:mod:`gesturecast.tools.bench.gesture_set.decisions`)
    as JSON in ``decisions.json``; the counts printed (everything with ``--json``)."""
    if phrases is None:
        raise UserError("--decisions-only: speech acts are switched off in these settings, so none is decided")
    result = {"stories_set": args.stories, **decisions(phrases, cued_texts, narration_texts)}
    text = json.dumps(result, indent=2) + "\n"
    args.out.mkdir(parents=True, exist_ok=True)
    write_text_atomic(args.out / "decisions.json", text)
    counts = {k: v for k, v in result.items() if not isinstance(v, list)}
    sys.stdout.write(text if args.json else json.dumps(counts) + "\n")
    return 0


def plot_cues(story: dict, out: Path) -> Path:
    """One row per intended cue of ``story``: frames from LEAD_S before to 1.6 s after the word, titled with it."""
    from gesturecast.tools.render.compare import CompareRow, render_comparison

    positions = frames_to_motion(story["frames_cued"]).positions()  # (T, J, 3)
    rows = []
    for cue in story["cues"]:
        start = max(int(round((cue["word_s"] - LEAD_S) * MOTION_FPS)), 0)
        label = f'"{cue["word"]}" -> {cue["decided"] or "nothing"} ({cue["outcome"] or "no cue"})'
        rows.append(CompareRow(label, positions[start: start + int(2.4 * MOTION_FPS)], CANONICAL_WITH_HANDS.parents,
                               CANONICAL_WITH_HANDS.names))
    return render_comparison(rows, out, MOTION_FPS, start_s=-LEAD_S)  # captions: seconds from the word
