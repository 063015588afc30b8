"""The model artifact the live runtime loads: ``model.json`` + ONNX files in one directory.

Layout of a bundle directory (e.g. ``models/weights/default/``)::

    model.json          format_version, timing (fps, d, δa, audio window), audio FeatureConfig,
                        normalisation statistics (motion features, latents, audio features), the
                        style vocabulary with precomputed wordllama label embeddings, the null-style
                        handling, default guidance, diffusion schedule, component configs,
                        training summary and license
    denoiser.onnx       one causal denoiser step (KV cache in/out), see export_denoiser
    denoiser_condition.onnx  a frame's condition (audio token + style modulations), once per latent
    vq_decoder.onnx     one streaming VQ decoder step (state in/out) of the stacked latent: the body
                        parts' code vectors side by side, channels per part in ``body_parts``
    vq_encoder.onnx     motion features (1, T, D) → quantized latents (1, T/d, C), for seed gestures
    motion_prompt.onnx  motion features (1, T, D) → (1, S) style embedding

A bundle is rebuilt from JSON + ONNX only — never by unpickling — with numpy and onnxruntime
(no torch import): this module is what the live runtime loads.
"""

from __future__ import annotations

import json
import logging
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gesturecast.errors import UserError
from gesturecast.input_files import read_bounded
from gesturecast.models.audio.stats import FeatureStats
from gesturecast.models.audio.streaming import FeatureConfig
from gesturecast.models.generator.denoiser_config import DenoiserConfig
from gesturecast.models.generator.diffusion import DEFAULT_DDIM_STEPS
from gesturecast.models.generator.styles import canonical_style
from gesturecast.models.runtime.denoiser_runtime import DenoiserRuntime, condition_path
from gesturecast.models.runtime.motion_prompt import MotionPromptRuntime
from gesturecast.models.runtime.ort_session import DEFAULT_THREADS, make_session

logger = logging.getLogger(__name__)

BUNDLE_FORMAT_VERSION = 2  # 2: one VQ-VAE per body part, stacked latents (``body_parts``)
MANIFEST_FILE = "model.json"
MAX_MANIFEST_BYTES = 64 << 20  # the default model's manifest is 0.2 MB; a larger one is not a manifest
ONNX_FILES = {
    "denoiser": "denoiser.onnx",
    "denoiser_condition": condition_path("denoiser.onnx").name,  # written by export_denoiser next to it
    "vq_decoder": "vq_decoder.onnx",
    "vq_encoder": "vq_encoder.onnx",
    "motion_prompt": "motion_prompt.onnx",
}
NULL_STYLE_NOTE = "learned null style inside the denoiser, selected by style_present = 0 (classifier-free guidance)"
LICENSE_NOTE = (
    "Non-commercial use only: trained on ZeroEGGS (CC BY-NC-ND 4.0), BEAT2 (CC BY-NC 4.0) and the "
    "Bandai Namco Research Motion Dataset (CC BY-NC 4.0)."
)
STD_FLOOR = 1e-4  # normalisation never divides by (almost) zero


@dataclass(frozen=True)
class Normalizer:
    """Per-channel ``(x − mean) / std`` and its inverse; (C,) float32 statistics."""

    mean: np.ndarray
    std: np.ndarray

    @classmethod
    def fit(cls, arrays: list[np.ndarray], std_floor: float = STD_FLOOR) -> Normalizer:
        """Statistics over all rows of (T_i, C) arrays (float64 accumulation); std at least ``std_floor``."""
        stacked = np.concatenate([np.asarray(a, np.float64) for a in arrays])  # (ΣT, C)
        std = np.maximum(stacked.std(axis=0), std_floor)
        return cls(stacked.mean(axis=0).astype(np.float32), std.astype(np.float32))

    def normalize(self, values: np.ndarray) -> np.ndarray:
        return ((values - self.mean) / self.std).astype(np.float32)

    def denormalize(self, values: np.ndarray) -> np.ndarray:
        return (values * self.std + self.mean).astype(np.float32)

    def to_dict(self) -> dict[str, list[float]]:
        return {"mean": [float(v) for v in self.mean], "std": [float(v) for v in self.std]}

    @classmethod
    def from_dict(cls, values: dict) -> Normalizer:
        return cls(np.asarray(values["mean"], np.float32), np.asarray(values["std"], np.float32))


@dataclass(frozen=True)
class StyleTable:
    """The style vocabulary and its precomputed (L, S) unit embeddings; ``trained`` = labels seen in training."""

    labels: tuple[str, ...]
    embeddings: np.ndarray
    trained: tuple[str, ...]
    prompt_template: str

    def embedding(self, label: str) -> np.ndarray:
        """(S,) embedding of a label or any of its synonyms; unknown labels raise UserError."""
        try:
            name = canonical_style(label)
        except UserError:
            name = None
        if name not in self.labels:
            raise UserError(f"unknown style {label!r}; known styles: {', '.join(self.labels)}")
        return self.embeddings[self.labels.index(name)]

    def to_dict(self) -> dict:
        return {
            "labels": list(self.labels),
            "trained": list(self.trained),
            "prompt_template": self.prompt_template,
            "embeddings": [[float(v) for v in row] for row in self.embeddings],
            "null_style": NULL_STYLE_NOTE,
        }

    @classmethod
    def from_dict(cls, values: dict) -> StyleTable:
        embeddings = np.asarray(values["embeddings"], np.float32)  # (L, S)
        if embeddings.shape[0] != len(values["labels"]):
            raise ValueError("style table: one embedding row per label expected")
        return cls(tuple(values["labels"]), embeddings, tuple(values["trained"]), values["prompt_template"])


def write_manifest(directory: Path, manifest: dict) -> Path:
    """Write ``model.json`` (format version stamped in) and check the ONNX files are present."""
    missing = [name for name in ONNX_FILES.values() if not (directory / name).is_file()]
    if missing:
        raise ValueError(f"bundle {directory} lacks {missing}")
    path = directory / MANIFEST_FILE
    path.write_text(json.dumps({"format_version": BUNDLE_FORMAT_VERSION, **manifest}, indent=1))
    return path


def read_manifest(directory: Path) -> dict:
    """The parsed model.json of a bundle; missing files or another format version raise UserError."""
    path = Path(directory) / MANIFEST_FILE
    if not path.is_file():
        raise UserError(f"no model bundle at {directory} (missing {MANIFEST_FILE}); train and export one first")
    try:
        manifest = json.loads(read_bounded(path, MAX_MANIFEST_BYTES, "model manifest").decode("utf-8"))
    except ValueError as error:  # JSONDecodeError and UnicodeDecodeError are ValueErrors
        raise UserError(f"{path} is not a readable model manifest ({error}); re-export the bundle") from None
    if not isinstance(manifest, dict):
        raise UserError(f"{path} is not a model manifest (a JSON object is expected); re-export the bundle")
    version = manifest.get("format_version")
    if version != BUNDLE_FORMAT_VERSION:
        raise UserError(f"{path} has format version {version!r}; this gesturecast reads {BUNDLE_FORMAT_VERSION} "
                        "(one VQ-VAE per body part): retrain with `gesturecast train` and export it")
    missing = [name for name in ONNX_FILES.values() if not (Path(directory) / name).is_file()]
    if missing:
        raise UserError(f"model bundle {directory} is incomplete: missing {', '.join(missing)}")
    return manifest


@dataclass(frozen=True)
class ModelBundle:
    """Everything the live generator needs, read from a bundle directory (numpy + onnxruntime)."""

    directory: Path
    manifest: dict
    denoiser_config: DenoiserConfig
    feature_config: FeatureConfig
    motion_stats: Normalizer
    latent_stats: Normalizer
    audio_stats: FeatureStats
    styles: StyleTable
    default_guidance: float
    default_steps: int  # DDIM steps K the model runs at unless told (4 for bundles exported before the field)
    schedule_name: str
    part_channels: dict[str, slice]  # each body part's channels of the stacked latent

    @classmethod
    def load(cls, directory: Path | str) -> ModelBundle:
        """Read a bundle; a missing, malformed or non-finite part raises UserError naming the manifest."""
        directory = Path(directory)
        manifest = read_manifest(directory)
        try:
            bundle = cls._from_manifest(directory, manifest)
        except (KeyError, TypeError, ValueError, AttributeError) as error:
            raise UserError(f"{directory / MANIFEST_FILE} is malformed ({type(error).__name__}: {error}); "
                            "re-export the bundle") from None
        bundle.check_finite()
        return bundle

    @classmethod
    def _from_manifest(cls, directory: Path, manifest: dict) -> ModelBundle:
        return cls(
            directory=directory,
            manifest=manifest,
            denoiser_config=DenoiserConfig.from_dict(manifest["denoiser"]),
            feature_config=FeatureConfig.from_dict(manifest["audio_features"]),
            motion_stats=Normalizer.from_dict(manifest["motion_stats"]),
            latent_stats=Normalizer.from_dict(manifest["latent_stats"]),
            audio_stats=FeatureStats.from_dict(manifest["audio_stats"]),
            styles=StyleTable.from_dict(manifest["styles"]),
            default_guidance=float(manifest["guidance"]["default_scale"]),
            default_steps=int(manifest.get("sampler", {}).get("default_steps", DEFAULT_DDIM_STEPS)),
            schedule_name=manifest["diffusion"]["schedule"],
            part_channels={name: slice(*part["latent_channels"]) for name, part in manifest["body_parts"].items()},
        )

    def check_finite(self) -> None:
        """UserError if any statistic, style embedding or the default guidance is NaN or infinite
        (one such number would turn every generated pose into NaN)."""
        arrays = {
            "motion_stats": (self.motion_stats.mean, self.motion_stats.std),
            "latent_stats": (self.latent_stats.mean, self.latent_stats.std),
            "audio_stats": (self.audio_stats.mean, self.audio_stats.std),
            "styles.embeddings": (self.styles.embeddings,),
            "guidance.default_scale": (np.asarray(self.default_guidance),),
        }
        bad = [name for name, values in arrays.items() if not all(np.isfinite(v).all() for v in values)]
        if bad:
            raise UserError(f"{self.directory / MANIFEST_FILE} holds NaN or infinite numbers in {', '.join(bad)}; "
                            "re-export the bundle from a healthy checkpoint")

    @property
    def frames_per_latent(self) -> int:
        return self.denoiser_config.frames_per_latent

    @property
    def audio_lookahead(self) -> int:
        return self.denoiser_config.audio_lookahead

    @property
    def audio_window(self) -> int:
        return self.denoiser_config.audio_window

    @property
    def motion_feature_dim(self) -> int:
        return int(self.manifest["motion_feature_dim"])

    def path(self, component: str) -> Path:
        return self.directory / ONNX_FILES[component]

    def denoiser(self, threads: int = DEFAULT_THREADS) -> DenoiserRuntime:
        return DenoiserRuntime(self.path("denoiser"), threads)

    def vq_decoder(self, threads: int = DEFAULT_THREADS):
        from gesturecast.models.runtime.vq import StreamingVQDecoder

        return StreamingVQDecoder(self.path("vq_decoder"), threads)

    def vq_encoder(self, threads: int = DEFAULT_THREADS) -> VQEncoderRuntime:
        return VQEncoderRuntime(self.path("vq_encoder"), threads)

    def motion_prompt(self, threads: int = DEFAULT_THREADS) -> MotionPromptRuntime:
        return MotionPromptRuntime(self.path("motion_prompt"), threads)


class VQEncoderRuntime:
    """onnxruntime VQ encoder: (T, D) normalized motion features → (T // d, C) quantized latents."""

    def __init__(self, path: Path | str, threads: int = DEFAULT_THREADS):
        self.session = make_session(path, threads)

    def encode(self, features: np.ndarray) -> np.ndarray:
        batch = np.asarray(features, np.float32)[None]  # (1, T, D)
        (latents,) = self.session.run(None, {"features": batch})
        return latents[0]  # (N, C)
