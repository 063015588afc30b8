"""Training the speech-act classifier: marked sentences → candidates with labels → softmax regression (numpy).

A sentence marks intended gestures with ``[gesture]`` before a word (:func:`parse_marked`). Its candidate phrases
(:func:`gesturecast.realtime.gestures.speech_acts.candidates`) take the intent of the gesture marked on their
first word, or "none". Candidates a rule already decides are left out (the rules answer for them at run time).
The model is fitted by full-batch Adam on the class-balanced cross-entropy with an L2 penalty; a seeded fifth of
the sentences is held back and its accuracy reported.
"""

from __future__ import annotations

import random
import re
from dataclasses import dataclass

import numpy as np

from gesturecast.realtime.gestures.speech_acts import (
    CLASSES,
    MARKS,
    Embedder,
    SpeechActModel,
    candidates,
    features,
    rule,
    tokenize,
)

MARK = re.compile(r"\[([a-z-]+)\]")


@dataclass(frozen=True)
class TrainConfig:
    steps: int = 1500
    learning_rate: float = 0.05
    l2: float = 1e-4
    held_out: float = 0.2
    seed: int = 0


def parse_marked(sentence: str) -> tuple[list[str], dict[int, str]]:
    """``"[wave]Hi, [bow]thanks!"`` → (words ``["Hi,", "thanks!"]``, {word index: gesture})."""
    words, marks = [], {}
    for token in sentence.split():
        match = MARK.match(token)
        if match:
            marks[len(words)] = match.group(1)
            token = token[match.end():]
        words.append(token)
    return words, marks


def examples(embed: Embedder, sentences: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """(n, F) features and (n,) class indices of every candidate a rule leaves open."""
    rows, labels = [], []
    for sentence in sentences:
        words, marks = parse_marked(sentence)
        tokens = tokenize(words)
        found = [c for c in candidates(tokens) if rule(tokens, c) is None]
        for candidate in found:
            gesture = marks.get(tokens[candidate.start].word)
            labels.append(CLASSES.index(MARKS[gesture]) if gesture else 0)
        rows.append(features(embed, tokens, words, found))
    return np.concatenate(rows), np.array(labels)


def fit(x: np.ndarray, y: np.ndarray, config: TrainConfig) -> SpeechActModel:
    """Softmax regression on (n, F) → (n,) labels (Adam, class-balanced cross-entropy, L2)."""
    n, f = x.shape
    k = len(CLASSES)
    counts = np.bincount(y, minlength=k).astype(np.float64)
    sample_weight = (n / (k * np.maximum(counts, 1)))[y] / n  # (n,)
    onehot = np.eye(k)[y]  # (n, k)
    params = [np.zeros((f, k)), np.zeros(k)]
    moments = [[np.zeros_like(p), np.zeros_like(p)] for p in params]
    for step in range(1, config.steps + 1):
        model = SpeechActModel(params[0], params[1])
        error = (model.probabilities(x) - onehot) * sample_weight[:, None]  # (n, k)
        grads = [x.T @ error + config.l2 * params[0], error.sum(axis=0)]
        for p, g, (m, v) in zip(params, grads, moments, strict=True):
            m[:] = 0.9 * m + 0.1 * g
            v[:] = 0.999 * v + 0.001 * g * g
            p -= config.learning_rate * (m / (1 - 0.9**step)) / (np.sqrt(v / (1 - 0.999**step)) + 1e-8)
    return SpeechActModel(params[0].astype(np.float32), params[1].astype(np.float32))


def train(sentences: list[str], config: TrainConfig = TrainConfig(), embed: Embedder | None = None
          ) -> tuple[SpeechActModel, dict]:
    """(model fitted on all sentences, {examples, held-out accuracy of a fit on the rest})."""
    embed = embed or Embedder()
    order = list(range(len(sentences)))
    random.Random(config.seed).shuffle(order)
    cut = int(len(order) * config.held_out)
    held = [sentences[i] for i in order[:cut]]
    kept = [sentences[i] for i in order[cut:]]
    x_kept, y_kept = examples(embed, kept)
    x_held, y_held = examples(embed, held)
    check = fit(x_kept, y_kept, config)
    accuracy = float(np.mean(check.probabilities(x_held).argmax(axis=1) == y_held))
    x_all, y_all = np.concatenate([x_kept, x_held]), np.concatenate([y_kept, y_held])
    counts = {name: int(c) for name, c in zip(CLASSES, np.bincount(y_all, minlength=len(CLASSES)), strict=True)}
    return fit(x_all, y_all, config), {"examples": counts, "held_out_accuracy": accuracy}
