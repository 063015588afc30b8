"""One typed, frozen settings object for generation, validated once: :class:`Settings`.

The command line, ``gesturecast.generate``, ``gesturecast.Stream``, ``serve``, batch and the Pipecat processor
all build their sessions from a :class:`Settings`. Every field is checked when the object is made, with the
same one-line wording as the command-line flag of the same name (``--steps`` takes what ``steps`` takes, by
:data:`NUMBER_LIMITS`); what depends on the model (a style label it knows, a look-ahead it serves) is checked
when the settings meet the model.

``Settings(style="happy").replace(latency="low")`` gives a changed copy (validated again).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from gesturecast.arguments import NumberLimit
from gesturecast.controls import STYLE_SETTINGS, Choice, Number, StyleChange, Switch
from gesturecast.errors import UserError
from gesturecast.frames import FACE_NAMES, VISEME_NAMES
from gesturecast.models.generator.style_prompt import PartStyles, StylePrompt, parse_part_styles
from gesturecast.models.generator.styles import canonical_style
from gesturecast.models.motion.root_anchor import RootMode


@dataclass(frozen=True)
class LatencySetting:
    """A named latency dial position: look-ahead δ (None = the model's δa) and compute margin."""

    name: str
    lookahead_frames: int | None
    compute_margin_ms: float

    def lookahead_for(self, model_lookahead: int) -> int:
        """δ for a model trained with look-ahead δa = ``model_lookahead`` (never more than δa)."""
        return model_lookahead if self.lookahead_frames is None else min(self.lookahead_frames, model_lookahead)

QUALITY = LatencySetting("quality", None, 100.0)  # GestureDiffuCLIP's δa = 8 at 30 fps: L = 533 ms
BALANCED = LatencySetting("balanced", 4, 80.0)  # (4 + 4 + 1) / 30 s + 80 ms = 380 ms
LOW = LatencySetting("low", 0, 80.0)  # (4 + 0 + 1) / 30 s + 80 ms = 247 ms
LATENCY_SETTINGS = {setting.name: setting for setting in (LOW, BALANCED, QUALITY)}


DEFAULT_MODEL_DIR = Path(str(resources.files("gesturecast.models"))) / "weights" / "default"
DEFAULT_GESTURES_DIR = Path(str(resources.files("gesturecast.models"))) / "weights" / "gestures"
SAMPLERS = ("ddim", "ddpm")
LIPSYNC_OFF = "off"
LIPSYNC_CHOICES = (*VISEME_NAMES, LIPSYNC_OFF)
FACE_OFF, FACE_BLINK, FACE_FULL = "off", "blink", "full"
FACE_MODES = (FACE_OFF, FACE_BLINK, FACE_FULL)  # what the face does besides the mouth
OUTPUT_RATES = (30, 60)  # 60: slerp upsampling of the 30 fps motion
DEFAULT_STYLE_STRENGTH = 1.0
GENERATOR_STYLE = "speech"  # what the generator hears under the stylizer's styles (docs/voices.md)
DEFAULT_INTENSITY = 1.0  # the generated gestures as they are
SINGLE_STYLE = 1.0  # γ = 1: the first style only
DEFAULT_AUDIO_GUIDANCE = 1.5  # docs/generator.md "Audio guidance": rests in pauses, follows the speech more
DEFAULT_SMOOTHING_FRAMES = 1  # centred 3-frame window: jerk ≈ real motion's (docs/generator.md "Smoothing")

# field -> its limits; the command-line flag ``--field-name`` uses the same limits (gesturecast.arguments); the style
# settings' ranges and choices are those of the live controls (gesturecast.controls.StyleChange)
NUMBER_LIMITS: dict[str, NumberLimit] = {
    "steps": NumberLimit(1, 1000, integer=True),  # DDIM steps K per latent (DDPM uses the model's T)
    "seed": NumberLimit(0, 2**32 - 1, integer=True),
    "lookahead": NumberLimit(0, 64, integer=True),  # δ frames; the model serves at most its δa
    "smoothing": NumberLimit(0, 15, integer=True),  # k frames (half a second at most: each adds to L)
    "margin_ms": NumberLimit(0.0, 2000.0),
    "threads": NumberLimit(1, 64, integer=True),
    **{name: NumberLimit(rule.low, rule.high) for name, rule in STYLE_SETTINGS.items() if isinstance(rule, Number)},
}
CHOICES: dict[str, tuple] = {
    "sampler": SAMPLERS,
    "latency": tuple(LATENCY_SETTINGS),
    "lipsync": LIPSYNC_CHOICES,
    "face": FACE_MODES,
    "fps": OUTPUT_RATES,
    **{name: rule.choices for name, rule in STYLE_SETTINGS.items() if isinstance(rule, Choice)},
}
SWITCHES = tuple(name for name, rule in STYLE_SETTINGS.items() if isinstance(rule, Switch))  # True or False


@dataclass(frozen=True)
class Settings:
    """How to generate: the model, the style, the sampler, the latency dial, the pose options.

    model: model bundle folder (the bundled default).
    style: a style label ("happy", "old"), ``text:FREE TEXT`` or ``motion:CLIP.bvh``.
    prompt: free-text style prompt (the same as ``style="text:..."``; wins over ``style``).
    motion_prompt: a BVH/NPZ clip whose style to imitate (wins over ``prompt`` and ``style``).
    part_styles: a style per body part: ``{"arms": "happy"}`` or ``["arms=happy"]``; parts not named follow
        ``style`` (GestureDiffuCLIP §6.3).
    style2, gamma: second style of x̂0 = γ·D(style) + (1 − γ)·D(style2) (DiffuseStyleGesture); γ = 1: one style.
    style_strength: how strongly the style shows, 0 .. 2: the stylizer after the generator changes the motion by k
        times the fitted style (0: the generator's own motion, 1: as fitted; docs/stylizer.md).
    generator_style: the label the generator hears whenever the stylizer gives the style (every stylizer style,
        the default ``neutral`` among them): ``speech``, learned from motion captured with its speech, so the motion
        follows the voice; ``neutral`` gives the generator's own neutral, learned mostly from motion without
        speech (docs/voices.md).
    guidance: classifier-free guidance s (None: the model's); audio_guidance: s_a (1: off).
    sampler, steps: "ddim" with K steps per latent (None: the model's, 2 for the bundled one), or "ddpm" over all the
        model's steps (offline quality).
    seed: noise seed (the same seed and audio give the same motion).
    latency: "quality", "balanced" or "low"; lookahead / margin_ms override the setting's δ and margin.
    smoothing: half-width k of the centred smoothing window in frames (adds k frames to L).
    threads: onnxruntime intra-op threads.
    seed_motion: start from this clip's last pose instead of the idle pose.
    lipsync: viseme names "vrm0" (A I U E O), "vrm1" (aa ih ou ee oh) or "off".
    face: "full" (blinks and the style's expression), "blink" or "off"; named like ``lipsync`` (VRM 0.x when off).
    root: "bounded" (stays near where it started), "free" or "locked".
    intensity: gesture size, 0 .. 2: each joint's rotation away from the idle, breathing pose is scaled by it (0:
        stands, breathes and blinks; 1: the motion as generated, bit for bit; 2: twice as big).
    pause: start with the body in the idle, breathing pose (a ``pause`` control turns it on and off live).
    gestures: the gesture lexicon that words and gesture controls draw on (the bundled one; a folder of the
        user's clips, docs/gestures.md), or None for none.
    fps: output rate, 30 or 60 (slerp upsampling).
    """

    model: Path = DEFAULT_MODEL_DIR
    style: str = "neutral"
    prompt: str | None = None
    motion_prompt: Path | None = None
    part_styles: PartStyles = ()
    style2: str | None = None
    gamma: float = SINGLE_STYLE
    style_strength: float = DEFAULT_STYLE_STRENGTH
    generator_style: str = GENERATOR_STYLE
    guidance: float | None = None
    audio_guidance: float = DEFAULT_AUDIO_GUIDANCE
    sampler: str = "ddim"
    steps: int | None = None
    seed: int = 0
    latency: str = QUALITY.name
    lookahead: int | None = None
    margin_ms: float | None = None
    smoothing: int = DEFAULT_SMOOTHING_FRAMES
    threads: int = 1
    seed_motion: Path | None = None
    lipsync: str = "vrm0"
    face: str = FACE_FULL
    root: str = RootMode.BOUNDED.value
    intensity: float = DEFAULT_INTENSITY
    pause: bool = False
    fps: int = 30
    gestures: Path | None = DEFAULT_GESTURES_DIR

    def __post_init__(self) -> None:
        object.__setattr__(self, "model", Path(self.model))
        for name in ("motion_prompt", "seed_motion", "gestures"):
            if getattr(self, name) is not None:
                object.__setattr__(self, name, Path(getattr(self, name)))
        object.__setattr__(self, "part_styles", _part_styles(self.part_styles))
        for name, limit in NUMBER_LIMITS.items():
            value = getattr(self, name)
            if value is not None:
                object.__setattr__(self, name, limit.check(name, value))
        for name, choices in CHOICES.items():
            if getattr(self, name) not in choices:
                raise UserError(f"{name} must be one of {', '.join(map(str, choices))}, got {getattr(self, name)!r}")
        for name in SWITCHES:
            if not isinstance(getattr(self, name), bool):
                raise UserError(f"{name} must be True or False, got {getattr(self, name)!r:.40}")
        self.style_prompt()  # an empty style or prompt is refused here
        if self.style2 is not None:
            StylePrompt.parse(self.style2)
        object.__setattr__(self, "generator_style", canonical_style(self.generator_style))

    def style_prompt(self) -> StylePrompt:
        """The first style: the motion prompt, else the text prompt, else ``style``."""
        if self.motion_prompt is not None:
            return StylePrompt("motion", str(self.motion_prompt))
        if self.prompt:
            return StylePrompt("text", self.prompt)
        return StylePrompt.parse(self.style)

    def second_style(self) -> StylePrompt | None:
        return None if self.style2 is None else StylePrompt.parse(self.style2)

    @property
    def lipsync_names(self) -> tuple[str, ...]:
        """The viseme blend-shape names of ``lipsync`` (VRM 0.x or 1.0), () when off."""
        return VISEME_NAMES.get(self.lipsync, ())

    @property
    def face_names(self) -> tuple[str, ...]:
        """The blink and expression blend-shape names (VRM 0.x or 1.0, as ``lipsync``), () when the face is off."""
        return face_names(self.face, self.lipsync)

    def replace(self, **changes) -> Settings:
        """A copy with ``changes`` (unknown names and bad values are one-line errors)."""
        return with_overrides(self, changes)

    def with_style(self, change: StyleChange) -> Settings:
        """A copy with a client's style change (its fields are fields of these settings); a style or prompt it
        names replaces the first style, also one given here as a prompt or motion prompt."""
        changes = change.changed()
        if "style" in changes or "prompt" in changes:
            changes = {"prompt": None, "motion_prompt": None, **changes}
        return self.replace(**changes)


def face_names(face: str, lipsync: str) -> tuple[str, ...]:
    """The face's blend-shape names for a ``face`` mode, named like ``lipsync`` (VRM 0.x when it is off)."""
    if face == FACE_OFF:
        return ()
    return FACE_NAMES["vrm1" if lipsync == "vrm1" else "vrm0"]


def with_overrides(settings: Settings | None, overrides: Mapping[str, object]) -> Settings:
    """``settings`` (default: ``Settings()``) with the named fields changed; an unknown name is a UserError."""
    base = Settings() if settings is None else settings
    known = {field.name for field in dataclasses.fields(Settings)}
    unknown = sorted(set(overrides) - known)
    if unknown:
        raise UserError(f"unknown setting(s) {', '.join(unknown)}; known: {', '.join(sorted(known))}")
    return dataclasses.replace(base, **overrides)


def _part_styles(value: PartStyles | Mapping[str, str] | Iterable[str]) -> PartStyles:
    """Part styles as ((part, StylePrompt), ...), from that form, a mapping or PART=STYLE strings."""
    if isinstance(value, str):
        raise UserError(f"part_styles wants PART=STYLE items or a mapping, got the string {value!r:.60}")
    return parse_part_styles(value)
