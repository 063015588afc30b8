"""``gesturecast bench idle``: how much the body moves once a long pause has settled, in real takes and in the idle.

The session cross-fades to the procedural idle motion (:mod:`gesturecast.realtime.pose.idle`) after a second of
silence, so in a long pause the avatar moves as much as its idle does. This bench puts that beside real people:

- **real**: every ZeroEGGS take with speech in the dataset cache, its ``train`` split only (the validation and test
  spans stay out of every choice). The speaking flags are the runtime's, from the take's own
  audio. A pause of at least :data:`LONG_PAUSE_S` has **settled** from :data:`SETTLED_AFTER_S` after its start to its
  end (real motion slows for about a second after the voice stops, then stays low);
- **idle**: :class:`IdleMotion` at the default :class:`IdleConfig`, seeds 0–2, over :data:`IDLE_SECONDS`;
- **avatar**: the bundle's motion for each take's same audio at the product's defaults (``Settings()``, the
  offline `generate` path), generation seeds ``--seeds``, read by the same ``rest`` measure (``--seeds ''``: none).

Speed: the mean speed (m/s) of the joints every take has (spine, chest and arms: the upper-body takes have no head)
relative to the hips. Reported per take: speaking speed, settled speed, their ratio, the settled seconds and
``rest`` (``bench voices``' measure of generated motion: speed in every pause ÷ while speaking, the upper body); the
takes' settled speeds pooled by time and averaged per take; the idle's speed and each real figure over it. One JSON
object; nothing is asserted.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from gesturecast.errors import UserError
from gesturecast.models.audio.files import SAMPLE_RATE
from gesturecast.models.audio.streaming import extract_features, speaking_flags
from gesturecast.models.dataset.cache import load_take, read_index
from gesturecast.models.evaluation.speech_following import upper_body_speed
from gesturecast.models.generator.diffusion import SamplerConfig
from gesturecast.models.motion.motion import MOTION_FPS, SkeletonMotion
from gesturecast.models.motion.skeleton import CANONICAL
from gesturecast.models.runtime.bundle import ModelBundle
from gesturecast.realtime.pose.idle import IdleConfig, IdleMotion
from gesturecast.realtime.run.engine_setup import load_bundle
from gesturecast.settings import DEFAULT_MODEL_DIR
from gesturecast.tools.bench.speech.voices import DEFAULT_SEEDS, parse_seeds, rest_ratio_of_flags
from gesturecast.tools.data_cli import DEFAULT_CACHE
from gesturecast.tools.eval.clips import EvalClip
from gesturecast.tools.eval.condition import DEFAULT_CONDITION
from gesturecast.tools.eval.generate import generate_offline

LONG_PAUSE_S = 2.5
SETTLED_AFTER_S = 1.5
IDLE_SECONDS = 60.0
IDLE_SEEDS = (0, 1, 2)
SHARED_JOINTS = ("Spine", "Chest", "LeftUpperArm", "LeftLowerArm", "LeftHand", "RightUpperArm", "RightLowerArm",
                 "RightHand")
ZEGGS_DATASETS = ("zeggs", "zeggs_upper")


def register_bench(bench_subparsers: argparse._SubParsersAction) -> None:
    parser = bench_subparsers.add_parser("idle", help="motion in settled pauses: real takes against the idle (JSON)")
    parser.add_argument("--cache", type=Path, default=DEFAULT_CACHE, help="dataset cache (gesturecast data build)")
    parser.add_argument("--bundle", type=Path, default=DEFAULT_MODEL_DIR, help="model bundle (default: bundled)")
    parser.add_argument("--seeds", default=DEFAULT_SEEDS, help="comma-separated generation seeds of the avatar's "
                        "motion on each take's audio ('': none)")
    parser.set_defaults(func=run_bench)


def shared_joint_speed(positions: np.ndarray) -> np.ndarray:
    """(T, J, 3) → (T,) mean speed (m/s) of :data:`SHARED_JOINTS` relative to the hips."""
    return upper_body_speed(positions, MOTION_FPS, joints=SHARED_JOINTS)


def settled_frames(speaking: np.ndarray, fps: float = MOTION_FPS) -> np.ndarray:
    """(T,) bool: the frames of every silent run of ≥ LONG_PAUSE_S from SETTLED_AFTER_S after its start."""
    settled = np.zeros(len(speaking), bool)
    edges = np.flatnonzero(np.diff(np.concatenate([[1], speaking.astype(int), [1]])))  # silent runs' starts, ends
    for start, stop in zip(edges[::2], edges[1::2], strict=True):
        if stop - start >= LONG_PAUSE_S * fps:
            settled[start + int(round(SETTLED_AFTER_S * fps)): stop] = True
    return settled


def real_take(motion: SkeletonMotion, audio: np.ndarray, frames: int) -> dict:
    """Speaking and settled-pause speeds of the first ``frames`` frames of one take, and its ``rest`` as
    ``bench voices`` measures generated motion (every pause ÷ speaking, the upper body)."""
    positions = motion.positions()[:frames]  # (T, J, 3)
    speed = shared_joint_speed(positions)  # (T,)
    flags = speaking_flags(extract_features(audio))  # (T',) read once for both measures
    speaking = flags[: len(speed)]
    speed = speed[: len(speaking)]
    settled = settled_frames(speaking)
    speaking_speed = float(speed[speaking].mean())
    settled_speed = float(speed[settled].mean()) if settled.any() else None  # None: no pause long enough
    return {"speaking_m_s": round(speaking_speed, 4),
            "settled_m_s": None if settled_speed is None else round(settled_speed, 4),
            "settled_over_speaking": None if settled_speed is None else round(settled_speed / speaking_speed, 3),
            "settled_s": round(float(settled.sum()) / MOTION_FPS, 1),
            "rest": round(rest_ratio_of_flags(positions, flags), 3)}


def avatar_rest(bundle: ModelBundle, audio: np.ndarray, seeds: list[int]) -> dict:
    """``rest`` of the bundle's motion for ``audio`` at ``Settings()``, per generation seed and their mean."""
    sampler = SamplerConfig("ddim", bundle.default_steps)
    clip = EvalClip("take", audio, DEFAULT_CONDITION.style)
    speaking = speaking_flags(extract_features(audio))  # (T',) the same for every seed
    per_seed = [rest_ratio_of_flags(generate_offline(bundle, sampler, clip, DEFAULT_CONDITION.style, seed,
                                                     generator_style=DEFAULT_CONDITION.generator_style).positions,
                                    speaking)
                for seed in seeds]
    return {"per_seed": [round(value, 3) for value in per_seed], "mean": round(float(np.mean(per_seed)), 3)}


def real_takes(cache: Path, bundle: ModelBundle | None = None, seeds: list[int] = ()) -> dict[str, dict]:
    """:func:`real_take` of the train split of every ZeroEGGS take with speech in the cache, with the avatar's
    ``rest`` on the same audio when ``seeds`` are given."""
    out = {}
    for record in read_index(cache)["takes"]:
        if record["dataset"] not in ZEGGS_DATASETS or not record["has_audio"]:
            continue
        motion, audio = load_take(cache, record)
        train = [segment for segment in record["segments"] if segment["split"] == "train"]
        stop = max(segment["stop"] for segment in train)  # the train split is the take's first part
        samples = int(round(stop / motion.fps * SAMPLE_RATE))
        take = real_take(motion, audio[:samples], stop)
        if seeds:
            take["avatar_rest"] = avatar_rest(bundle, audio[:samples], seeds)
        out[f"{record['dataset']}/{record['name']}"] = take
    return out


def idle_speed(config: IdleConfig | None = None, seeds: tuple[int, ...] = IDLE_SEEDS,
               seconds: float = IDLE_SECONDS) -> float:
    """Mean :func:`shared_joint_speed` of the idle motion (default: the default idle) over ``seconds``, averaged over
    ``seeds``."""
    times = np.arange(int(seconds * MOTION_FPS)) / MOTION_FPS  # (T,)
    speeds = []
    for seed in seeds:
        idle = IdleMotion(config, seed=seed)
        motion = SkeletonMotion(idle.rotations(times), idle.root_position(times), MOTION_FPS, CANONICAL)
        speeds.append(shared_joint_speed(motion.positions()).mean())
    return float(np.mean(speeds))


def idle_report(takes: dict[str, dict], idle: float) -> dict:
    """The takes, their pooled and per-take settled speeds (of the takes with a settled pause), and each over the
    idle's."""
    settling = [take for take in takes.values() if take["settled_m_s"] is not None]
    if not settling:
        raise UserError("no take in the cache has a pause long enough to settle "
                        f"(≥ {LONG_PAUSE_S} s of silence in its train split)")
    seconds = np.array([take["settled_s"] for take in settling])
    settled = np.array([take["settled_m_s"] for take in settling])
    pooled, per_take = float((settled * seconds).sum() / seconds.sum()), float(settled.mean())
    return {"takes": takes, "idle_m_s": round(idle, 4),
            "real_settled_m_s": {"pooled_by_time": round(pooled, 4), "mean_of_takes": round(per_take, 4)},
            "real_over_idle": {"pooled_by_time": round(pooled / idle, 2), "mean_of_takes": round(per_take / idle, 2)},
            "long_pause_s": LONG_PAUSE_S, "settled_after_s": SETTLED_AFTER_S, "joints": list(SHARED_JOINTS)}


def run_bench(args: argparse.Namespace) -> int:
    seeds = parse_seeds(args.seeds)
    takes = real_takes(args.cache, load_bundle(args.bundle) if seeds else None, seeds)
    print(json.dumps(idle_report(takes, idle_speed()), indent=1))
    return 0
