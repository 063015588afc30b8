"""The stylizer: re-performs the generator's motion in the style in effect, causally, frame by frame.

The generator decides *what* to do and *when* from the speech; the stylizer decides *how*: posture, gesture
amplitude per joint, tempo and tension, tremor (``gesturecast.models.style.params``, fitted from the Bandai takes
by ``gesturecast style-fit``). It runs after the idle cross-fade, on every pose frame, so a style also holds in
silence. The legs and hips are never touched.

Every way to give a style reaches it:

- a label of the fitted book (``neutral``, ``happy``, ``old`` …, or a synonym) takes its fitted parameters
  (``neutral``: none);
- a label only the generator knows (the paired speech takes' styles: ``speech``, ``flirty``, ``sarcastic`` …) is
  left to the generator, which learned it with speech and hears it itself (``StyleHearing.own_labels``):
  no change here;
- any other prompt (free text, a motion clip) is placed in the style space the generator's style resolver embeds it
  in, and takes the book's styles weighted by a softmax (temperature :data:`SIMILARITY_TEMPERATURE`) of its cosine
  similarity to each book label's embedding;
- a γ mix of two styles mixes their parameters the same way (γ·P₁ + (1 − γ)·P₂, γ > 1 extrapolates);
- per-part styles give each body part's joints the parameters of its own prompt;
- the strength k (``style_strength``, 0..2) scales the change; at k = 0 the frames leave bit for bit as they came.

Whatever the mix, parts and strength, the styled joints are then kept within a human range, softly
(:mod:`gesturecast.models.style.joint_limits`): a γ of −2 or a doubled style bends a body no further than people do.

A change of style or strength moves the parameters over :data:`DEFAULT_RAMP_S` (smoothstep) from the frame it
first applies to. The state (the filter's centre and low-pass) always follows the input and depends only on the
frames in order, so a stream gives the same bits whatever its chunking, live or offline.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from gesturecast.models.generator.style_prompt import PartStyles, StylePrompt
from gesturecast.models.generator.styles import canonical_style
from gesturecast.models.style.joint_limits import JointRanges
from gesturecast.models.style.params import (
    StyleBook,
    StyleFilter,
    StyleParams,
    mix,
    part_rows,
    rotation_vectors,
    with_rotation_vectors,
)
from gesturecast.realtime.pose.idle import IdleConfig, relaxed_pose
from gesturecast.realtime.pose.transitions import DEFAULT_RAMP_S, Ramp

SIMILARITY_TEMPERATURE = 0.1
Embed = Callable[[StylePrompt], np.ndarray]  # a prompt -> (E,) embedding in the generator's style space


class StyleCodes:
    """A style prompt → the book's parameters (module docstring), cached per prompt."""

    def __init__(self, book: StyleBook, embed: Embed) -> None:
        self.book = book
        self._embed = embed
        self._labels: np.ndarray | None = None  # (L, E) unit embeddings of the book's labels
        self._cache: dict[StylePrompt, StyleParams] = {}

    def params(self, prompt: StylePrompt) -> StyleParams:
        if prompt not in self._cache:
            self._cache[prompt] = self._resolve(prompt)
        return self._cache[prompt]

    def weights(self, prompt: StylePrompt) -> np.ndarray:
        """(L,) weights of the book's labels (in ``book.labels`` order) for a prompt outside the book."""
        if self._labels is None:
            self._labels = np.stack([_unit(self._embed(StylePrompt("label", label))) for label in self.book.labels])
        similarity = self._labels @ _unit(self._embed(prompt))  # (L,)
        scores = np.exp((similarity - similarity.max()) / SIMILARITY_TEMPERATURE)
        return scores / scores.sum()

    def _resolve(self, prompt: StylePrompt) -> StyleParams:
        if prompt.kind == "label":
            self._embed(prompt)  # refuses a label the generator does not know
            fitted = self.book.get(canonical_style(prompt.value))
            return StyleParams.identity() if fitted is None else fitted
        weights = self.weights(prompt)
        return mix([self.book.styles[label] for label in self.book.labels], weights.tolist())


def _unit(vector: np.ndarray) -> np.ndarray:
    return np.asarray(vector, dtype=np.float64) / max(float(np.linalg.norm(vector)), 1e-12)


class Stylizer:
    """One stream's stylizer: :meth:`set_style` then :meth:`apply` on its pose frames, in stream order."""

    def __init__(self, codes: StyleCodes, fps: float, fade_s: float = DEFAULT_RAMP_S,
                 ranges: JointRanges | None = None) -> None:
        self.codes = codes
        self.fps = fps
        self.fade_s = fade_s
        self.ranges = ranges or JointRanges.load()
        self.filter = StyleFilter(fps, rotation_vectors(relaxed_pose(IdleConfig())))
        self.reset()

    @staticmethod
    def from_file(path: Path, embed: Embed, fps: float) -> Stylizer:
        return Stylizer(StyleCodes(StyleBook.load(path), embed), fps)

    def reset(self) -> None:
        """A new stream: no state, the next style applies at once."""
        self.filter.reset()
        self._ramp: Ramp | None = None

    def target(self, style: StylePrompt, second: StylePrompt | None, gamma: float, parts: PartStyles,
               strength: float) -> np.ndarray:
        """The (S, CHANNELS) parameters of a style request (module docstring)."""
        params = self.codes.params(style)
        if second is not None:
            params = mix([params, self.codes.params(second)], [gamma, 1.0 - gamma])
        values = params.values.copy()
        for part, prompt in parts:
            rows = part_rows(part)
            values[rows] = self.codes.params(prompt).values[rows]
        return StyleParams(values).scaled(strength).values

    def set_style(self, values: np.ndarray, t: float) -> None:
        """Move to the parameters ``values`` (S, CHANNELS) from stream time ``t`` (at once on the first call)."""
        if self._ramp is None:
            self._ramp = Ramp(values, self.fade_s, t)
        elif not np.array_equal(values, self._ramp.target):
            self._ramp.set_target(values, t)

    def apply(self, rotations: np.ndarray, times: np.ndarray) -> np.ndarray:
        """Styled canonical rotations (n, J, 4) of frames (n, J, 4) at stream times (n,), in order."""
        values = np.stack([self._ramp.value(float(t)) for t in times])  # (n, S, CHANNELS)
        given = rotation_vectors(rotations)  # (n, S, 3)
        styled = self.ranges.limit(self.filter.run(given, values, times), given)  # (n, S, 3)
        changed = values.reshape(len(times), -1).any(axis=1)  # (n,) frames with a style to show
        if not changed.any():
            return rotations
        out = rotations.copy()
        out[changed] = with_rotation_vectors(rotations[changed], styled[changed])
        return out
