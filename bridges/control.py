"""Control messages clients may send to steer the engine, validated against a fixed schema.

A control message is a JSON object ``{"type": "control", <fields>..., "token": "..."}`` with at
least one known field. Unknown fields, wrong types (booleans are not numbers) and values out of
range are rejected with a one-line reason; nothing invalid reaches the engine.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass

from gesturecast.models.motion.root_anchor import ROOT_MODES
from gesturecast.settings import (  # the same ranges as the flags and Settings
    GAMMA_RANGE,
    GUIDANCE_RANGE,
    STYLE_STRENGTH_RANGE,
)

MAX_STYLE_CHARS = 200
MAX_PROMPT_CHARS = 500
MAX_GESTURE_CHARS = 64
ENVELOPE_FIELDS = frozenset({"type", "token"})
WORDS_MESSAGE = "words"  # {"type": "words", "words": [...]}: the same as a control with only words


class ControlError(ValueError):
    """A rejected control message; ``str(error)`` is the one-line reason sent back."""


@dataclass(frozen=True)
class TextField:
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


MOTION_PROMPT_PREFIX = "motion:"


@dataclass(frozen=True)
class StyleField(TextField):
    """A style from a client: a label or ``text:...``. ``motion:PATH`` names a file on the server, so it is
    refused from clients (motion prompts are given at start with --motion-prompt)."""

    def check(self, name: str, value: object) -> str:
        value = super().check(name, value)
        if value.strip().startswith(MOTION_PROMPT_PREFIX):
            raise ControlError(f"{name}: motion prompts name files on the server and are not accepted from clients")
        return value


@dataclass(frozen=True)
class NumberField:
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
            raise ControlError(f"{name} must be within [{self.low:g}, {self.high:g}], got {number:g}")
        return number

    def describe(self) -> dict:
        return {"type": "number", "min": self.low, "max": self.high}


@dataclass(frozen=True)
class ChoiceField:
    choices: tuple[str, ...]

    def check(self, name: str, value: object) -> str:
        if value not in self.choices:
            raise ControlError(f"{name} must be one of {', '.join(self.choices)}")
        return str(value)

    def describe(self) -> dict:
        return {"type": "choice", "choices": list(self.choices)}


MAX_PARTS = 8
MAX_PART_NAME_CHARS = 32
MAX_WORDS = 500  # words of one message: minutes of speech
MAX_WORD_CHARS = 64
MAX_STREAM_SECONDS = 1e6  # word times beyond this are not stream times (11 days)


@dataclass(frozen=True)
class WordsField:
    """``[{"word": "hello", "start": 1.2, "end": 1.5}, ...]``: words with stream-time stamps (seconds since the
    stream's first sample); trigger words cue the lexicon's gestures with the stroke on the word."""

    def check(self, name: str, value: object) -> list[dict]:
        if not isinstance(value, list) or not 0 < len(value) <= MAX_WORDS:
            raise ControlError(f"{name} must be a list of 1..{MAX_WORDS} {{word, start, end}} objects")
        return [self._word(f"{name}[{index}]", item) for index, item in enumerate(value)]

    @staticmethod
    def _word(name: str, item: object) -> dict:
        if not isinstance(item, dict) or set(item) - {"word", "start", "end"}:
            raise ControlError(f"{name} must be an object with word, start and end only")
        TextField(MAX_WORD_CHARS).check(f"{name}.word", item.get("word"))
        times = {key: NumberField(0.0, MAX_STREAM_SECONDS).check(f"{name}.{key}", item.get(key, item.get("start")))
                 for key in ("start", "end")}
        if times["end"] < times["start"]:
            raise ControlError(f"{name}.end is before its start")
        return {"word": item["word"], **times}

    def describe(self) -> dict:
        return {"type": "words", "max_words": MAX_WORDS}


@dataclass(frozen=True)
class PartStylesField:
    """``{"arms": "happy", "torso": "text:tired"}``: a style per body part (GestureDiffuCLIP §6.3); ``{}`` gives
    the whole body one style again. Part names are checked against the model when the control is applied."""

    style: StyleField

    def check(self, name: str, value: object) -> dict[str, str]:
        if not isinstance(value, dict):
            raise ControlError(f'{name} must be an object of body part → style, e.g. {{"arms": "happy"}}')
        if len(value) > MAX_PARTS:
            raise ControlError(f"{name} names more than {MAX_PARTS} body parts")
        for part, style in value.items():
            if not part.strip() or len(part) > MAX_PART_NAME_CHARS:
                raise ControlError(f"{name}: a body part name must be 1..{MAX_PART_NAME_CHARS} characters")
            self.style.check(f"{name}.{part:.32}", style)
        return dict(value)

    def describe(self) -> dict:
        return {"type": "parts", "max_parts": MAX_PARTS, "style": self.style.describe()}


CONTROL_FIELDS: dict[str, TextField | NumberField | ChoiceField | PartStylesField | WordsField] = {
    "style": StyleField(MAX_STYLE_CHARS),
    "style2": StyleField(MAX_STYLE_CHARS),
    "part_styles": PartStylesField(StyleField(MAX_STYLE_CHARS)),
    "prompt": TextField(MAX_PROMPT_CHARS),
    "style_strength": NumberField(*STYLE_STRENGTH_RANGE),  # 0 neutral .. 1 the default .. 2
    "guidance": NumberField(*GUIDANCE_RANGE),
    "audio_guidance": NumberField(*GUIDANCE_RANGE),  # s_a: how strongly the motion follows the speech
    "gamma": NumberField(*GAMMA_RANGE),
    "root": ChoiceField(ROOT_MODES),  # bounded (in place), free or locked root motion
    "gesture": TextField(MAX_GESTURE_CHARS),  # a lexicon gesture (wave, bow, …), carried out as soon as it can
    "words": WordsField(),  # words with stream times: trigger words cue gestures (also as a "words" message)
}


def decode_client_message(text: str) -> dict:
    """A client's text message → a JSON object with a string ``type``; ControlError (one line) otherwise.

    Python's parser raises more than JSONDecodeError on hostile input: RecursionError for deeply
    nested arrays, ValueError for integers beyond its digit limit; all of them are one-line refusals.
    """
    try:
        decoded = json.loads(text)
    except RecursionError:
        raise ControlError("not JSON (nested too deeply)") from None
    except json.JSONDecodeError as error:
        raise ControlError(f"not JSON ({error.msg})") from None
    except ValueError:  # an integer beyond sys.get_int_max_str_digits()
        raise ControlError("not JSON (a number has too many digits)") from None
    if not isinstance(decoded, dict) or not isinstance(decoded.get("type"), str):
        raise ControlError('a message must be a JSON object with a "type"')
    return decoded


def control_schema() -> dict:
    """The schema as plain JSON-able data (sent in the hello so clients can build controls)."""
    return {name: rule.describe() for name, rule in CONTROL_FIELDS.items()}


def validate_control(message: dict) -> dict:
    """The validated control fields of ``message`` (envelope fields removed); ControlError if invalid."""
    fields = {key: value for key, value in message.items() if key not in ENVELOPE_FIELDS}
    unknown = sorted(set(fields) - set(CONTROL_FIELDS))
    if unknown:
        raise ControlError(f"unknown control field(s): {', '.join(unknown)}; known: {', '.join(CONTROL_FIELDS)}")
    if not fields:
        raise ControlError(f"a control message needs at least one of: {', '.join(CONTROL_FIELDS)}")
    return {name: CONTROL_FIELDS[name].check(name, value) for name, value in fields.items()}
