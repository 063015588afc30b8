"""One VQ-VAE per body part behind one interface: columns, stacking, streaming parity, ONNX, checkpoints."""

import numpy as np
import pytest
import torch

from gesturecast.models.export.bundle import VQEncodeGraph
from gesturecast.models.export.vq import export_vq_decoder_step
from gesturecast.models.motion.body_parts import PART_NAMES, body_part, body_parts
from gesturecast.models.motion.motion_features import FEATURE_DIM
from gesturecast.models.networks.part_vqvae import (
    PartVQVAE,
    PartVQVAEConfig,
    load_motion_vq,
    motion_vq_checkpoint,
    part_channel_masks,
)
from gesturecast.models.networks.vqvae import VQVAEConfig
from gesturecast.models.runtime.vq import StreamingVQDecoder

LATENTS = (4, 2, 3)


def make_model(seed: int = 0) -> PartVQVAE:
    torch.manual_seed(seed)
    configs = tuple(VQVAEConfig(feature_dim=part.feature_dim, hidden_dim=16, latent_dim=latent, codebook_size=8,
                                res_blocks_per_stage=1) for part, latent in zip(body_parts(), LATENTS, strict=True))
    return PartVQVAE(PartVQVAEConfig(PART_NAMES, configs)).eval()


def test_parts_cover_every_feature_column_once_and_legs_own_the_root():
    columns = np.concatenate([part.columns for part in body_parts()])
    assert sorted(columns.tolist()) == list(range(FEATURE_DIM))
    assert set(range(4)) <= set(body_part("legs").columns)  # root height, planar velocity, yaw rate
    assert body_part("arms").feature_dim == 8 * 6 and body_part("torso").feature_dim == 5 * 6
    with pytest.raises(ValueError, match="unknown body part"):
        body_part("tail")


def test_stacked_latent_has_each_parts_channels_and_decoding_restores_canonical_order():
    model = make_model()
    x = torch.randn(2, 16, FEATURE_DIM)  # (B, T, D)
    encoding = model.encode(x)
    assert encoding.quantized.shape == (2, 4, sum(LATENTS)) and encoding.codes.shape == (2, 4, 3)
    slices = model.config.latent_slices()
    arms_only = model.models[0].encode(x[..., list(body_part("arms").columns)]).quantized
    torch.testing.assert_close(encoding.quantized[..., slices["arms"]], arms_only)
    decoded = model.decode(encoding.quantized)  # (B, T, D)
    torso = model.models[1].decode(encoding.quantized[..., slices["torso"]])
    torch.testing.assert_close(decoded[..., list(body_part("torso").columns)], torso)


def test_changing_one_parts_latent_changes_only_that_parts_columns():
    model = make_model()
    latents = torch.randn(1, 3, sum(LATENTS))
    changed = latents.clone()
    changed[..., model.config.latent_slices()["torso"]] += 1.0
    difference = (model.decode(changed) - model.decode(latents)).abs().amax(dim=(0, 1))  # (D,)
    torso = list(body_part("torso").columns)
    others = [c for c in range(FEATURE_DIM) if c not in torso]
    assert difference[torso].max() > 1e-3 and difference[others].max() == 0.0


def test_streaming_part_decoder_equals_offline_and_its_onnx_export_matches():
    model = make_model(1)
    latents = torch.randn(1, 5, sum(LATENTS))
    offline = model.decode(latents)[0].detach().numpy()  # (T, D)
    decoder, state, frames = model.decoder, model.decoder.initial_state(), []
    for n in range(5):
        step_frames, state = decoder.step(latents[:, n], state)
        frames.append(step_frames[0].detach().numpy())
    np.testing.assert_allclose(np.concatenate(frames), offline, atol=1e-5)  # float32 conv order, as test_vqvae
    runtime = StreamingVQDecoder(export_vq_decoder_step(model))
    onnx_frames = np.concatenate([runtime.step(latents[0, n].numpy()) for n in range(5)])
    np.testing.assert_allclose(onnx_frames, offline, atol=1e-5)


def test_encoder_graph_and_checkpoint_roundtrip():
    model = make_model(2)
    x = torch.randn(1, 8, FEATURE_DIM)
    torch.testing.assert_close(VQEncodeGraph(model)(x), model.encode(x).quantized)
    rebuilt = load_motion_vq(motion_vq_checkpoint(model))
    assert isinstance(rebuilt, PartVQVAE) and rebuilt.config == model.config
    torch.testing.assert_close(rebuilt.decode(model.encode(x).quantized), model.decode(model.encode(x).quantized))


def test_channel_masks_partition_the_latent():
    config = make_model().config
    masks = part_channel_masks(config.latent_slices(), config.latent_dim)
    np.testing.assert_array_equal(sum(masks.values()), np.ones(config.latent_dim))


def test_a_part_config_must_match_its_columns():
    wrong = tuple(VQVAEConfig(feature_dim=10) for _ in PART_NAMES)
    with pytest.raises(ValueError, match="feature columns"):
        PartVQVAEConfig(PART_NAMES, wrong)
