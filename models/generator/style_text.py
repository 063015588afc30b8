"""Text style embeddings from the packaged ``wordllama`` model (numpy only, weights ship in the wheel).

A style label (or any free text at run time, zero-shot in the spirit of GestureDiffuCLIP §4.1's CLIP
text latents) becomes a prompt "a person gesturing in a {label} way". Because every prompt shares the
template, raw embeddings are dominated by it (cosine ≈ 0.7 between "happy" and "tired"); the
embedding of the bare template is subtracted and the result L2-normalised, which makes synonyms
the nearest neighbours (tired/exhausted, old/elderly).

The model is always loaded from the package folder with downloads disabled: no network at run time.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from gesturecast.errors import UserError
from gesturecast.models.generator.styles import STYLE_SYNONYMS

logger = logging.getLogger(__name__)

PROMPT_TEMPLATE = "a person gesturing in a {label} way"
BARE_PROMPT = "a person gesturing in a way"
NORM_EPSILON = 1e-8


def style_prompt(label: str) -> str:
    """The text prompt of a style label or free-text style ("not-confident" → "... not confident way")."""
    return PROMPT_TEMPLATE.format(label=label.replace("-", " ").replace("_", " ").strip())


def load_wordllama():
    """The packaged WordLlama model, loaded from its installed folder with downloads disabled."""
    try:
        import wordllama
        from wordllama import WordLlama

        return WordLlama.load(cache_dir=Path(wordllama.__file__).parent, disable_download=True)
    except (ImportError, FileNotFoundError, OSError) as error:
        raise UserError(f"cannot load the packaged wordllama text model ({error}); reinstall gesturecast") from None


class StyleTextEmbedder:
    """Prompt → (S,) float32 unit vector (S = 256)."""

    def __init__(self):
        self.model = load_wordllama()
        self.template = self.model.embed([BARE_PROMPT], norm=True)[0].astype(np.float64)  # (S,)

    @property
    def dim(self) -> int:
        return int(self.template.shape[0])

    def embed_texts(self, texts: Sequence[str]) -> np.ndarray:
        """(n,) prompts → (n, S) template-centred, unit-norm float32 embeddings."""
        raw = self.model.embed(list(texts), norm=True).astype(np.float64)  # (n, S)
        centred = raw - self.template  # (n, S)
        norms = np.linalg.norm(centred, axis=1, keepdims=True)  # (n, 1)
        return (centred / np.maximum(norms, NORM_EPSILON)).astype(np.float32)

    def embed_labels(self, labels: Sequence[str]) -> np.ndarray:
        """(n,) style labels or free-text styles → (n, S) via :func:`style_prompt`."""
        return self.embed_texts([style_prompt(label) for label in labels])


def vocabulary_embeddings(embedder: StyleTextEmbedder) -> tuple[tuple[str, ...], np.ndarray]:
    """The canonical style vocabulary and its (L, S) embeddings, to precompute into a model artifact."""
    labels = tuple(STYLE_SYNONYMS)
    return labels, embedder.embed_labels(labels)


def save_label_embeddings(path: Path | str, labels: Sequence[str], embeddings: np.ndarray) -> None:
    """Write labels + (L, S) embeddings as .npz (no pickles)."""
    np.savez(path, labels=np.asarray(labels, dtype=np.str_), embeddings=embeddings.astype(np.float32))
    logger.info("wrote %d style embeddings to %s", len(labels), path)


def load_label_embeddings(path: Path | str) -> dict[str, np.ndarray]:
    """label → (S,) embedding, from :func:`save_label_embeddings`."""
    with np.load(path, allow_pickle=False) as data:
        return {str(label): row for label, row in zip(data["labels"], data["embeddings"], strict=True)}
