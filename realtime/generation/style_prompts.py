"""Style prompts → style embeddings in the denoiser's style space (numpy + onnxruntime, no torch).

Three kinds of prompt (GestureDiffuCLIP §4.1: text, motion; DiffuseStyleGesture: labels):

- ``label``: a vocabulary label or synonym ("happy", "elderly") → the embedding precomputed into
  the bundle at training time (unknown labels raise :class:`UserError` listing the known ones);
- ``text``: any free text → wordllama embedding of the same prompt template used in training;
- ``motion``: a BVH/NPZ clip of any supported skeleton → canonical features → motion_prompt.onnx.

On the command line: ``happy``, ``text:calm and slow``, ``motion:clip.bvh``; per body part (GestureDiffuCLIP
§6.3): ``--part-style arms=happy "torso=text:tired and bent"``.
"""

from __future__ import annotations

import threading
from pathlib import Path

import numpy as np

from gesturecast.errors import UserError
from gesturecast.models.generator.style_prompt import StylePrompt
from gesturecast.models.runtime.bundle import ModelBundle
from gesturecast.models.runtime.ort_session import DEFAULT_THREADS


class StyleResolver:
    """Turns :class:`StylePrompt` objects into (S,) float32 embeddings; loads wordllama / ONNX lazily.

    Thread-safe: a control is resolved on the server thread (to refuse it before acknowledging) while
    the session thread resolves the styles it applies."""

    def __init__(self, bundle: ModelBundle, threads: int = DEFAULT_THREADS):
        self.bundle = bundle
        self.threads = threads
        self._text_embedder = None
        self._motion_prompt = None
        self._lock = threading.Lock()

    def embed(self, prompt: StylePrompt) -> np.ndarray:
        """(S,) embedding; UserError for an unknown label, a text with nothing to embed, or a bad clip."""
        with self._lock:
            if prompt.kind == "label":
                return self.bundle.styles.embedding(prompt.value)
            if prompt.kind == "text":
                return self._embed_text(prompt.value)
            return self._embed_motion(Path(prompt.value))

    def _embed_text(self, text: str) -> np.ndarray:
        if self._text_embedder is None:
            from gesturecast.models.generator.style_text import StyleTextEmbedder

            self._text_embedder = StyleTextEmbedder()
        return self._text_embedder.embed_labels([text])[0]

    def _embed_motion(self, path: Path) -> np.ndarray:
        from gesturecast.models.motion.motion_features import face_forward, motion_to_features
        from gesturecast.models.motion.retarget import load_motion_file

        if not path.is_file():
            raise UserError(f"motion style prompt not found: {path}")
        if self._motion_prompt is None:
            self._motion_prompt = self.bundle.motion_prompt(self.threads)
        features = motion_to_features(face_forward(load_motion_file(path)))  # (T, D)
        return self._motion_prompt.embed(features)
