import socket

import numpy as np
import pytest

from gesturecast.models.generator.style_text import (
    StyleTextEmbedder,
    load_label_embeddings,
    save_label_embeddings,
    style_prompt,
    vocabulary_embeddings,
)
from gesturecast.models.generator.styles import STYLE_SYNONYMS


@pytest.fixture(scope="module")
def embedder():
    return StyleTextEmbedder()


def test_loads_with_network_unreachable(monkeypatch):
    monkeypatch.setenv("HF_HUB_OFFLINE", "1")

    def refuse(*args, **kwargs):
        raise AssertionError("wordllama tried to use the network")

    monkeypatch.setattr(socket.socket, "connect", refuse)
    monkeypatch.setattr(socket, "create_connection", refuse)
    embedding = StyleTextEmbedder().embed_labels(["happy"])
    assert embedding.shape == (1, 256)


def test_prompt_template():
    assert style_prompt("happy") == "a person gesturing in a happy way"
    assert style_prompt("not-confident") == "a person gesturing in a not confident way"


def test_embeddings_are_unit_norm_and_synonyms_are_nearest(embedder):
    labels = ["tired", "exhausted", "old", "elderly", "happy", "angry"]
    vectors = embedder.embed_labels(labels)
    np.testing.assert_allclose(np.linalg.norm(vectors, axis=1), 1.0, atol=1e-5)
    similarity = vectors @ vectors.T
    np.fill_diagonal(similarity, -np.inf)
    nearest = [labels[j] for j in similarity.argmax(axis=1)]
    assert nearest[:4] == ["exhausted", "tired", "elderly", "old"]


def test_vocabulary_round_trip(embedder, tmp_path):
    labels, table = vocabulary_embeddings(embedder)
    assert labels == tuple(STYLE_SYNONYMS) and table.shape == (len(labels), embedder.dim)
    save_label_embeddings(tmp_path / "styles.npz", labels, table)
    loaded = load_label_embeddings(tmp_path / "styles.npz")
    np.testing.assert_array_equal(loaded["happy"], table[labels.index("happy")])
