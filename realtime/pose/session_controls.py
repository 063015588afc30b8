"""Live changes of style, part styles, guidance, audio guidance, γ, root mode, gesture size and pause, blended in
over a short stream time (no pop).

Controls arrive from any thread (WebSocket clients, the CLI) and are applied by the session
between latent steps. Numbers (guidance s, audio guidance s_a, γ) move along a smoothstep ramp. A new style with no
second style is blended with DiffuseStyleGesture's own mechanism: the generator runs
x̂0 = γ·D(new) + (1 − γ)·D(old) while γ ramps 0 → 1, then drops the old style. While body parts have their own
prompts, style and part-style changes ramp the part mixture's channel weights W instead (a soft mask moving from
the old prompts' channels to the new ones, generation/style_mixture.py), then drop the prompts no channel uses. A
stream holds at most MAX_MIXTURE_ROWS style rows, also when part-style changes arrive faster than the fade. The gesture
size (``intensity``, 0 while paused) is handed to the pose frames of each latent, which ramp it in along the same
smoothstep (realtime/pose/gesture_size.py).
"""

from __future__ import annotations

import logging
import threading
from collections import deque
from dataclasses import replace

from gesturecast.controls import Control, Gesture, Sentence, StyleChange, Words
from gesturecast.log_throttle import ThrottledLog
from gesturecast.models.generator.style_prompt import PartStyles, StylePrompt, parse_part_styles
from gesturecast.models.motion.root_anchor import RootAnchor, RootMode
from gesturecast.realtime.generation.generator import Generator
from gesturecast.realtime.generation.style_mixture import align_mixtures, bound_blend_rows, drop_unused_rows
from gesturecast.realtime.gestures.cues import CueRefused
from gesturecast.realtime.gestures.director import GestureDirector
from gesturecast.realtime.gestures.lexicon import current_name
from gesturecast.realtime.pose.gesture_size import FULL_SIZE
from gesturecast.realtime.pose.style_hearing import StyleHearing, StyleState
from gesturecast.realtime.pose.transitions import DEFAULT_RAMP_S, Ramp
from gesturecast.settings import SINGLE_STYLE

logger = logging.getLogger(__name__)

MAX_PENDING_CONTROLS = 32  # bounded inbox: the oldest unapplied control is dropped first
# words a latent step decides speech acts for (about 1 ms a word on the stream's thread, out of a 133 ms latent):
# the words after them wait in the inbox for the next steps, in order (counted in ``deferred_word_steps``)
WORDS_PER_LATENT = 40
# style rows of one stream while part styles blend (each is a row of every denoiser call): a mixture of the default
# model's 3 body parts has at most 4 rows, so a blend from one full mixture to another fits; part-style controls
# faster than the fade fold the oldest rows in instead of growing the batch
MAX_MIXTURE_ROWS = 8


class SessionControls:
    """Holds the control inbox, the ramps and the stream's style (:class:`StyleState`); :meth:`advance` applies them
    at stream time ``t``. The generator is told what ``hearing`` makes of each change (realtime/pose/style_hearing.py),
    never the style itself."""

    def __init__(self, generator: Generator, root: RootAnchor, gestures: GestureDirector,
                 intensity: float = FULL_SIZE, paused: bool = False, fade_s: float = DEFAULT_RAMP_S,
                 style: StyleState | None = None, hearing: StyleHearing | None = None) -> None:
        self.generator = generator
        self.style = StyleState.of(generator.settings) if style is None else style  # the session's, from Settings
        self.hearing = StyleHearing() if hearing is None else hearing
        self.root = root
        self.gestures = gestures
        self.intensity = intensity
        self.paused = paused
        self.fade_s = fade_s
        self._inbox: deque[tuple[Control, ...]] = deque(maxlen=MAX_PENDING_CONTROLS)
        self._lock = threading.Lock()
        self._guidance = Ramp(generator.base_guidance, fade_s)
        self._style_strength = Ramp(self.style.strength, fade_s)
        self._audio_guidance = Ramp(generator.settings.audio_guidance, fade_s)
        self._gamma = Ramp(self.style.gamma, fade_s)
        self._blending_from: StylePrompt | None = None  # old style while a style change blends in
        self._mixture_ramp: Ramp | None = None  # W (R, C) flattened, while a part-style change blends in
        self._refused_log = ThrottledLog(logger)  # a flood of gestures into a full plan: a line per interval
        self.deferred_word_steps = 0  # words left queued by a step's :data:`WORDS_PER_LATENT`, summed over the steps

    def submit(self, controls: tuple[Control, ...]) -> dict:
        """Queue one message's typed controls (built by :func:`gesturecast.controls.parse_controls`, so their values
        are already checked), applied together at the next latent; thread-safe. What only the model can tell is
        checked here first (a gesture not in the lexicon, a style label or body part the model does not know), so
        one it cannot use raises UserError here (the caller answers the client) instead of failing the stream when
        applied. Returns what the ack may tell: for a gesture, about when its stroke shows
        (``{"gesture_stroke_in_ms": ...}``); else {}."""
        controls = tuple(self._by_current_name(control) for control in controls)
        notes = {}
        for control in controls:
            self._check(control)
            if isinstance(control, Gesture):
                notes["gesture_stroke_in_ms"] = round(self.gestures.stroke_lead_s() * 1e3)
        with self._lock:
            self._inbox.append(tuple(controls))
        return notes

    def _by_current_name(self, control: Control) -> Control:
        """A gesture control naming a renamed shipped gesture by its old name (``bye``) names it as it is called
        now (``hand-up``)."""
        if not isinstance(control, Gesture):
            return control
        return Gesture(current_name(control.name, self.gestures.names))

    def _check(self, control: Control) -> None:
        if isinstance(control, Gesture):
            self.gestures.check_gesture(control.name)
        elif isinstance(control, Words):
            self.gestures.check_lexicon()
            self.gestures.check_live_words(control.words)
        elif isinstance(control, Sentence):
            self.gestures.check_lexicon()
        else:
            for prompt in _prompts_of(control):
                self.generator.styles.embed(prompt)
            if control.part_styles is not None:
                parts = parse_part_styles(control.part_styles)
                self.generator.part_mixture(self.style.style, parts)  # unknown body parts
                for _, prompt in parts:  # unknown styles (e.g. a misspelt label) inside part_styles
                    self.generator.styles.embed(prompt)

    def advance(self, t: float) -> None:
        """Apply queued controls and move the ramps to stream time ``t`` (called once per latent)."""
        for control in self._take(WORDS_PER_LATENT):
            self._apply(control, t)
        self._update_style_blend(t)
        self._update_mixture_blend(t)
        guidance = float(self._guidance.value(t))
        if guidance != self.generator.base_guidance:
            self.generator.set_guidance(guidance)
        strength = float(self._style_strength.value(t))
        if strength != self.style.strength:
            self.style = replace(self.style, strength=strength)
            self.generator.set_style_strength(self.heard.strength)
        audio_guidance = float(self._audio_guidance.value(t))
        if audio_guidance != self.generator.settings.audio_guidance:
            self.generator.set_audio_guidance(audio_guidance)
        if self._blending_from is None and self.style.second_style is not None:
            self._set_gamma(float(self._gamma.value(t)))

    @property
    def gesture_size(self) -> float:
        """The size of the body's motion around the idle pose in effect: the intensity, 0 while paused."""
        return 0.0 if self.paused else self.intensity

    def _take(self, word_budget: int) -> list[Control]:
        """The queued controls, in order, up to ``word_budget`` words: a words control past the budget is split and
        its later words, with the rest of the inbox, stay queued for the next steps."""
        taken: list[Control] = []
        with self._lock:
            while self._inbox:
                message = self._inbox.popleft()
                for index, control in enumerate(message):
                    count = len(control.words) if isinstance(control, Words) else 0
                    if count > word_budget:
                        taken.append(Words(control.words[:word_budget]))
                        self._inbox.appendleft((Words(control.words[word_budget:]), *message[index + 1 :]))
                        self.deferred_word_steps += sum(_word_count(queued) for queued in self._inbox)
                        return taken
                    word_budget -= count
                    taken.append(control)
        return taken

    def describe(self) -> str:
        """The style in effect, for display (``happy``, ``text:calm``, ``happy→sad γ=0.5``)."""
        style = self.style
        name = _prompt_name(style.style)
        if style.part_styles:
            name += " " + " ".join(f"{part}={_prompt_name(prompt)}" for part, prompt in style.part_styles)
        if style.second_style is None or self._blending_from is not None:
            return name
        return f"{name}→{_prompt_name(style.second_style)} γ={style.gamma:.2f}"

    def _apply(self, control: Control, t: float) -> None:
        if isinstance(control, StyleChange):
            self._apply_style(control, t)
            return
        try:
            if isinstance(control, Gesture):  # as soon as possible: its stroke as early as it can be from this latent
                self.gestures.cue_gesture(control.name, t)
            elif isinstance(control, Sentence):  # placed on its own speech once that has arrived
                self.gestures.hear_sentence(control.text, control.start, control.end, wait=False)
            else:  # on the words' own stream times (late by the wait when already generated)
                self.gestures.hear_words(control.words, wait=False)
        except CueRefused as error:  # the plan filled up since the submit: the stream goes on without them
            self._refused_log.log(logging.WARNING, f"gesture cues not kept: {error}")

    def _apply_style(self, change: StyleChange, t: float) -> None:
        if change.root is not None:
            self.root.set_mode(RootMode(change.root))  # re-anchored where the avatar stands: no jump
        if change.intensity is not None:
            self.intensity = change.intensity
        if change.pause is not None:
            self.paused = change.pause
        for value, ramp in ((change.guidance, self._guidance), (change.style_strength, self._style_strength),
                            (change.audio_guidance, self._audio_guidance), (change.gamma, self._gamma)):
            if value is not None:
                ramp.set_target(float(value), t)
        new_style = _style_from_control(change)
        if change.part_styles is not None or (self.style.part_styles and new_style is not None):
            parts = None if change.part_styles is None else parse_part_styles(change.part_styles)
            self._start_mixture_blend(new_style or self.style.style, parts, t)
        elif change.style2 is not None:
            self._blending_from = None
            second = StylePrompt.parse(change.style2)
            self._set_style(new_style or self.style.style, second, float(self._gamma.value(t)))
        elif new_style is not None and new_style != self.style.style:
            self._start_style_blend(new_style, t)

    @property
    def heard(self) -> StyleState:
        """What the generator hears of the stream's style."""
        return self.hearing.heard(self.style)

    def _set_style(self, style: StylePrompt, second_style: StylePrompt | None = None,
                   gamma: float = SINGLE_STYLE) -> None:
        """The stream's style, second style and γ (the generator is told what it hears of them)."""
        self.style = replace(self.style, style=style, second_style=second_style, gamma=gamma)
        heard = self.heard
        self.generator.set_style(heard.style, heard.second_style, heard.gamma, heard.strength)

    def _set_gamma(self, gamma: float) -> None:
        self.style = replace(self.style, gamma=gamma)
        self.generator.set_gamma(self.heard.gamma)

    def _start_style_blend(self, new_style: StylePrompt, t: float) -> None:
        style = self.style
        if style.second_style is not None:  # a user γ mix is active: keep its second style, ramp as usual
            self._set_style(new_style, style.second_style, style.gamma)
            return
        self._blending_from = style.style
        self._blend = Ramp(0.0, self.fade_s, t)
        self._blend.set_target(SINGLE_STYLE, t)
        self._set_style(new_style, self._blending_from, 0.0)

    def _start_mixture_blend(self, style: StylePrompt, part_styles: PartStyles | None, t: float) -> None:
        """Ramp W from the mixture in effect to the one of ``style`` and ``part_styles`` (None: keep the parts)."""
        generator = self.generator
        parts = tuple(self.style.part_styles if part_styles is None else part_styles)
        if self._blending_from is not None:  # a γ style blend still running ends here
            self._blending_from = None
            self._set_style(self.style.style)
        self.style = replace(self.style, style=style, part_styles=parts)
        heard = self.heard
        old_prompts, old_weights = generator.mixture
        union, start, target = bound_blend_rows(*align_mixtures(
            old_prompts, old_weights, *generator.part_mixture(heard.style, heard.part_styles)), MAX_MIXTURE_ROWS)
        generator.blend_part_styles(union, start, heard.style, heard.part_styles, heard.strength)
        self._mixture_ramp = Ramp(start, self.fade_s, t)
        self._mixture_ramp.set_target(target, t)

    def _update_mixture_blend(self, t: float) -> None:
        if self._mixture_ramp is None:
            return
        weights = self._mixture_ramp.value(t).astype("float32")  # (R, C)
        if self._mixture_ramp.done(t):
            self._mixture_ramp = None
            self.generator.set_mixture(*drop_unused_rows(self.generator.mixture[0], weights, self.heard.style))
        else:
            self.generator.set_mixture_weights(weights)

    def _update_style_blend(self, t: float) -> None:
        if self._blending_from is None:
            return
        if self._blend.done(t):
            self._blending_from = None
            self._set_style(self.style.style)
        else:
            self._set_gamma(float(self._blend.value(t)))


def _style_from_control(change: StyleChange) -> StylePrompt | None:
    if change.prompt is not None:
        return StylePrompt("text", change.prompt)
    if change.style is not None:
        return StylePrompt.parse(change.style)
    return None


def _word_count(message: tuple[Control, ...]) -> int:
    return sum(len(control.words) for control in message if isinstance(control, Words))


def _prompts_of(change: StyleChange) -> list[StylePrompt]:
    """Every style prompt a style change names (first style, then second)."""
    first = _style_from_control(change)
    second = None if change.style2 is None else StylePrompt.parse(change.style2)
    return [prompt for prompt in (first, second) if prompt is not None]


def _prompt_name(prompt: StylePrompt) -> str:
    return prompt.value if prompt.kind == "label" else f"{prompt.kind}:{prompt.value}"
