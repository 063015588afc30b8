"""Training checkpoint → model bundle directory (ONNX files + model.json), the format of models/bundle.py.

Exports the denoiser (condition and step graphs, export_denoiser), the VQ decoder step (export_vq),
the VQ encoder with quantization (here: seed gestures), and the motion-prompt encoder; then writes the
manifest with configs, statistics, style table and the training summary. Weights are rounded to
float16 and stored that way (half the size; onnxruntime still computes in float32, see onnx_half).
"""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

import torch
from torch import nn

from gesturecast.errors import UserError
from gesturecast.models.export.denoiser_onnx import export_denoiser
from gesturecast.models.export.motion_prompt import export_motion_prompt
from gesturecast.models.export.onnx_half import round_weights_to_half, store_weights_in_half
from gesturecast.models.export.vq import export_vq_decoder_step
from gesturecast.models.generator.denoiser_config import DenoiserConfig
from gesturecast.models.generator.diffusion import DEFAULT_DDIM_STEPS, DEFAULT_NUM_TIMESTEPS, DEFAULT_SCHEDULE
from gesturecast.models.motion.body_parts import body_parts
from gesturecast.models.networks.denoiser_network import CausalDenoiser
from gesturecast.models.networks.motion_prompt import MotionPromptConfig, MotionPromptEncoder
from gesturecast.models.networks.part_vqvae import PartVQVAE, PartVQVAEConfig, load_motion_vq
from gesturecast.models.runtime.bundle import LICENSE_NOTE, ONNX_FILES, write_manifest
from gesturecast.models.training.pipeline import STAGES

OPSET_VERSION = 17
EXAMPLE_LATENTS = 8
BUNDLE_FOLDER_MODE = 0o755
WEIGHTS_NOTE = "rounded to float16 and stored as float16; onnxruntime computes in float32"


class VQEncodeGraph(nn.Module):
    """features (B, T, D) → quantized latents (B, T/d, C): encoder + nearest codebook vector."""

    def __init__(self, model: PartVQVAE):
        super().__init__()
        self.model = model

    def forward(self, features: torch.Tensor) -> torch.Tensor:
        return self.model.quantized_latents(features)  # (B, N, C)


def export_vq_encoder(model: PartVQVAE, path: Path) -> Path:
    example = torch.zeros(1, EXAMPLE_LATENTS * model.config.downsample, model.config.feature_dim)
    with torch.no_grad():
        torch.onnx.export(VQEncodeGraph(model.eval()), (example,), str(path), input_names=["features"],
                          output_names=["latents"],
                          dynamic_axes={"features": {0: "batch", 1: "frames"}, "latents": {0: "batch", 1: "latents"}},
                          opset_version=OPSET_VERSION, dynamo=False)
    return path


def models_from_checkpoint(checkpoint: dict) -> tuple[PartVQVAE, CausalDenoiser, MotionPromptEncoder]:
    """Rebuild the three torch models from a training checkpoint's plain data."""
    stages = checkpoint["stages"]
    missing = [stage for stage in STAGES if stage not in stages]
    if missing:
        raise UserError(f"the checkpoint has not finished training (missing {', '.join(missing)}); run train --resume")
    vqvae = load_motion_vq(stages["vqvae"]["model"])
    if not isinstance(vqvae, PartVQVAE):
        raise UserError("the checkpoint has one whole-body VQ-VAE (checkpoint format 1); bundles since format 2 "
                        "need one per body part: retrain with `gesturecast train`")
    denoiser = CausalDenoiser(DenoiserConfig.from_dict(stages["denoiser"]["config"]))
    denoiser.load_state_dict(stages["denoiser"]["state"])
    prompt = MotionPromptEncoder(MotionPromptConfig(**stages["motion_prompt"]["config"]))
    prompt.load_state_dict(stages["motion_prompt"]["state"])
    return vqvae, denoiser.eval(), prompt.eval()


def bundle_models(checkpoint: dict) -> tuple[PartVQVAE, CausalDenoiser, MotionPromptEncoder]:
    """The torch models exactly as a bundle ships them: the checkpoint's weights rounded to float16."""
    vqvae, denoiser, prompt = models_from_checkpoint(checkpoint)
    return round_weights_to_half(vqvae), round_weights_to_half(denoiser), round_weights_to_half(prompt)


def training_summary(checkpoint: dict) -> dict:
    stages = checkpoint["stages"]
    preset = checkpoint["preset"]
    return {
        "preset": preset["name"],
        "seed": preset["seed"],
        "data": stages["data"]["summary"],
        "steps": {"vqvae": preset["vq"]["steps"], "denoiser": preset["denoiser"]["steps"],
                  "motion_prompt": preset["prompt"]["steps"]},
        "stage_seconds": {key: round(value, 1) for key, value in checkpoint["stage_seconds"].items()},
        "parameters": {"vqvae": stages["vqvae"]["metrics"]["parameters"],
                       "denoiser": stages["denoiser"]["metrics"]["parameters"],
                       "motion_prompt": stages["motion_prompt"]["metrics"]["parameters"]},
        "final_losses": {"vqvae": stages["vqvae"]["metrics"]["final_losses"],
                         "denoiser": stages["denoiser"]["metrics"]["final_loss"],
                         "motion_prompt": stages["motion_prompt"]["metrics"]["final_loss"]},
        "vqvae_validation": {"parts": stages["vqvae"]["metrics"].get("val", {}),
                             **stages["vqvae"]["metrics"].get("val_joint_errors", {}),
                             "part_joint_errors": stages["vqvae"]["metrics"].get("val_part_joint_errors", {})},
        **checkpoint.get("summary", {}),
    }


def body_parts_manifest(config: PartVQVAEConfig) -> dict:
    """Each part's joints and its channels [start, end) of the stacked latent (what per-part styles mask)."""
    slices = config.latent_slices()
    return {part.name: {"joints": list(part.joints), "latent_channels": [slices[part.name].start,
                                                                           slices[part.name].stop]}
            for part in body_parts(config.parts)}


def bundle_manifest(checkpoint: dict) -> dict:
    stages = checkpoint["stages"]
    denoiser = stages["denoiser"]["config"]
    vq = PartVQVAEConfig.from_dict(stages["vqvae"]["model"]["config"])
    return {
        "fps": checkpoint["feature_config"]["fps"],
        "frames_per_latent": denoiser["frames_per_latent"],
        "audio_lookahead": denoiser["audio_lookahead"],
        "audio_window": denoiser["audio_window"],
        "audio_features": checkpoint["feature_config"],
        "motion_feature_dim": vq.feature_dim,
        "motion_stats": stages["data"]["motion_stats"],
        "latent_stats": stages["denoiser"]["latent_stats"],
        "audio_stats": stages["data"]["audio_stats"],
        "styles": stages["data"]["styles"],
        "guidance": {"default_scale": checkpoint["preset"]["default_guidance"]},
        "sampler": {"default_steps": checkpoint["preset"].get("sampler_steps", DEFAULT_DDIM_STEPS)},
        "diffusion": {"schedule": DEFAULT_SCHEDULE, "num_timesteps": DEFAULT_NUM_TIMESTEPS, "prediction": "x0"},
        "denoiser": denoiser,
        "vqvae": vq.to_dict(),
        "body_parts": body_parts_manifest(vq),
        "motion_prompt": stages["motion_prompt"]["config"],
        "files": dict(ONNX_FILES),
        "weights": WEIGHTS_NOTE,
        "training": training_summary(checkpoint),
        "license": LICENSE_NOTE,
    }


def export_bundle(checkpoint: dict, directory: Path) -> Path:
    """Write a complete bundle to ``directory`` (replaced only once the new one is complete)."""
    vqvae, denoiser, prompt = bundle_models(checkpoint)
    directory = Path(directory)
    directory.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(dir=directory.parent, prefix=f".{directory.name}-export-"))
    try:
        export_denoiser(denoiser, staging / ONNX_FILES["denoiser"])  # and ONNX_FILES["denoiser_condition"]
        export_vq_decoder_step(vqvae, staging / ONNX_FILES["vq_decoder"])
        export_vq_encoder(vqvae, staging / ONNX_FILES["vq_encoder"])
        export_motion_prompt(prompt, staging / ONNX_FILES["motion_prompt"])
        for name in ONNX_FILES.values():
            store_weights_in_half(staging / name)
        write_manifest(staging, bundle_manifest(checkpoint))
        staging.chmod(BUNDLE_FOLDER_MODE)  # mkdtemp makes it private; a bundle is shipped data
        if directory.exists():
            shutil.rmtree(directory)
        staging.rename(directory)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    return directory
