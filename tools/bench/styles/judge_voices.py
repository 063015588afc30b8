"""``bench styles``'s ``judge_voices``: the style judge on more held-out speech than one clip.

The ``stylizer`` section judges one held-out clip (ZeroEGGS Flirty, acted read speech with long pauses). Here the
judge also reads every held-out recording of ``bench voices``' voice set (``tools/bench/speech/voice_set.py``, written
down before any choice was made on it) of the groups :data:`GROUPS`: six English TTS voices, three TTS voices in
other languages and three spontaneous talk-show speakers (the Flirty spans and the channel copies are left out: they
repeat the clip above). Each recording is generated in every judged style with every seed, at the default settings,
and judged as one set per seed, as the clip above is. Reported: per group and pooled over the recordings, the
per-style share of windows judged as the style asked for and their mean; and ``with_clip``: pooled with the clip
above, every window counting once.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gesturecast.models.motion.motion import MOTION_FPS
from gesturecast.models.runtime.bundle import ModelBundle
from gesturecast.models.style.judge import JUDGED_STYLES, StyleJudge
from gesturecast.tools.bench.speech.voice_set import HELD_OUT, SPONTANEOUS, TTS_EN, TTS_OTHER, voice_audio
from gesturecast.tools.eval.clips import EvalClip

GROUPS = (TTS_EN, TTS_OTHER, SPONTANEOUS)
Hits = dict[str, list[bool]]  # style -> one entry per judged window


def judged_windows(clips: dict, seeds: tuple[int, ...], judge: StyleJudge) -> Hits:
    """Per style, whether each window of each seed's set of styled clips ((style, seed) -> Generated) reads as it."""
    hits: Hits = {style: [] for style in JUDGED_STYLES}
    for seed in seeds:
        sets = [(clips[(style, seed)].rotations, clips[(style, seed)].positions[:, 0]) for style in JUDGED_STYLES]
        for style, labels in zip(JUDGED_STYLES, judge.judge_set(sets, MOTION_FPS), strict=True):
            hits[style].extend(label == style for label in labels)
    return hits


def scores(per_style: dict[str, float]) -> dict:
    """Per-style accuracies (rounded), their mean and the lowest."""
    return {"per_style": {style: round(value, 3) for style, value in per_style.items()},
            "mean": round(float(np.mean(list(per_style.values()))), 3), "min": round(min(per_style.values()), 3)}


def accuracy(hits: Hits) -> dict:
    """Per-style share of windows read right, their mean and the lowest."""
    return scores({style: float(np.mean(values)) for style, values in hits.items()})


def merged(parts: list[Hits]) -> Hits:
    return {style: [hit for part in parts for hit in part[style]] for style in JUDGED_STYLES}


def judge_on_voices(bundle: ModelBundle, shared: Path, seeds: tuple[int, ...], judge: StyleJudge, generate,
                    clip_hits: Hits) -> dict:
    """The section (module docstring); ``generate(bundle, clip, seeds)`` gives the styled clips of one speech."""
    by_group: dict[str, list[Hits]] = {group: [] for group in GROUPS}
    names = []
    for item in voice_audio(HELD_OUT, shared):
        if item.voice.group in GROUPS:
            clips = generate(bundle, EvalClip(item.voice.name, item.heard, "neutral"), seeds)
            by_group[item.voice.group].append(judged_windows(clips, seeds, judge))
            names.append(item.voice.name)
    every = [hits for group in GROUPS for hits in by_group[group]]
    return {"voices": names, "groups": {group: accuracy(merged(parts)) for group, parts in by_group.items()},
            "pooled": accuracy(merged(every)), "with_clip": accuracy(merged([*every, clip_hits]))}
