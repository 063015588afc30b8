"""What a client may change while a stream runs, as typed frozen values, checked once, here.

Every door builds these from its wire form with :func:`parse_controls`: ``Stream.control(**fields)``, a WebSocket
``control`` or ``words`` message, ``serve``'s ``start`` and ``control`` messages, an OSC gesture, ``live``'s inputs.
A bad field is refused by the same one-line :class:`ControlError` whichever door it came through; the session reads
only the typed values:

- :class:`StyleChange`: style, second style, part styles, prompt, style strength, guidance, audio guidance, γ, root,
  gesture size (``intensity``) and ``pause``;
- :class:`Gesture`: a lexicon gesture, carried out as soon as the look-ahead allows;
- :class:`Words`: words with stream times; trigger words cue gestures.

The style settings are declared once, by :class:`StyleChange`'s fields and their rules (:data:`STYLE_SETTINGS`):
``Settings`` takes its ranges and choices from it, ``serve``'s ``start`` message carries a :class:`StyleChange`, and
the JSON schema that the hello message sends to clients is generated from it (:func:`control_schema`).

Words have one parser, :func:`parse_words`, with one set of limits and one error: a ``words`` message or control,
``Stream.words`` and ``Stream.spoken`` (and through it the Pipecat processor), and transcripts (JSON word lists,
.srt and .vtt files, lists given to ``gesturecast.generate``) all check their words with it.

This module is the ground floor: it imports nothing of the project but its base error.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, fields

from gesturecast.errors import UserError

MAX_STYLE_CHARS = 200
MAX_PROMPT_CHARS = 500
MAX_GESTURE_CHARS = 64
MAX_PARTS = 8
MAX_PART_NAME_CHARS = 32
MAX_MESSAGE_WORDS = 500  # words of one words message or call: minutes of speech
MAX_TRANSCRIPT_WORDS = 200_000  # words of a transcript given at once (a file or a list): a day of speech
MAX_WORD_CHARS = 64
MAX_SENTENCE_CHARS = 2000  # a sentence (or a few) without word times, one text control or Stream.spoken call
MAX_STREAM_SECONDS = 1e6  # times beyond this are not stream times (11 days)
MOTION_PROMPT_PREFIX = "motion:"
GUIDANCE_RANGE = (0.0, 10.0)  # classifier-free guidance s and audio guidance s_a
STYLE_STRENGTH_RANGE = (0.0, 2.0)  # 0: the generator's own motion, 1: the fitted style, 2: twice its change
GAMMA_RANGE = (-2.0, 3.0)  # γ: interpolation in 0..1, extrapolation outside
ROOT_MODES = ("bounded", "free", "locked")  # stays near where it started, the generated root motion, pinned
INTENSITY_RANGE = (0.0, 2.0)  # gesture size: 0 stands and breathes, 1 the generated motion as it is, 2 twice as big


def exact_number(number: float) -> str:
    """``number`` short when that is exact (50, 1e+300), else with every digit it needs (3.0000001: not "3")."""
    short = f"{number:g}"
    return short if float(short) == number else repr(number)


class ControlError(UserError, ValueError):
    """A refused control or word; ``str(error)`` is the one-line reason every door gives (and the WebSocket sends
    back)."""


@dataclass(frozen=True)
class Text:
    """A non-blank string of at most ``max_chars`` characters."""

    max_chars: int

    def check(self, name: str, value: object) -> str:
        if not isinstance(value, str):
            raise ControlError(f"{name} must be a string")
        if not value.strip():
            raise ControlError(f"{name} must not be blank")
        if len(value) > self.max_chars:
            raise ControlError(f"{name} is longer than {self.max_chars} characters")
        try:
            value.encode("utf-8")
        except UnicodeEncodeError:  # JSON's "\ud800" escapes decode to lone surrogates no text model reads
            raise ControlError(f"{name} is not valid Unicode text (lone surrogate)") from None
        return value

    def describe(self) -> dict:
        return {"type": "string", "max_chars": self.max_chars}


@dataclass(frozen=True)
class Style(Text):
    """A style: a label or ``text:...``. ``motion:PATH`` names a file on the server, so it is refused from clients
    (motion prompts are given at start with --motion-prompt)."""

    def check(self, name: str, value: object) -> str:
        value = super().check(name, value)
        if value.strip().startswith(MOTION_PROMPT_PREFIX):
            raise ControlError(f"{name}: motion prompts name files on the server and are not accepted from clients")
        return value


@dataclass(frozen=True)
class Number:
    """A finite number in [low, high] (booleans are not numbers)."""

    low: float
    high: float

    def check(self, name: str, value: object) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ControlError(f"{name} must be a finite number")
        try:
            number = float(value)  # an int beyond float range overflows
        except OverflowError:
            number = math.inf
        if not math.isfinite(number):
            raise ControlError(f"{name} must be a finite number")
        if not self.low <= number <= self.high:
            raise ControlError(f"{name} must be within [{self.low:g}, {self.high:g}], got {exact_number(number)}")
        return number

    def describe(self) -> dict:
        return {"type": "number", "min": self.low, "max": self.high}


@dataclass(frozen=True)
class Choice:
    """One of a fixed set of names."""

    choices: tuple[str, ...]

    def check(self, name: str, value: object) -> str:
        if not isinstance(value, str) or value not in self.choices:
            raise ControlError(f"{name} must be one of {', '.join(self.choices)}")
        return value

    def describe(self) -> dict:
        return {"type": "choice", "choices": list(self.choices)}


@dataclass(frozen=True)
class Switch:
    """On or off: a JSON ``true`` / ``false`` (numbers and strings are not switches)."""

    def check(self, name: str, value: object) -> bool:
        if not isinstance(value, bool):
            raise ControlError(f"{name} must be true or false")
        return value

    def describe(self) -> dict:
        return {"type": "boolean"}


PartStylePairs = tuple[tuple[str, str], ...]


@dataclass(frozen=True)
class PartStyleRule:
    """``{"arms": "happy", "torso": "text:tired"}``: a style per body part (GestureDiffuCLIP §6.3); ``{}`` gives
    the whole body one style again. Part names are checked against the model when the control is submitted."""

    style: Style

    def check(self, name: str, value: object) -> PartStylePairs:
        if not isinstance(value, Mapping):
            raise ControlError(f'{name} must be an object of body part → style, e.g. {{"arms": "happy"}}')
        if len(value) > MAX_PARTS:
            raise ControlError(f"{name} names more than {MAX_PARTS} body parts")
        for part, style in value.items():
            if not isinstance(part, str) or not part.strip() or len(part) > MAX_PART_NAME_CHARS:
                raise ControlError(f"{name}: a body part name must be 1..{MAX_PART_NAME_CHARS} characters")
            self.style.check(f"{name}.{part:.32}", style)
        return tuple(value.items())

    def describe(self) -> dict:
        return {"type": "parts", "max_parts": MAX_PARTS, "style": self.style.describe()}


def _setting(rule: Text | Number | Choice | PartStyleRule | Switch):
    """A :class:`StyleChange` field: None (unchanged) unless given, checked by ``rule``."""
    return field(default=None, metadata={"rule": rule})


@dataclass(frozen=True)
class StyleChange:
    """A change of the style settings (None: unchanged); the one declaration of those settings and their ranges.

    style, style2: a label (``happy``) or ``text:FREE TEXT``; with style2, x̂0 = γ·D(style) + (1 − γ)·D(style2).
    part_styles: (body part, style) pairs; () gives the whole body one style again.
    prompt: free-text style (wins over ``style``).
    style_strength: 0 (neutral) .. 1 (the model's default) .. 2; guidance: s; audio_guidance: s_a; gamma: γ.
    root: "bounded", "free" or "locked".
    intensity: gesture size, 0 (stands, breathes and blinks) .. 1 (the motion as generated) .. 2 (twice as big).
    pause: true sends the body to the idle, breathing pose (e.g. while the microphone is muted); false resumes.
    """

    style: str | None = _setting(Style(MAX_STYLE_CHARS))
    style2: str | None = _setting(Style(MAX_STYLE_CHARS))
    part_styles: PartStylePairs | None = _setting(PartStyleRule(Style(MAX_STYLE_CHARS)))
    prompt: str | None = _setting(Text(MAX_PROMPT_CHARS))
    style_strength: float | None = _setting(Number(*STYLE_STRENGTH_RANGE))
    guidance: float | None = _setting(Number(*GUIDANCE_RANGE))
    audio_guidance: float | None = _setting(Number(*GUIDANCE_RANGE))
    gamma: float | None = _setting(Number(*GAMMA_RANGE))
    root: str | None = _setting(Choice(ROOT_MODES))
    intensity: float | None = _setting(Number(*INTENSITY_RANGE))
    pause: bool | None = _setting(Switch())

    def changed(self) -> dict[str, object]:
        """The fields this change sets, by name."""
        return {name: value for name in STYLE_SETTINGS if (value := getattr(self, name)) is not None}

    def wire(self) -> dict:
        """The JSON form (what a client sent, checked)."""
        return {name: dict(value) if name == "part_styles" else value for name, value in self.changed().items()}


STYLE_SETTINGS: dict[str, Text | Number | Choice | PartStyleRule | Switch] = {
    item.name: item.metadata["rule"] for item in fields(StyleChange)}


@dataclass(frozen=True)
class Gesture:
    """Carry out the lexicon gesture ``name`` (wave, bow, …) as soon as it can."""

    name: str

    RULE = Text(MAX_GESTURE_CHARS)

    def wire(self) -> dict:
        return {"gesture": self.name}


@dataclass(frozen=True)
class Word:
    """A spoken word and its stream times in seconds (since the stream's first sample)."""

    text: str
    start: float
    end: float


STREAM_TIME = Number(0.0, MAX_STREAM_SECONDS)
WORD_TEXT = Text(MAX_WORD_CHARS)


def parse_words(value: object, name: str = "words", max_words: int = MAX_MESSAGE_WORDS) -> tuple[Word, ...]:
    """The one check of words, whichever door they come through: ``[{"word": "hello", "start": 1.2, "end": 1.5},
    ...]``, 1 to ``max_words`` items (``end`` defaults to ``start``; other keys, such as a recogniser's confidence, are
    ignored) → words with stream times; a one-line ControlError naming ``name`` and the item otherwise."""
    if not isinstance(value, list) or not 0 < len(value) <= max_words:
        raise ControlError(f"{name} must be a list of 1..{max_words} {{word, start, end}} objects")
    return tuple(_word(f"{name}[{index}]", item) for index, item in enumerate(value))


def _word(name: str, item: object) -> Word:
    if not isinstance(item, Mapping):
        raise ControlError(f"{name} must be an object with word, start and end")
    text = WORD_TEXT.check(f"{name}.word", item.get("word"))
    start, end = (STREAM_TIME.check(f"{name}.{key}", item.get(key, item.get("start"))) for key in ("start", "end"))
    if end < start:
        raise ControlError(f"{name}.end is before its start")
    return Word(text, start, end)


@dataclass(frozen=True)
class WordList:
    """The rule of a ``words`` field: :func:`parse_words` of at most :data:`MAX_MESSAGE_WORDS`."""

    def check(self, name: str, value: object) -> tuple[Word, ...]:
        return parse_words(value, name)

    def describe(self) -> dict:
        return {"type": "words", "max_words": MAX_MESSAGE_WORDS}


@dataclass(frozen=True)
class Words:
    """Words with stream times: trigger words cue the lexicon's gestures with the stroke on the word."""

    words: tuple[Word, ...]

    RULE = WordList()

    def wire(self) -> dict:
        return {"words": [{"word": word.text, "start": word.start, "end": word.end} for word in self.words]}


SENTENCE_TEXT = Text(MAX_SENTENCE_CHARS)


@dataclass(frozen=True)
class Sentence:
    """Text without word times (``{"text": "Hello everyone!", "start": 1.2}``): its words get times from its own
    speech, forced-aligned once that has arrived; ``start`` / ``end`` (stream seconds, optional) bound that speech."""

    text: str
    start: float | None = None
    end: float | None = None

    def wire(self) -> dict:
        bounds = {key: value for key, value in (("start", self.start), ("end", self.end)) if value is not None}
        return {"text": self.text, **bounds}


Control = StyleChange | Gesture | Words | Sentence
CONTROL_FIELDS = (*STYLE_SETTINGS, "gesture", "words", "text", "start", "end")  # every field a message may carry


def control_schema() -> dict:
    """The schema of control fields as plain JSON-able data (sent in the hello so clients can build controls)."""
    rules = {**STYLE_SETTINGS, "gesture": Gesture.RULE, "words": Words.RULE, "text": SENTENCE_TEXT,
             "start": STREAM_TIME, "end": STREAM_TIME}
    return {name: rules[name].describe() for name in CONTROL_FIELDS}


def parse_controls(message: Mapping[str, object], envelope: frozenset[str] = frozenset()) -> tuple[Control, ...]:
    """The typed controls of one control message's fields (``envelope`` names are skipped), in the order the session
    applies them: a gesture, words, then a style change. ControlError (one line) for an unknown field, a message with
    none, or a bad value."""
    values = {key: value for key, value in message.items() if key not in envelope}
    unknown = sorted(str(key) for key in set(values) - set(CONTROL_FIELDS))
    if unknown:
        raise ControlError(f"unknown control field(s): {', '.join(unknown)}; known: {', '.join(CONTROL_FIELDS)}")
    if not values:
        raise ControlError(f"a control message needs at least one of: {', '.join(CONTROL_FIELDS)}")
    controls: list[Control] = []
    if "gesture" in values:
        controls.append(Gesture(Gesture.RULE.check("gesture", values["gesture"])))
    if "words" in values:
        controls.append(Words(Words.RULE.check("words", values["words"])))
    if "text" in values:
        controls.append(Sentence(SENTENCE_TEXT.check("text", values["text"]),
                                 *(STREAM_TIME.check(key, values[key]) if key in values else None
                                   for key in ("start", "end"))))
    elif "start" in values or "end" in values:
        raise ControlError("start and end bound a text's speech; they need a text field")
    style = {name: rule.check(name, values[name]) for name, rule in STYLE_SETTINGS.items() if name in values}
    if style:
        controls.append(StyleChange(**style))
    return tuple(controls)


def parse_style_change(message: Mapping[str, object]) -> StyleChange:
    """The :class:`StyleChange` of the style fields in ``message`` (other keys are ignored); ControlError if bad."""
    return StyleChange(**{name: rule.check(name, message[name]) for name, rule in STYLE_SETTINGS.items()
                          if name in message})


def wire(controls: tuple[Control, ...]) -> dict:
    """The checked JSON form of a message's controls."""
    return {key: value for control in controls for key, value in control.wire().items()}


def acknowledged(controls: tuple[Control, ...]) -> dict:
    """What an ``ack`` reports as applied: the checked fields, ``words`` as their count (not 500 words echoed)."""
    applied = wire(controls)
    if "words" in applied:
        applied["words"] = len(applied["words"])
    return applied
