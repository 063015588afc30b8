"""Training arrays from the dataset cache: motion features, aligned audio features, style labels.

Paired takes (speech + motion) get mirror + speed augmentation (with their audio); motion-only
takes (Bandai) get mirroring only — they are 98 % of the frames, and speed variants of them would
triple memory without teaching the audio link. A clip carries the body parts its take holds reliably
(``parts``); the training stages mask the others in every loss. Audio features come from the same streaming code
the live engine runs (:func:`gesturecast.models.audio.streaming.extract_features`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from tqdm import tqdm

from gesturecast.models.audio.files import SAMPLE_RATE
from gesturecast.models.audio.streaming import FeatureConfig, extract_features
from gesturecast.models.dataset.augment import AugmentConfig, augmented_variants, slice_audio
from gesturecast.models.dataset.cache import is_full_body, load_take, read_index
from gesturecast.models.dataset.respeak import TRAINING_VOICES, respeak
from gesturecast.models.dataset.transcripts import cached_words
from gesturecast.models.dataset.voice_transforms import random_voice
from gesturecast.models.generator.styles import canonical_style
from gesturecast.models.motion.body_parts import PART_NAMES, holds_every_part
from gesturecast.models.motion.motion import SkeletonMotion
from gesturecast.models.motion.motion_features import motion_to_features


@dataclass
class TrainingClip:
    name: str
    dataset: str
    style: str  # canonical style name
    variant: str
    motion: np.ndarray  # (T, D) float32 motion features (raw, not normalised)
    audio: np.ndarray | None  # (T, F) float32 audio features aligned with the motion, None without speech
    voice_copy: bool = False  # a waveform-augmented repeat of another clip's motion (denoiser training only)
    parts: tuple[str, ...] = PART_NAMES  # the body parts whose motion is reliable (the rest is masked)

    @property
    def num_frames(self) -> int:
        return int(self.motion.shape[0])

    @property
    def full_body(self) -> bool:
        return holds_every_part(self.parts)


def aligned_audio_features(audio: np.ndarray, num_frames: int, config: FeatureConfig) -> np.ndarray:
    """(N,) 16 kHz samples of ``num_frames`` motion frames → (num_frames, F), the last frame repeated if short."""
    features = extract_features(audio, config)[:num_frames]  # (≤ T, F)
    if len(features) == 0:
        return np.zeros((num_frames, config.num_features), np.float32)
    missing = num_frames - len(features)
    return np.concatenate([features, np.repeat(features[-1:], missing, axis=0)]) if missing else features


def augmentation(has_audio: bool, split: str, mirror_motion_only: bool, paired_speeds: tuple[float, ...]):
    if split != "train":
        return AugmentConfig(mirror=False, speeds=())
    if has_audio:
        return AugmentConfig(mirror=True, speeds=paired_speeds)
    return AugmentConfig(mirror=mirror_motion_only, speeds=())


def voice_variants(tag: str, audio: np.ndarray | None, copies: int,
                   rng: np.random.Generator) -> list[tuple[str, np.ndarray | None]]:
    """The variant's own audio, then ``copies`` random new voices of it (none without audio)."""
    if audio is None:
        return [(tag, None)]
    return [(tag, audio), *((f"{tag}+voice{i}", random_voice(audio, SAMPLE_RATE, rng)) for i in range(copies))]


def take_speakers(cache_dir: Path, record: dict, audio: np.ndarray | None,
                  respoken: int) -> list[tuple[str, np.ndarray | None]]:
    """("", the take's own audio), then ("+tts-VOICE", its words re-spoken) for the first ``respoken`` training
    voices (models/dataset/respeak.py); only the own audio for takes without speech."""
    if audio is None or respoken == 0:
        return [("", audio)]
    words = cached_words(cache_dir, record, audio)
    return [("", audio), *((f"+tts-{voice.voice}", respeak(audio, words, voice))
                           for voice in TRAINING_VOICES[:respoken])]


def training_style(record: dict, has_audio: bool, paired_style: str) -> str:
    """The label a take trains under: ``paired_style`` for a take with speech when given, else the take's own."""
    return canonical_style(paired_style if paired_style and has_audio else record["style"])


def variant_clips(record: dict, part: SkeletonMotion, part_audio: np.ndarray | None, speaker_tag: str,
                  augment: AugmentConfig, copies: int, feature_config: FeatureConfig,
                  rng: np.random.Generator, style: str) -> list[TrainingClip]:
    """One segment in one speaker's audio: its augmented variants, each with ``copies`` waveform voice copies."""
    clips = []
    for tag, variant, variant_audio in augmented_variants(part, part_audio, augment, SAMPLE_RATE):
        features = motion_to_features(variant)  # (T, D)
        for voice_tag, voice_audio in voice_variants(tag + speaker_tag, variant_audio, copies, rng):
            audio_features = (
                None if voice_audio is None else aligned_audio_features(voice_audio, len(features), feature_config)
            )
            clips.append(TrainingClip(record["name"], record["dataset"], style, voice_tag,
                                      features, audio_features, voice_tag != tag, tuple(record["parts"])))
    return clips


def load_training_clips(
    cache_dir: Path,
    split: str,
    feature_config: FeatureConfig,
    mirror_motion_only: bool = True,
    paired_speeds: tuple[float, ...] = (),
    progress: bool = True,
    voice_copies: int = 0,
    seed: int = 0,
    partial_takes: bool = False,
    respoken_copies: int = 0,
    paired_style: str = "",
) -> list[TrainingClip]:
    """Every segment of ``split`` in the cache, augmented for training, with audio features; takes that hold only
    some body parts (SHOW) only when ``partial_takes``. In ``train``, each paired take also comes with
    ``voice_copies`` waveform voice copies per variant and ``respoken_copies`` re-spoken TTS copies. Takes with
    speech train under ``paired_style`` when it is given."""
    clips = []
    rng = np.random.default_rng(seed)
    copies = voice_copies if split == "train" else 0
    respoken = respoken_copies if split == "train" else 0
    records = [record for record in read_index(cache_dir)["takes"] if partial_takes or is_full_body(record)]
    for record in tqdm(records, desc=f"load {split}", unit="take", disable=not progress):
        segments = [s for s in record["segments"] if s["split"] == split]
        if not segments:
            continue
        motion, audio = load_take(cache_dir, record)
        augment = augmentation(audio is not None, split, mirror_motion_only, paired_speeds)
        speakers = take_speakers(cache_dir, record, audio, respoken)
        style = training_style(record, audio is not None, paired_style)
        for segment in segments:
            part = motion.slice(segment["start"], segment["stop"])
            for speaker_tag, speaker_audio in speakers:
                part_audio = None if speaker_audio is None else slice_audio(
                    speaker_audio, segment["start"], segment["stop"], motion.fps, SAMPLE_RATE)
                clips.extend(variant_clips(record, part, part_audio, speaker_tag, augment,
                                           0 if speaker_tag else copies, feature_config, rng, style))
    return clips


def dataset_summary(clips: list[TrainingClip], fps: float) -> dict:
    """Minutes of (augmented) motion per dataset and of paired speech, and the styles seen."""
    minutes: dict[str, float] = {}
    for clip in clips:
        minutes[clip.dataset] = minutes.get(clip.dataset, 0.0) + clip.num_frames / fps / 60.0
    paired = sum(clip.num_frames for clip in clips if clip.audio is not None) / fps / 60.0
    return {
        "clips": len(clips),
        "minutes_per_dataset": {name: round(value, 2) for name, value in sorted(minutes.items())},
        "paired_minutes": round(paired, 2),
        "styles": sorted({clip.style for clip in clips}),
    }
