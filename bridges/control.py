"""Control messages clients may send to steer the engine, validated against a fixed schema.

A control message is a JSON object ``{"type": "control", <fields>..., "token": "..."}`` with at
least one known field. Unknown fields, wrong types (booleans are not numbers) and values out of
range are rejected with a one-line reason; nothing invalid reaches the engine.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

MAX_STYLE_CHARS = 200
MAX_PROMPT_CHARS = 500
GUIDANCE_RANGE = (0.0, 10.0)  # classifier-free guidance scale s
GAMMA_RANGE = (-2.0, 3.0)  # style interpolation (0..1) and extrapolation (outside) γ
ENVELOPE_FIELDS = frozenset({"type", "token"})


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
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise ControlError(f"{name} must be a finite number")
        if not self.low <= value <= self.high:
            raise ControlError(f"{name} must be within [{self.low:g}, {self.high:g}], got {value:g}")
        return float(value)

    def describe(self) -> dict:
        return {"type": "number", "min": self.low, "max": self.high}


CONTROL_FIELDS: dict[str, TextField | NumberField] = {
    "style": StyleField(MAX_STYLE_CHARS),
    "style2": StyleField(MAX_STYLE_CHARS),
    "prompt": TextField(MAX_PROMPT_CHARS),
    "guidance": NumberField(*GUIDANCE_RANGE),
    "audio_guidance": NumberField(*GUIDANCE_RANGE),  # s_a: how strongly the motion follows the speech
    "gamma": NumberField(*GAMMA_RANGE),
}


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
