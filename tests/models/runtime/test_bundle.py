import json
import shutil
import subprocess
import sys

import numpy as np
import pytest
import torch

from gesturecast.errors import UserError
from gesturecast.models.export.bundle import bundle_models
from gesturecast.models.generator.diffusion import CLEAN_TIMESTEP, get_schedule, sampler_step, sampling_plan
from gesturecast.models.generator.style_prompt import StylePrompt
from gesturecast.models.networks.denoiser_network import KVCache
from gesturecast.models.runtime.bundle import MANIFEST_FILE, ONNX_FILES, ModelBundle
from gesturecast.realtime.generation.generator import Generator, GeneratorSettings, guide_trajectories

GUIDANCE = 2.0
SEED = 11
LATENT_STEPS = 2  # the second step runs with the first latent in the KV cache


@pytest.fixture(scope="module")
def bundle(tiny_model):
    return ModelBundle.load(tiny_model[1])


def torch_generator_steps(checkpoint, bundle, generator: Generator, windows: np.ndarray) -> np.ndarray:
    """The generator's latent steps recomputed with the torch models (same noise, same guidance rows)."""
    vqvae, denoiser, _ = bundle_models(checkpoint)
    schedule = get_schedule(bundle.schedule_name)
    layout = generator.layout
    rng = np.random.default_rng(SEED)
    cache = KVCache.empty(denoiser.config, layout.batch)
    decoder_state = vqvae.decoder.initial_state(1)
    styles = torch.as_tensor(layout.styles)  # (B, S)
    style_present = torch.as_tensor(layout.style_present)  # (B,)
    frames = []
    with torch.no_grad():
        for window in windows:
            audio = torch.as_tensor(window)[None].expand(layout.batch, -1, -1)  # (B, A, F)
            x = rng.standard_normal(bundle.denoiser_config.latent_dim)  # (C,)
            for t, t_prev in sampling_plan(schedule.num_timesteps, generator.settings.sampler):
                rows = torch.as_tensor(x, dtype=torch.float32)[None].expand(layout.batch, -1)  # (B, C)
                timesteps = torch.full((layout.batch,), t, dtype=torch.int64)
                x0_rows, _ = denoiser.step(rows, timesteps, audio, styles, cache, style_present=style_present)
                x0 = guide_trajectories(x0_rows.numpy(), layout, 1.0, GUIDANCE)[0]  # one style: one trajectory
                x = sampler_step(schedule, generator.settings.sampler, x0, t, t_prev, x)
            clean = torch.as_tensor(x, dtype=torch.float32)[None].expand(layout.batch, -1)  # (B, C)
            commit_t = torch.full((layout.batch,), CLEAN_TIMESTEP, dtype=torch.int64)
            _, cache = denoiser.step(clean, commit_t, audio, styles, cache, style_present=style_present)
            latent = torch.as_tensor(bundle.latent_stats.denormalize(x))[None]  # (1, C)
            decoded, decoder_state = vqvae.decoder.step(latent, decoder_state)  # (1, d, D)
            frames.append(bundle.motion_stats.denormalize(decoded[0].numpy()))
    return np.concatenate(frames)


def test_onnxruntime_generator_matches_torch_for_full_latent_steps(tiny_model, bundle):
    windows = np.random.default_rng(3).standard_normal(
        (LATENT_STEPS, bundle.audio_window, bundle.denoiser_config.audio_dim)
    ).astype(np.float32)
    generator = Generator(bundle, GeneratorSettings(style=StylePrompt("label", "old"), guidance=GUIDANCE, seed=SEED))
    onnx_frames = np.concatenate([generator.step(window, True) for window in windows])
    torch_frames = torch_generator_steps(tiny_model[0], bundle, generator, windows)
    assert generator.layout.batch == 2
    np.testing.assert_allclose(onnx_frames, torch_frames, atol=1e-4, rtol=0)


def test_manifest_carries_configs_statistics_styles_and_training_summary(bundle):
    manifest = bundle.manifest
    assert manifest["fps"] == 30 and manifest["frames_per_latent"] == bundle.frames_per_latent == 4
    assert manifest["audio_lookahead"] == 8 and manifest["diffusion"]["schedule"] == "cosine_1000"
    assert set(bundle.styles.trained) == {"neutral", "old", "happy"}
    assert set(bundle.styles.trained) <= set(bundle.styles.labels)
    np.testing.assert_allclose(np.linalg.norm(bundle.styles.embeddings, axis=1), 1.0, atol=1e-5)
    assert bundle.motion_stats.mean.shape == (manifest["motion_feature_dim"],)
    assert bundle.audio_stats.mean.shape == (bundle.feature_config.num_features,)
    training = manifest["training"]
    assert training["preset"] == "tiny" and training["parameters"]["denoiser"] > 0
    assert "non-commercial" in manifest["license"].lower()
    np.testing.assert_array_equal(bundle.styles.embedding("elderly"), bundle.styles.embedding("old"))


def test_wrong_format_version_or_missing_file_is_a_user_error(tiny_model, tmp_path):
    copy = shutil.copytree(tiny_model[1], tmp_path / "bundle")
    manifest = json.loads((copy / MANIFEST_FILE).read_text())
    (copy / MANIFEST_FILE).write_text(json.dumps({**manifest, "format_version": 99}))
    with pytest.raises(UserError, match="format version 99"):
        ModelBundle.load(copy)
    (copy / MANIFEST_FILE).write_text(json.dumps(manifest))
    (copy / ONNX_FILES["vq_decoder"]).unlink()
    with pytest.raises(UserError, match="vq_decoder.onnx"):
        ModelBundle.load(copy)
    with pytest.raises(UserError, match="no model bundle"):
        ModelBundle.load(tmp_path / "nowhere")


def test_bundle_and_generator_run_without_importing_torch(tiny_model):
    script = (
        "import sys, numpy as np\n"
        "from gesturecast.models.runtime.bundle import ModelBundle\n"
        "from gesturecast.realtime.generation.generator import Generator\n"
        f"bundle = ModelBundle.load({str(tiny_model[1])!r})\n"
        "frames = Generator(bundle).step(np.zeros((bundle.audio_window, bundle.denoiser_config.audio_dim)), True)\n"
        "assert np.isfinite(frames).all()\n"
        "print('torch' in sys.modules)\n"
    )
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True)
    assert result.stdout.strip() == "False"
