"""Live changes of style, part styles, guidance, audio guidance, γ and root mode, blended in over a short stream
time (no pop).

Controls arrive from any thread (WebSocket clients, the CLI) and are applied by the session
between latent steps. Numbers (guidance s, audio guidance s_a, γ) move along a smoothstep ramp. A new style with no
second style is blended with DiffuseStyleGesture's own mechanism: the generator runs
x̂0 = γ·D(new) + (1 − γ)·D(old) while γ ramps 0 → 1, then drops the old style. While body parts have their own
prompts, style and part-style changes ramp the part mixture's channel weights W instead (a soft mask moving from
the old prompts' channels to the new ones, generation/style_mixture.py), then drop the prompts no channel uses. A
stream holds at most MAX_MIXTURE_ROWS style rows, also when part-style changes arrive faster than the fade.
"""

from __future__ import annotations

import logging
import threading
from collections import deque
from dataclasses import replace
from typing import Protocol

from gesturecast.controls import Control, Gesture, StyleChange, Word, Words
from gesturecast.errors import UserError
from gesturecast.models.generator.style_prompt import PartStyles, StylePrompt, parse_part_styles
from gesturecast.models.motion.root_anchor import RootAnchor, RootMode
from gesturecast.realtime.generation.generator import Generator
from gesturecast.realtime.generation.style_mixture import align_mixtures, bound_blend_rows, drop_unused_rows
from gesturecast.realtime.gestures.cues import CONTROL_SOURCE, Cue, CuePlan, CueRefused
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


class GestureDoor(Protocol):
    """Where ``gesture`` and ``words`` controls go: the session's cue plan (checked on submit, with the cue times
    by ``check_cue_times``), ``cue`` and ``cue_words``; ``control_stroke_lead_s`` tells a gesture's ack when it
    shows."""

    cues: CuePlan

    def check_cue_times(self, times: list[float]) -> None: ...

    def cue(self, cue: Cue) -> object: ...

    def control_stroke_lead_s(self) -> float: ...

    def cue_words(self, words: list[Word]) -> object: ...


class SessionControls:
    """Holds the control inbox and the ramps; :meth:`advance` applies them at stream time ``t``."""

    def __init__(self, generator: Generator, root: RootAnchor, gestures: GestureDoor | None = None,
                 fade_s: float = DEFAULT_RAMP_S) -> None:
        self.generator = generator
        self.root = root
        self.gestures = gestures
        self.fade_s = fade_s
        self._inbox: deque[tuple[Control, ...]] = deque(maxlen=MAX_PENDING_CONTROLS)
        self._lock = threading.Lock()
        self._guidance = Ramp(generator.base_guidance, fade_s)
        self._style_strength = Ramp(generator.settings.style_strength, fade_s)
        self._audio_guidance = Ramp(generator.settings.audio_guidance, fade_s)
        self._gamma = Ramp(generator.settings.gamma, fade_s)
        self._blending_from: StylePrompt | None = None  # old style while a style change blends in
        self._mixture_ramp: Ramp | None = None  # W (R, C) flattened, while a part-style change blends in
        self.deferred_word_steps = 0  # words left queued by a step's :data:`WORDS_PER_LATENT`, summed over the steps

    def submit(self, controls: tuple[Control, ...]) -> dict:
        """Queue one message's typed controls (built by :func:`gesturecast.controls.parse_controls`, so their values
        are already checked), applied together at the next latent; thread-safe. What only the model can tell is
        checked here first (a gesture not in the lexicon, a style label or body part the model does not know), so
        one it cannot use raises UserError here (the caller answers the client) instead of failing the stream when
        applied. Returns what the ack may tell: for a gesture, about when its stroke shows
        (``{"gesture_stroke_in_ms": ...}``); else {}."""
        notes = {}
        for control in controls:
            self._check(control)
            if isinstance(control, Gesture):
                notes["gesture_stroke_in_ms"] = round(self.gestures.control_stroke_lead_s() * 1e3)
        with self._lock:
            self._inbox.append(tuple(controls))
        return notes

    def _check(self, control: Control) -> None:
        if isinstance(control, Gesture):
            self._check_gesture(control.name)
            self.gestures.check_cue_times([])
        elif isinstance(control, Words):
            self._check_gesture(None)
            self.gestures.check_cue_times([word.start for word in control.words])
        else:
            for prompt in _prompts_of(control):
                self.generator.styles.embed(prompt)
            if control.part_styles is not None:
                parts = parse_part_styles(control.part_styles)
                self.generator.part_mixture(self.generator.settings.style, parts)  # unknown body parts
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
        if strength != self.generator.settings.style_strength:
            self.generator.set_style_strength(strength)
        audio_guidance = float(self._audio_guidance.value(t))
        if audio_guidance != self.generator.settings.audio_guidance:
            self.generator.set_audio_guidance(audio_guidance)
        if self._blending_from is None and self.generator.settings.second_style is not None:
            self.generator.set_gamma(float(self._gamma.value(t)))

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
        settings = self.generator.settings
        name = _prompt_name(settings.style)
        if settings.part_styles:
            name += " " + " ".join(f"{part}={_prompt_name(prompt)}" for part, prompt in settings.part_styles)
        if settings.second_style is None or self._blending_from is not None:
            return name
        return f"{name}→{_prompt_name(settings.second_style)} γ={settings.gamma:.2f}"

    def _check_gesture(self, name: str | None) -> None:
        """UserError unless the stream has a lexicon (and ``name``, when given, is in it)."""
        if self.gestures is None or not self.gestures.cues.clips:
            raise UserError("this stream has no gesture lexicon")
        if name is not None:
            self.gestures.cues.check(name)

    def _apply(self, control: Control, t: float) -> None:
        if isinstance(control, StyleChange):
            self._apply_style(control, t)
            return
        try:
            if isinstance(control, Gesture):  # as soon as possible: its stroke as early as it can be from this latent
                self.gestures.cue(Cue(control.name, t, CONTROL_SOURCE))
            else:  # on the words' own stream times (late by the wait when already generated)
                self.gestures.cue_words(list(control.words))
        except CueRefused as error:  # the plan filled up since the submit: the stream goes on without them
            logger.warning("gesture cues not kept: %s", error)

    def _apply_style(self, change: StyleChange, t: float) -> None:
        if change.root is not None:
            self.root.set_mode(RootMode(change.root))  # re-anchored where the avatar stands: no jump
        for value, ramp in ((change.guidance, self._guidance), (change.style_strength, self._style_strength),
                            (change.audio_guidance, self._audio_guidance), (change.gamma, self._gamma)):
            if value is not None:
                ramp.set_target(float(value), t)
        new_style = _style_from_control(change)
        if change.part_styles is not None or (self.generator.settings.part_styles and new_style is not None):
            parts = None if change.part_styles is None else parse_part_styles(change.part_styles)
            self._start_mixture_blend(new_style or self.generator.settings.style, parts, t)
        elif change.style2 is not None:
            self._blending_from = None
            style = new_style or self.generator.settings.style
            self.generator.set_style(style, StylePrompt.parse(change.style2), float(self._gamma.value(t)))
        elif new_style is not None and new_style != self.generator.settings.style:
            self._start_style_blend(new_style, t)

    def _start_style_blend(self, new_style: StylePrompt, t: float) -> None:
        settings = self.generator.settings
        if settings.second_style is not None:  # a user γ mix is active: keep its second style, ramp as usual
            self.generator.set_style(new_style, settings.second_style, settings.gamma)
            return
        self._blending_from = settings.style
        self._blend = Ramp(0.0, self.fade_s, t)
        self._blend.set_target(SINGLE_STYLE, t)
        self.generator.set_style(new_style, self._blending_from, 0.0)

    def _start_mixture_blend(self, style: StylePrompt, part_styles: PartStyles | None, t: float) -> None:
        """Ramp W from the mixture in effect to the one of ``style`` and ``part_styles`` (None: keep the parts)."""
        generator = self.generator
        parts = generator.settings.part_styles if part_styles is None else part_styles
        if self._blending_from is not None:  # a γ style blend still running ends here
            self._blending_from = None
            generator.set_style(generator.settings.style)
        old_prompts, old_weights = generator.mixture
        union, start, target = bound_blend_rows(
            *align_mixtures(old_prompts, old_weights, *generator.part_mixture(style, parts)), MAX_MIXTURE_ROWS)
        generator.set_mixture(union, start)
        generator.settings = replace(generator.settings, style=style, part_styles=tuple(parts))
        self._mixture_ramp = Ramp(start, self.fade_s, t)
        self._mixture_ramp.set_target(target, t)

    def _update_mixture_blend(self, t: float) -> None:
        if self._mixture_ramp is None:
            return
        weights = self._mixture_ramp.value(t).astype("float32")  # (R, C)
        if self._mixture_ramp.done(t):
            self._mixture_ramp = None
            self.generator.set_mixture(*drop_unused_rows(self.generator.mixture[0], weights,
                                                         self.generator.settings.style))
        else:
            self.generator.set_mixture_weights(weights)

    def _update_style_blend(self, t: float) -> None:
        if self._blending_from is None:
            return
        if self._blend.done(t):
            self._blending_from = None
            self.generator.set_style(self.generator.settings.style)
        else:
            self.generator.set_gamma(float(self._blend.value(t)))


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
