"""Train the style judge (``gesturecast.models.style.judge``) so that it must generalise across content.

Every take of a judged style gives its windows' features, centred and scaled on its action (the judge reads how
the styles of one action differ: ``judge.centred``; actions with takes in fewer than three of the judged styles
are left out). Accuracy is measured leave-one-content-out: for each
action (bow, bye, walk …) a judge trained on the other actions labels the held-out action's windows; the
per-style accuracy is the share of a style's held-out windows labelled with it. The shipped judge is then trained
on every action.
"""

from __future__ import annotations

import numpy as np

from gesturecast.models.style.descriptors import window_features
from gesturecast.models.style.judge import JUDGED_STYLES, MIN_STYLES, StyleJudge, centred, train_judge
from gesturecast.tools.style.takes import Take

Rows = list[tuple[str, int, np.ndarray]]  # (content, style index, window features (W, F))


def judge_rows(takes: list[Take], styles: tuple[str, ...] = JUDGED_STYLES) -> Rows:
    """The centred window features of every take of a judged style, with its content and style index; contents with
    takes in fewer than ``MIN_STYLES`` of the styles have no reference and are left out."""
    judged = [take for take in takes if take.style in styles]
    features = [window_features(take.motion.rotations, take.motion.root_position, take.motion.fps) for take in judged]
    rows: Rows = []
    for content in sorted({take.content for take in judged}):
        mine = [k for k, take in enumerate(judged) if take.content == content]
        if len({judged[k].style for k in mine}) < MIN_STYLES:
            continue
        for k, centred_features in zip(mine, centred([features[k] for k in mine]), strict=True):
            rows.append((content, styles.index(judged[k].style), centred_features))
    return rows


def _fit(rows: Rows, styles: tuple[str, ...]) -> StyleJudge:
    features = np.concatenate([f for _, _, f in rows])  # (W, F)
    labels = np.concatenate([np.full(len(f), label) for _, label, f in rows])  # (W,)
    return train_judge(features, labels, styles)


def held_out_content_confusion(rows: Rows, styles: tuple[str, ...] = JUDGED_STYLES) -> np.ndarray:
    """(L, L) window counts [true style, judged style] over every action held out in turn."""
    confusion = np.zeros((len(styles), len(styles)), dtype=int)
    for content in sorted({content for content, _, _ in rows}):
        judge = _fit([row for row in rows if row[0] != content], styles)
        for _, label, features in (row for row in rows if row[0] == content):
            np.add.at(confusion[label], np.argmax(judge.probabilities(features), axis=1), 1)
    return confusion


def accuracy_report(confusion: np.ndarray, styles: tuple[str, ...]) -> dict:
    """Per-style accuracy (the confusion's diagonal share of each row), their mean, chance, the confusion."""
    per_style = np.diag(confusion) / np.maximum(confusion.sum(axis=1), 1)
    return {"per_style": {name: round(float(a), 3) for name, a in zip(styles, per_style, strict=True)},
            "mean": round(float(per_style.mean()), 3), "chance": round(1.0 / len(styles), 3),
            "windows_per_style": confusion.sum(axis=1).tolist(), "confusion": confusion.tolist()}


def fit_judge(takes: list[Take], styles: tuple[str, ...] = JUDGED_STYLES) -> tuple[StyleJudge, dict]:
    """The judge trained on every action, and its leave-one-content-out accuracy on the real takes (over the
    ``styles`` that have takes)."""
    styles = tuple(style for style in styles if any(take.style == style for take in takes))
    rows = judge_rows(takes, styles)
    report = accuracy_report(held_out_content_confusion(rows, styles), styles)
    report["contents"] = len({content for content, _, _ in rows})
    return _fit(rows, styles), report
