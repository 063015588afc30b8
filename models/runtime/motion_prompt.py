"""onnxruntime wrapper of the exported motion-prompt encoder (numpy + onnxruntime only)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gesturecast.models.runtime.ort_session import DEFAULT_THREADS, make_session


class MotionPromptRuntime:
    def __init__(self, path: Path | str | bytes, threads: int = DEFAULT_THREADS):
        self.session = make_session(path, threads)

    def embed(self, features: np.ndarray) -> np.ndarray:
        """(T, D) canonical motion features → (S,) unit style embedding."""
        batch = np.asarray(features, dtype=np.float32)[None]  # (1, T, D)
        (embedding,) = self.session.run(None, {"features": batch})
        return embedding[0]
