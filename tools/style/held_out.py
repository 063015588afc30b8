"""The fitted stylizer checked on actions it never saw, by a judge that never saw them (``style-fit``'s
``held_out_actions``).

The actions with takes in every judged style are split into two folds (alternately, by name). For each fold, the
stylizer is fitted (and calibrated) on the other fold's takes and the judge trained on the other fold's real takes;
the stylizer then re-performs each held-out action's neutral take in every judged style, and the judge reads that
set as it reads a speech's (``judge.centred``). Reported: the per-style share of windows judged as the style, with
and without the calibration, and the FK distance (``descriptors.clip_descriptor``) of each re-performed take to the
real take of that action in that style, mean over the (action, style) cases.
"""

from __future__ import annotations

import numpy as np

from gesturecast.models.style.descriptors import clip_descriptor, style_distance, window_features
from gesturecast.models.style.judge import JUDGED_STYLES, StyleJudge, centred
from gesturecast.tools.style.calibrate import calibrate
from gesturecast.tools.style.fit import fit_styles, restyled_rotations
from gesturecast.tools.style.judge_fit import accuracy_report, fit_judge
from gesturecast.tools.style.takes import NEUTRAL, Take


def _complete_actions(takes: list[Take], styles: tuple[str, ...]) -> list[str]:
    return sorted(content for content in {take.content for take in takes}
                  if {take.style for take in takes if take.content == content} >= set(styles))


def _first(takes: list[Take], content: str, style: str) -> Take:
    return next(take for take in takes if take.content == content and take.style == style)


def _judge_fold(takes: list[Take], fold: set[str], styles_by_variant: dict, judge: StyleJudge, confusions: dict,
                distances: dict) -> None:
    """Adds the fold's held-out actions to each variant's confusion (L, L) and FK distances."""
    for content in sorted(fold):
        neutral = _first(takes, content, NEUTRAL)
        for variant, styles in styles_by_variant.items():
            rotations = [restyled_rotations(neutral, styles[style].values) for style in judge.labels]
            features = [window_features(r, neutral.motion.root_position, neutral.motion.fps) for r in rotations]
            for label, windows in enumerate(centred(features)):
                np.add.at(confusions[variant][label], np.argmax(judge.probabilities(windows), axis=1), 1)
            for style, r in zip(judge.labels, rotations, strict=True):
                real = _first(takes, content, style).motion
                distances[variant].append(style_distance(clip_descriptor(r, neutral.motion.root_position, real.fps),
                                                         clip_descriptor(real.rotations, real.root_position,
                                                                         real.fps)))


def held_out_actions(takes: list[Take], styles: tuple[str, ...] = JUDGED_STYLES) -> dict:
    """Per variant (``median``: as fitted, ``calibrated``) the held-out judge report and FK distance, over the
    actions with takes in every one of ``styles`` (``neutral`` first); none when fewer than two have."""
    actions = _complete_actions(takes, styles)
    if len(actions) < 2:
        return {"actions": actions, "skipped": "fewer than two actions have takes in every judged style"}
    variants = ("median", "calibrated")
    confusions = {v: np.zeros((len(styles), len(styles)), dtype=int) for v in variants}
    distances: dict[str, list[float]] = {v: [] for v in variants}
    for fold in (set(actions[0::2]), set(actions[1::2])):
        train = [take for take in takes if take.content not in fold]
        median, _ = fit_styles(train)
        judge, _ = fit_judge(train, styles)
        _judge_fold(takes, fold, {"median": median, "calibrated": calibrate(median, train)[0]}, judge, confusions,
                    distances)
    out = {}
    for variant in variants:
        report = accuracy_report(confusions[variant], styles)
        out[variant] = {"judge": {key: report[key] for key in ("per_style", "mean")},
                        "fk_distance_to_real": round(float(np.mean(distances[variant])), 3)}
    return {**out, "actions": actions}
