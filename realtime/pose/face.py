"""The face besides the mouth: blinks, and an expression that follows the style.

**Blinks.** The gaps between blinks are drawn from a gamma distribution (shape :data:`GAP_SHAPE`) whose mean gives
about 17 blinks a minute at rest and 11 while speaking (people blink less while they talk and more in the
pauses). A pause after speech (the voice-activity flag falling, a phrase boundary) brings the next blink forward
to the pause when it is due within :data:`PAUSE_PULL_S` and the last blink is at least :data:`MIN_GAP_S` ago, so
blinks gather at the pauses without becoming more frequent. Each blink lasts 100–150 ms: the lid closes in the
first 35 %, stays shut for 20 % and opens in the rest (smoothstep), and one blink in eight is followed by a second
after 150–250 ms. Both eyes blink together (``Blink``; ``Blink_L`` / ``Blink_R`` carry the same weight for
receivers that drive each eye).

**Expression.** A style label maps to weights of the five emotion presets (:data:`LABEL_EXPRESSIONS`: "happy"
smiles, "angry" frowns, "old" and "tired" look a little sad); free text gets them from the packaged text
embedding, by its cosine similarity to each preset's name: none at :data:`TEXT_SIMILARITY_FLOOR`, the most a
label gives (:data:`TEXT_WEIGHT`) at :data:`TEXT_SIMILARITY_FULL` ("cheerful" smiles, "furious" frowns,
"shocked" looks surprised; the small embedding has quirks: "calm and slow" is nearer "angry" than "relaxed");
a motion prompt gets none. A γ mix of two styles mixes their expressions. The weights are eased to a new style over
:data:`EXPRESSION_RAMP_S`.

**A face that lives** (:class:`ExpressionDynamics`). The style's weights are the face's range, not a preset held
still: emphasis is the frame's speech energy above the voice's running level (an average of :data:`LEVEL_S` over
speech), in units of :data:`EMPHASIS_DB`, 0..1. While speaking the intensity rises with emphasis
(:data:`SPEAKING_LEVEL` + :data:`EMPHASIS_GAIN` × emphasis, reached within :data:`ATTACK_S`); in pauses it eases
down to :data:`PAUSE_LEVEL` over :data:`RELEASE_S`. On top: a smile grows at each phrase end (the voice stopping;
:data:`PHRASE_END_SMILE`, fading over :data:`PHRASE_END_S`), a frown deepens on stressed words (the angry preset
also follows emphasis, :data:`STRESS_FROWN`), and the brows lift on emphasis (the surprised preset,
:data:`BROW_LIFT`, less under a frown). Each style blinks at its own rate and length (:data:`STYLE_BLINKS`: a tired
face blinks slower and longer, an angry one stares).

Everything is a function of stream time, the frames' voice-activity flags and speech energy, and the seed, drawn in
frame order: streaming and offline runs give the same face. Weights are in the order of
:data:`gesturecast.frames.FACE_NAMES`.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from gesturecast.frames import EXPRESSION_PRESETS
from gesturecast.models.generator.style_prompt import StylePrompt
from gesturecast.realtime.generation.style_prompts import StyleResolver
from gesturecast.realtime.pose.transitions import Ramp, smoothstep
from gesturecast.settings import FACE_FULL

REST_BLINKS_PER_MIN = 17.0
SPEAKING_BLINKS_PER_MIN = 11.0
GAP_SHAPE = 4.0  # gamma shape of the gaps: regular but not periodic
MIN_GAP_S = 1.2  # a pause brings a blink forward only this long after the last one
PAUSE_PULL_S = 2.0  # ... and only when it was due within this time
BLINK_S = (0.10, 0.15)  # duration range
CLOSING_SHARE, SHUT_SHARE = 0.35, 0.2  # the lid closes in this share of the blink, then stays shut for this share
DOUBLE_CHANCE = 0.125
DOUBLE_GAP_S = (0.15, 0.25)
EXPRESSION_RAMP_S = 0.8
LEVEL_S = 3.0  # time constant of the voice's running energy level (over speech frames only)
EMPHASIS_DB = 6.0  # energy this far above the running level is full emphasis
SPEAKING_LEVEL, EMPHASIS_GAIN, PAUSE_LEVEL = 0.75, 0.5, 0.55  # expression intensity: speech, + emphasis, pauses
ATTACK_S, RELEASE_S = 0.08, 0.6  # time constants of the intensity rising and falling
PHRASE_END_S = 0.8  # a phrase end's smile fades with this time constant
PHRASE_END_SMILE = 0.4  # the happy preset × (1 + this) at a phrase end
STRESS_FROWN = 0.5  # the angry preset × (1 + this × emphasis)
BROW_LIFT = 0.25  # the surprised preset + this × emphasis (× (1 − the angry weight))
# style label -> (blink rate factor, blink length factor); labels not listed blink as usual
STYLE_BLINKS: dict[str, tuple[float, float]] = {
    "tired": (0.75, 1.8), "old": (0.9, 1.4), "sad": (0.9, 1.3), "pensive": (0.9, 1.2), "angry": (0.65, 0.9),
    "threatening": (0.65, 0.9), "proud": (0.8, 1.0), "happy": (1.15, 1.0), "scared": (1.4, 0.9),
}
HAPPY, ANGRY, SURPRISED = (EXPRESSION_PRESETS.index(name) for name in ("happy", "angry", "surprised"))
TEXT_SIMILARITY_FLOOR = 0.25  # free text: cosine similarity to a preset's name at or below this gives no weight
TEXT_SIMILARITY_FULL = 0.5  # ... and from this on the full TEXT_WEIGHT
TEXT_WEIGHT = 0.7
BLINK_SHAPES = 3  # Blink, Blink_L, Blink_R come first in FACE_NAMES

# style label -> weights of (happy, angry, sad, relaxed, surprised); labels not listed keep a neutral face
LABEL_EXPRESSIONS: dict[str, tuple[float, float, float, float, float]] = {
    "happy": (0.7, 0.0, 0.0, 0.0, 0.1),
    "laughing": (1.0, 0.0, 0.0, 0.0, 0.0),
    "childish": (0.5, 0.0, 0.0, 0.0, 0.2),
    "flirty": (0.4, 0.0, 0.0, 0.3, 0.0),
    "proud": (0.35, 0.0, 0.0, 0.1, 0.0),
    "active": (0.3, 0.0, 0.0, 0.0, 0.1),
    "musical": (0.3, 0.0, 0.0, 0.2, 0.0),
    "agreement": (0.3, 0.0, 0.0, 0.1, 0.0),
    "angry": (0.0, 0.8, 0.0, 0.0, 0.0),
    "threatening": (0.0, 0.6, 0.0, 0.0, 0.0),
    "chimpira": (0.0, 0.5, 0.0, 0.0, 0.0),
    "disagreement": (0.0, 0.4, 0.1, 0.0, 0.0),
    "sarcastic": (0.2, 0.2, 0.0, 0.0, 0.0),
    "sad": (0.0, 0.0, 0.8, 0.0, 0.0),
    "tired": (0.0, 0.0, 0.35, 0.2, 0.0),
    "old": (0.0, 0.0, 0.2, 0.2, 0.0),
    "not-confident": (0.0, 0.0, 0.4, 0.0, 0.1),
    "pensive": (0.0, 0.0, 0.3, 0.2, 0.0),
    "scared": (0.0, 0.0, 0.3, 0.0, 0.6),
    "distracted": (0.0, 0.0, 0.0, 0.2, 0.1),
    "relaxed": (0.1, 0.0, 0.0, 0.6, 0.0),
    "still": (0.0, 0.0, 0.0, 0.3, 0.0),
}

TextEmbedder = Callable[[list[str]], np.ndarray]  # texts -> (n, S) unit embeddings (the style text space)


def text_embedder(resolver: StyleResolver) -> TextEmbedder:
    """The style space's free-text embedding of a session's style resolver (holds no reference to the session)."""
    return lambda texts: np.stack([resolver.embed(StylePrompt("text", text)) for text in texts])


class Expressions:
    """A style prompt → (5,) emotion-preset weights (module docstring); free text needs ``embed_texts``."""

    def __init__(self, embed_texts: TextEmbedder | None = None) -> None:
        self._embed_texts = embed_texts
        self._presets: np.ndarray | None = None  # (5, S) embeddings of the preset names
        self._cache: dict[StylePrompt, np.ndarray] = {}

    def of(self, prompt: StylePrompt) -> np.ndarray:
        if prompt not in self._cache:
            self._cache[prompt] = self._weights(prompt)
        return self._cache[prompt]

    def _weights(self, prompt: StylePrompt) -> np.ndarray:
        if prompt.kind == "label":
            return np.array(LABEL_EXPRESSIONS.get(prompt.value, (0.0,) * len(EXPRESSION_PRESETS)))
        if prompt.kind != "text" or self._embed_texts is None:
            return np.zeros(len(EXPRESSION_PRESETS))
        if self._presets is None:
            self._presets = self._embed_texts(list(EXPRESSION_PRESETS))
        similarity = self._presets @ self._embed_texts([prompt.value])[0]  # (5,) cosine (unit embeddings)
        span = TEXT_SIMILARITY_FULL - TEXT_SIMILARITY_FLOOR
        return TEXT_WEIGHT * np.clip((similarity - TEXT_SIMILARITY_FLOOR) / span, 0.0, 1.0)


class Blinks:
    """Blink times and lid weights of one stream, drawn in frame order from a seeded generator."""

    def __init__(self, seed: int) -> None:
        self._rng = np.random.default_rng([seed, 0xB11C])
        self._blinks: list[tuple[float, float]] = []  # (start, duration) of blinks not yet over, in order
        self.rate_factor, self.length_factor = 1.0, 1.0  # the style's (STYLE_BLINKS), from the next blink on
        self._next = self._gap(speaking=False)  # start of the next blink
        self._last_start = -math.inf
        self._was_speaking = False

    def _gap(self, speaking: bool) -> float:
        rate = (SPEAKING_BLINKS_PER_MIN if speaking else REST_BLINKS_PER_MIN) * self.rate_factor
        return float(self._rng.gamma(GAP_SHAPE, 60.0 / rate / GAP_SHAPE))

    def weight(self, t: float, speaking: bool) -> float:
        """The lid's closure (0 open … 1 shut) at stream time ``t``; call once per frame, in order."""
        pause = self._was_speaking and not speaking
        self._was_speaking = speaking
        if pause and t - self._last_start >= MIN_GAP_S and t < self._next <= t + PAUSE_PULL_S:
            self._next = t  # a phrase boundary: blink in the pause
        if t >= self._next:
            self._start(t, speaking)
        self._blinks = [(start, length) for start, length in self._blinks if t < start + length]
        return max((_lid(t - start, length) for start, length in self._blinks), default=0.0)

    def _start(self, t: float, speaking: bool) -> None:
        length = float(self._rng.uniform(*BLINK_S)) * self.length_factor
        self._blinks.append((t, length))
        self._last_start = t
        if self._rng.random() < DOUBLE_CHANCE:
            second = t + length + float(self._rng.uniform(*DOUBLE_GAP_S))
            self._blinks.append((second, float(self._rng.uniform(*BLINK_S)) * self.length_factor))
            self._last_start = second
        self._next = self._last_start + self._gap(speaking)


def _lid(elapsed: float, length: float) -> float:
    """Closure ``elapsed`` seconds into a blink of ``length``: closing, shut, then opening (module docstring)."""
    if elapsed < 0.0:
        return 0.0
    closing, opening = CLOSING_SHARE * length, (CLOSING_SHARE + SHUT_SHARE) * length
    if elapsed < closing:
        return float(smoothstep(elapsed / closing))
    return float(1.0 - smoothstep((elapsed - opening) / (length - opening)))


class ExpressionDynamics:
    """How strongly the style's expression shows, frame by frame, from the voice (module docstring)."""

    def __init__(self) -> None:
        self._level: float | None = None  # running speech energy level (dB)
        self._intensity = PAUSE_LEVEL
        self._emphasis = 0.0  # smoothed like the intensity
        self._phrase_end = -math.inf
        self._was_speaking = False
        self._last_t: float | None = None

    def weights(self, base: np.ndarray, t: float, speaking: bool, energy_db: float) -> np.ndarray:
        """(5,) preset weights at stream time ``t`` from the style's (5,) ``base``; call once per frame, in order."""
        dt = 0.0 if self._last_t is None else t - self._last_t
        self._last_t = t
        if self._was_speaking and not speaking:
            self._phrase_end = t
        self._was_speaking = speaking
        emphasis = self._emphasis_of(energy_db, dt) if speaking else 0.0
        target = SPEAKING_LEVEL + EMPHASIS_GAIN * emphasis if speaking else PAUSE_LEVEL
        self._intensity = _follow(self._intensity, target, dt)
        self._emphasis = _follow(self._emphasis, emphasis, dt)
        out = base * self._intensity
        out[HAPPY] *= 1.0 + PHRASE_END_SMILE * math.exp(-(t - self._phrase_end) / PHRASE_END_S)
        out[ANGRY] *= 1.0 + STRESS_FROWN * self._emphasis
        out[SURPRISED] += BROW_LIFT * self._emphasis * (1.0 - min(out[ANGRY], 1.0))
        return np.clip(out, 0.0, 1.0)

    def _emphasis_of(self, energy_db: float, dt: float) -> float:
        """0..1: the energy above the voice's running level, which moves toward it over LEVEL_S of speech."""
        if self._level is None:
            self._level = energy_db
        self._level += (1.0 - math.exp(-dt / LEVEL_S)) * (energy_db - self._level)
        return float(np.clip((energy_db - self._level) / EMPHASIS_DB, 0.0, 1.0))


def _follow(value: float, target: float, dt: float) -> float:
    """One step of a first-order follower: fast up (ATTACK_S), slow down (RELEASE_S)."""
    time_constant = ATTACK_S if target > value else RELEASE_S
    return value + (1.0 - math.exp(-dt / time_constant)) * (target - value)


class FaceAnimator:
    """Per-stream face weights (FACE_NAMES order) for ``mode`` "blink" (lids only) or "full" (and expression)."""

    def __init__(self, mode: str, seed: int, expressions: Expressions) -> None:
        self.mode = mode
        self.expressions = expressions
        self._seed = seed
        self.reset()

    def reset(self) -> None:
        """A new stream: fresh blink draws, a neutral expression."""
        self.blinks = Blinks(self._seed)
        self._expression = Ramp(np.zeros(len(EXPRESSION_PRESETS)), EXPRESSION_RAMP_S)
        self.dynamics = ExpressionDynamics()

    def set_style(self, weights: np.ndarray, t: float, label: str | None = None) -> None:
        """Ease toward these (5,) preset weights from stream time ``t`` (no-op when they are already the target);
        blink as the style ``label`` does (STYLE_BLINKS; None or an unlisted label: as usual) from the next blink."""
        self.blinks.rate_factor, self.blinks.length_factor = STYLE_BLINKS.get(label or "", (1.0, 1.0))
        if self.mode == FACE_FULL and not np.array_equal(weights, self._expression.target):
            self._expression.set_target(weights, t)

    def frames(self, times: np.ndarray, speaking: list[bool], energy_db: list[float] | None = None) -> np.ndarray:
        """(n, 3 + 5) weights of the frames at stream times (n,) with their voice-activity flags and speech energy
        (dB; None: no emphasis), in order."""
        out = np.zeros((len(times), BLINK_SHAPES + len(EXPRESSION_PRESETS)))
        for k, t in enumerate(times):
            out[k, :BLINK_SHAPES] = self.blinks.weight(float(t), speaking[k])
            if self.mode == FACE_FULL:
                energy = 0.0 if energy_db is None else energy_db[k]
                out[k, BLINK_SHAPES:] = self.dynamics.weights(self._expression.value(float(t)), float(t), speaking[k],
                                                              energy)
        return out
