"""What a style prompt is, before any model sees it (pure data: no onnxruntime, no torch).

Three kinds of prompt (GestureDiffuCLIP §4.1: text, motion; DiffuseStyleGesture: labels): ``happy`` is a
label, ``text:calm and slow`` free text, ``motion:clip.bvh`` a motion clip. Per body part (GestureDiffuCLIP
§6.3): ``arms=happy``, ``torso=text:tired and bent``. Turning a prompt into an embedding is the runtime's job
(realtime/generation/style_prompts.py).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass

from gesturecast.errors import UserError

STYLE_KINDS = ("label", "text", "motion")
KIND_SEPARATOR = ":"
PART_SEPARATOR = "="
PartStyles = tuple[tuple[str, "StylePrompt"], ...]  # (body part, prompt) pairs, each part once


@dataclass(frozen=True)
class StylePrompt:
    kind: str
    value: str

    def __post_init__(self) -> None:
        if self.kind not in STYLE_KINDS:
            raise UserError(f"style kind must be one of {', '.join(STYLE_KINDS)}, got {self.kind!r}")
        if not isinstance(self.value, str) or not self.value.strip():
            raise UserError("empty style prompt")

    @classmethod
    def parse(cls, spec: str) -> StylePrompt:
        """``happy`` → label, ``text:...`` → free text, ``motion:path`` → motion clip."""
        if not isinstance(spec, str):
            raise UserError(f"a style is a string such as happy or text:calm, got {spec!r:.60}")
        kind, separator, value = spec.partition(KIND_SEPARATOR)
        if separator and kind in ("text", "motion"):
            return cls(kind, value)
        return cls("label", spec)


def parse_part_styles(specs: Iterable[str | tuple[str, str | StylePrompt]] | Mapping[str, str | StylePrompt]
                      ) -> PartStyles:
    """``["arms=happy", "legs=text:tired"]``, ``{"arms": "happy"}`` or ``(("arms", StylePrompt), ...)`` →
    ((part, prompt), ...); a spec without ``=`` or a part named twice raises UserError (part names are checked
    against the model later)."""
    items = specs.items() if isinstance(specs, Mapping) else specs
    pairs = [_split_part_spec(item) if isinstance(item, str) else tuple(item) for item in items]
    parts = [part for part, _ in pairs]
    repeated = sorted({part for part in parts if parts.count(part) > 1})
    if repeated:
        raise UserError(f"body part {repeated[0]!r} is given two styles")
    return tuple((part, spec if isinstance(spec, StylePrompt) else StylePrompt.parse(spec)) for part, spec in pairs)


def _split_part_spec(spec: str) -> tuple[str, str]:
    part, separator, style = spec.partition(PART_SEPARATOR)
    if not separator or not part.strip():
        raise UserError(f"a part style is PART=STYLE (e.g. arms=happy), got {spec!r:.60}")
    return part.strip(), style
