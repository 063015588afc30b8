"""The fitted stylizer against a small learned one, on actions neither has seen (``style-fit --compare-learned``).

The actions are split into two folds (alternately, by name). For each fold, both stylizers learn from the other
fold's takes: the fitted one (``fit.fit_styles``) and the causal residual network of
``gesturecast.models.training.stylizer_net`` (one per seed). Each then re-performs every held-out neutral take in
every style, and the result is compared with the real take of that action in that style on the FK measure of
``bench styles`` (``descriptors.clip_descriptor``): the distance of the two descriptors, averaged over every held-out
(action, style). ``unchanged`` is the same distance for the neutral take itself: what doing nothing scores.
"""

from __future__ import annotations

import time

import numpy as np

from gesturecast.models.style.descriptors import clip_descriptor, style_distance
from gesturecast.models.style.params import STYLED_INDEX, rotation_vectors, with_rotation_vectors
from gesturecast.tools.style.fit import fit_styles, restyled_rotations
from gesturecast.tools.style.takes import NEUTRAL, Take


def _with_styled(take: Take, vectors: np.ndarray) -> np.ndarray:
    """The take's rotations (T, J, 4) with its styled joints set to rotation vectors (T, S, 3)."""
    return with_rotation_vectors(take.motion.rotations, vectors)


def _distance(take: Take, rotations: np.ndarray, real: Take) -> float:
    return style_distance(clip_descriptor(rotations, take.motion.root_position, take.motion.fps),
                          clip_descriptor(real.motion.rotations, real.motion.root_position, real.motion.fps))


def _cases(takes: list[Take], contents: set[str]) -> list[tuple[Take, Take]]:
    """(neutral take, styled take) of every action in ``contents`` and every style it has."""
    neutral = {take.content: take for take in takes if take.style == NEUTRAL and take.content in contents}
    return [(neutral[take.content], take) for take in takes
            if take.content in neutral and take.style != NEUTRAL and take is not neutral[take.content]]


def _fitted(train: list[Take], cases: list[tuple[Take, Take]]) -> list[float]:
    styles, _ = fit_styles(train)
    out = []
    for neutral, real in cases:
        out.append(_distance(neutral, restyled_rotations(neutral, styles[real.style].values), real))
    return out


def _learned(train: list[Take], cases: list[tuple[Take, Take]], labels: list[str], seed: int, steps: int
             ) -> list[float]:
    from gesturecast.models.training.stylizer_net import resample, stylize, train_stylizer

    def flat(take: Take) -> np.ndarray:
        return rotation_vectors(take.motion.rotations).reshape(take.motion.num_frames, -1)  # (T, S·3)

    pairs = [(flat(n), resample(flat(s), len(flat(n))), labels.index(s.style)) for n, s in _cases(train, {
        take.content for take in train})]
    model = train_stylizer(pairs, len(labels), seed, steps)
    out = []
    for neutral, real in cases:
        styled = stylize(model, flat(neutral), labels.index(real.style)).reshape(-1, len(STYLED_INDEX), 3)
        out.append(_distance(neutral, _with_styled(neutral, styled), real))
    return out


def compare_stylizers(takes: list[Take], seeds: tuple[int, ...] = (0, 1), steps: int = 1500) -> dict:
    """Held-out FK distance to the real styled takes: unchanged, fitted, learned per seed with ``steps`` Adam steps
    (module docstring)."""
    contents = sorted({take.content for take in takes})
    labels = sorted({take.style for take in takes if take.style != NEUTRAL})
    scores: dict[str, list[float]] = {"unchanged": [], "fitted": [], **{f"learned_seed{s}": [] for s in seeds}}
    started = time.perf_counter()
    for fold in (set(contents[0::2]), set(contents[1::2])):
        train = [take for take in takes if take.content not in fold]
        cases = _cases(takes, fold)
        scores["unchanged"] += [_distance(n, n.motion.rotations, s) for n, s in cases]
        scores["fitted"] += _fitted(train, cases)
        for seed in seeds:
            scores[f"learned_seed{seed}"] += _learned(train, cases, labels, seed, steps)
    return {"held_out_fk_distance": {name: round(float(np.mean(values)), 3) for name, values in scores.items()},
            "cases": len(scores["unchanged"]), "seconds": round(time.perf_counter() - started, 1)}
