"""The bundled default model as it is committed: it loads, is small, and generates finite motion."""

from pathlib import Path

import numpy as np
import onnx
from onnx import TensorProto

from gesturecast.models.runtime.bundle import ONNX_FILES, ModelBundle
from gesturecast.realtime.generation.generator import Generator, GeneratorSettings

DEFAULT_BUNDLE = Path(__file__).resolve().parents[3] / "models" / "weights" / "default"
MAX_BUNDLE_BYTES = 7_000_000  # "a few MB" (format 2: three part VQ-VAEs, 6.3 MB): the README states the size
LATENTS = 3


def test_default_bundle_is_complete_small_and_stores_half_precision_weights():
    sizes = {name: (DEFAULT_BUNDLE / name).stat().st_size for name in [*ONNX_FILES.values(), "model.json"]}
    assert sum(sizes.values()) < MAX_BUNDLE_BYTES, sizes
    initializers = onnx.load(str(DEFAULT_BUNDLE / ONNX_FILES["denoiser"])).graph.initializer
    assert any(init.data_type == TensorProto.FLOAT16 for init in initializers)


def test_default_bundle_generates_finite_motion_of_the_right_shape():
    bundle = ModelBundle.load(DEFAULT_BUNDLE)
    generator = Generator(bundle, GeneratorSettings())
    rng = np.random.default_rng(0)
    windows = rng.standard_normal((LATENTS, bundle.audio_window, bundle.denoiser_config.audio_dim)).astype(np.float32)
    motion = np.concatenate([generator.step(window) for window in windows])
    assert motion.shape == (LATENTS * bundle.frames_per_latent, bundle.motion_feature_dim)
    assert np.isfinite(motion).all()
    assert np.ptp(motion, axis=0).max() > 0  # it moves
