"""The evaluation suite: every system on the held-out and unseen-speech sets, plus the deltas.

Systems: ``ground_truth`` (the held-out real motion), ``mismatched_ground_truth`` (real motion paired
with another held-out clip's audio: what beat consistency gives for motion unrelated to the speech),
``ddpm`` (the 1000-step offline sampler, run on a limited duration: see :class:`EvalConfig`) and
``ddim_k1/2/4/8`` (the live sampler). Generated systems run through the product's session.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
from tqdm import tqdm

from gesturecast.models.audio.files import SAMPLE_RATE
from gesturecast.models.dataset.augment import audio_samples_for_frames
from gesturecast.models.evaluation.metrics import seed_diversity
from gesturecast.models.generator.diffusion import SamplerConfig
from gesturecast.models.motion.motion import MOTION_FPS
from gesturecast.models.runtime.bundle import ModelBundle
from gesturecast.tools.eval.clips import EvalClip
from gesturecast.tools.eval.condition import DEFAULT_CONDITION, Condition
from gesturecast.tools.eval.generate import SystemSpec, generate_live, generate_offline
from gesturecast.tools.eval.metrics import EvalNetworks, motion_metrics, style_accuracy

LOGGER = logging.getLogger(__name__)
GROUND_TRUTH = "ground_truth"
MISMATCHED = "mismatched_ground_truth"
DDPM = "ddpm"
DDIM_STEPS = (1, 2, 4, 8)
SYSTEM_NAMES = (GROUND_TRUTH, MISMATCHED, DDPM, *(f"ddim_k{k}" for k in DDIM_STEPS))


@dataclass(frozen=True)
class EvalConfig:
    held_out_seconds: float | None = 10.0  # crop of every held-out clip (all systems)
    unseen_seconds: float | None = 30.0  # crop of every unseen-speech clip
    style_seconds: float = 6.0  # audio generated per requested style (≥ 2.2 s: one classifier window)
    ddpm_seconds: float = 10.0  # DDPM: every clip it runs on is cropped to this
    ddpm_unseen_clips: int = 1  # DDPM: only the first N unseen clips
    ddpm_styles: int = 2  # DDPM: style accuracy on the first N styles only
    styles: tuple[str, ...] = ()  # requested styles for style accuracy; () = the model's ∩ the classifier's
    systems: tuple[str, ...] = SYSTEM_NAMES
    seed: int = 0
    condition: Condition = DEFAULT_CONDITION  # the style asked and the label the generator hears (Settings())


QUICK = EvalConfig(held_out_seconds=5.0, unseen_seconds=5.0, style_seconds=2.5, ddpm_seconds=2.5,
                   ddpm_styles=1)


def system_spec(name: str, bundle: ModelBundle) -> SystemSpec:
    if name == DDPM:
        return SystemSpec(name, SamplerConfig("ddpm", bundle.denoiser_config.num_timesteps))
    return SystemSpec(name, SamplerConfig("ddim", int(name.removeprefix("ddim_k"))))


@dataclass
class EvalSets:
    held_out: list[EvalClip]
    unseen: list[EvalClip]
    styles: tuple[str, ...]


class SuiteRunner:
    """Runs systems on the sets with one progress bar counted in seconds of audio."""

    def __init__(self, bundle: ModelBundle, networks: EvalNetworks, sets: EvalSets, config: EvalConfig,
                 progress: bool = True) -> None:
        self.bundle, self.networks, self.sets, self.config = bundle, networks, sets, config
        self.bar = tqdm(total=self._planned_seconds(), unit="s", desc="eval (audio seconds)", disable=not progress)
        self.compute_s: dict[str, float] = {}

    # ---- planning ----
    def _subsets(self, name: str) -> tuple[list[EvalClip], list[EvalClip], tuple[str, ...], float]:
        """(held-out clips, unseen clips, styles, seconds per style) that system ``name`` runs on."""
        config = self.config
        if name != DDPM:
            return self.sets.held_out, self.sets.unseen, self.sets.styles, config.style_seconds
        held = [c.crop(config.ddpm_seconds) for c in self.sets.held_out]
        unseen = [c.crop(config.ddpm_seconds) for c in self.sets.unseen[: config.ddpm_unseen_clips]]
        return held, unseen, self.sets.styles[: config.ddpm_styles], min(config.style_seconds, config.ddpm_seconds)

    def _planned_seconds(self) -> float:
        total = 0.0
        for name in self.config.systems:
            if name in (GROUND_TRUTH, MISMATCHED):
                continue
            held, unseen, styles, style_s = self._subsets(name)
            total += sum(c.seconds for c in held + unseen) + len(styles) * style_s
            total += held[0].seconds if name != DDPM else 0.0  # second seed for seed diversity
        return total + self.sets.held_out[0].seconds * 2  # live-vs-offline check

    # ---- running ----
    def _generate(self, spec: SystemSpec, clip: EvalClip, style: str, seed: int,
                  generate: Callable = generate_offline) -> np.ndarray:
        result = generate(self.bundle, spec.sampler, clip, style, seed,
                          generator_style=self.config.condition.generator_style)
        self.compute_s[spec.name] = self.compute_s.get(spec.name, 0.0) + result.compute_s
        self.bar.update(clip.seconds)
        return result.positions

    def _style_clip(self, seconds: float) -> EvalClip:
        """Speech for style accuracy: the first clip (held-out, then unseen) at least ``seconds`` long, cropped."""
        clips = self.sets.held_out + self.sets.unseen
        long_enough = [c for c in clips if c.seconds >= seconds]
        return (long_enough[0] if long_enough else max(clips, key=lambda c: c.seconds)).crop(seconds)

    def generated_system(self, name: str) -> dict:
        spec = system_spec(name, self.bundle)
        held, unseen, styles, style_s = self._subsets(name)
        seed = self.config.seed
        held_pos = [self._generate(spec, c, self.speech_style, seed) for c in held]
        result = motion_metrics(held_pos, [c.audio for c in held], self.networks)
        if name != DDPM:
            other_seed = self._generate(spec, held[0], self.speech_style, seed + 1)
            result["diversity"]["seed"] = seed_pair_diversity(held_pos[0], other_seed)
        per_style = {s: [self._generate(spec, self._style_clip(style_s), s, seed)] for s in styles}
        result["style_accuracy"] = style_accuracy(per_style, self.networks.classifier)
        unseen_pos = [self._generate(spec, c, self.speech_style, seed) for c in unseen]
        result["unseen_speech"] = motion_metrics(unseen_pos, [c.audio for c in unseen], self.networks)
        result["compute_s"] = self.compute_s.get(name, 0.0)
        result["clips"] = {"held_out": [c.name for c in held], "unseen": [c.name for c in unseen],
                           "styles": list(styles), "seconds_per_style": style_s}
        return result

    @property
    def speech_style(self) -> str:
        """The style every speech clip is generated in: the condition's (the product's default unless asked)."""
        return self.config.condition.style

    def ground_truth(self, mismatched: bool) -> dict:
        held = self.sets.held_out
        positions = [c.positions for c in held]
        audios = [c.audio for c in held]
        if mismatched:
            audios = audios[1:] + audios[:1]  # clip i's motion with clip i+1's speech
            positions, audios = zip(*(crop_pair(p, a) for p, a in zip(positions, audios, strict=True)), strict=True)
        result = motion_metrics(list(positions), list(audios), self.networks)
        per_style: dict[str, list[np.ndarray]] = {}
        for clip in held:
            per_style.setdefault(clip.style, []).append(clip.positions)
        result["style_accuracy"] = style_accuracy(per_style, self.networks.classifier)
        result["clips"] = {"held_out": [c.name for c in held]}
        return result

    def held_out_only(self, name: str) -> dict:
        """A generated system's metrics on the held-out set alone (for the look-ahead comparison)."""
        spec = system_spec(name, self.bundle)
        held = self.sets.held_out
        positions = [self._generate(spec, c, self.speech_style, self.config.seed) for c in held]
        return motion_metrics(positions, [c.audio for c in held], self.networks)

    def run_system(self, name: str) -> dict:
        if name in (GROUND_TRUTH, MISMATCHED):
            return self.ground_truth(name == MISMATCHED)
        return self.generated_system(name)

    def live_vs_offline(self) -> dict:
        """The first held-out clip at the model's own K through the live engine and the offline path."""
        spec = system_spec(f"ddim_k{self.bundle.default_steps}", self.bundle)
        spec = replace(spec, name="live_check")
        clip = self.sets.held_out[0]
        style = self.speech_style
        offline = self._generate(spec, clip, style, self.config.seed)
        live = self._generate(spec, clip, style, self.config.seed, generate=generate_live)
        frames = min(len(offline), len(live))
        metrics = {kind: motion_metrics([p], [clip.audio], self.networks) for kind, p in
                   (("offline", offline), ("live", live))}
        return {
            "clip": clip.name, "sampler": f"ddim K={self.bundle.default_steps}",
            "frames": {"offline": len(offline), "live": len(live)},
            "max_abs_position_difference_m": float(np.abs(offline[:frames] - live[:frames]).max()),
            "metrics": metrics,
        }


def crop_pair(positions: np.ndarray, audio: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Motion and audio cut to the shorter of the two (whole motion frames)."""
    frames = min(positions.shape[0], int(audio.shape[0] / (SAMPLE_RATE / MOTION_FPS)))
    return positions[:frames], audio[: audio_samples_for_frames(frames, MOTION_FPS, SAMPLE_RATE)]


def seed_pair_diversity(a: np.ndarray, b: np.ndarray) -> float:
    """Seed diversity of two clips generated for the same audio (cut to the shorter)."""
    frames = min(len(a), len(b))
    return seed_diversity(np.stack([a[:frames], b[:frames]]))
