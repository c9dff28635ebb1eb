"""The sentence encoder: agreement with sentence-transformers, batching, the disk cache."""

from __future__ import annotations

import numpy as np
import pytest
from support.semantics_fixtures import encoder

from sgtool.semantics.cache import EmbeddingCache, cache_root
from sgtool.semantics.encoder import SentenceEncoder
from sgtool.semantics.text import category_text, same_category

# Produced by sentence-transformers 6.2 from the same package weights
# (benchmarks/encoder_reference.py prints them).
REFERENCE_FIRST6 = {
    "frying pan": [-0.0274160, -0.0168622, 0.0138545, 0.0553675, -0.0286319, -0.0351935],
    "kitchen": [0.0352997, -0.0042929, -0.0325952, 0.0650124, -0.0409888, 0.0001441],
    "a brown leather jacket": [-0.0434339, 0.1295249, 0.0043792, -0.0135741, 0.0663444,
                               -0.0403171],
    "toilet paper roll holder": [-0.0492246, 0.0792782, -0.0572238, -0.0247979, -0.0730999,
                                 -0.0329356],
}
REFERENCE_COS = {(0, 1): 0.3764787, (0, 2): 0.1701814, (0, 3): 0.0499523,
                 (1, 2): 0.1308791, (1, 3): 0.1782379, (2, 3): 0.1658190}


def test_matches_sentence_transformers_reference() -> None:
    texts = list(REFERENCE_FIRST6)
    v = encoder().encode(texts)
    assert v.shape == (4, 384) and v.dtype == np.float32
    np.testing.assert_allclose(np.linalg.norm(v, axis=1), 1.0, atol=1e-6)
    for t, row in zip(texts, v, strict=True):
        np.testing.assert_allclose(row[:6], REFERENCE_FIRST6[t], atol=2e-6)
    cos = v @ v.T
    for (i, j), c in REFERENCE_COS.items():
        assert cos[i, j] == pytest.approx(c, abs=2e-6)


def test_vectors_do_not_depend_on_batch_company(tmp_path) -> None:
    texts = ["sink", "bathroom", "toothbrush holder", "a", "living room", "sink"]
    e = SentenceEncoder(cache=False)
    together = e.encode(texts)
    e2 = SentenceEncoder(cache=False)
    alone = np.stack([e2.encode([t])[0] for t in texts])
    assert np.array_equal(together, alone)  # bit for bit
    assert np.array_equal(together[0], together[5])


def test_disk_cache_round_trip_avoids_the_model(tmp_path) -> None:
    path = tmp_path / "emb.sqlite"
    first = SentenceEncoder(cache=EmbeddingCache(path))
    v1 = first.encode(["fridge", "oven", "fridge"])
    assert first.model_loads == 1
    assert EmbeddingCache(path).count(first.model_id) == 2
    second = SentenceEncoder(cache=EmbeddingCache(path))
    v2 = second.encode(["oven", "fridge"])
    assert second.model_loads == 0  # served from disk, model never loaded
    assert np.array_equal(v2, v1[[1, 0]])
    assert "numpy" in second.model_id and "all-MiniLM-L6-v2" in second.model_id


def test_broken_cache_degrades_to_no_cache(tmp_path) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    e = SentenceEncoder(cache=EmbeddingCache(blocker / "emb.sqlite"))
    assert e.encode(["cup"]).shape == (1, 384)


def test_cache_root_env(monkeypatch, tmp_path) -> None:
    monkeypatch.setenv("SGTOOL_CACHE", str(tmp_path))
    assert cache_root() == tmp_path
    monkeypatch.delenv("SGTOOL_CACHE")
    assert cache_root().parts[-2:] == (".cache", "sgtool")


def test_category_text() -> None:
    assert category_text("Frying_Pan.n.01") == "frying pan"
    assert category_text("  bottom-cabinet ") == "bottom cabinet"
    assert category_text(category_text("wall_mounted_tv")) == "wall mounted tv"
    # AI2-THOR's CamelCase types, acronyms included; an upper-case sense suffix
    assert category_text("CounterTop") == "counter top"
    assert category_text("TVStand") == category_text("tv_stand") == "tv stand"
    assert category_text("CD") == "cd" and category_text("Mp3Player") == "mp3 player"
    assert category_text("Frying_Pan.N.01") == "frying pan"
    assert same_category("frying_pan.n.01", "Frying pan")
    assert not same_category("pan", "frying pan")


def test_cosine_separates_synonyms_from_unrelated() -> None:
    # SCOUT Fig. 7 (a): synonyms are separable by cosine; a sanity check of the encoder
    v = encoder().encode(["sponge", "scrubber", "bookshelf", "bookcase", "tv", "plant"])
    assert v[0] @ v[1] > v[4] @ v[5]
    assert v[2] @ v[3] > v[4] @ v[5]


def test_loading_the_model_leaves_the_environment_as_it_was(monkeypatch) -> None:
    """The Hugging Face variables are set only while the model loads: a notebook's later
    downloads (and its child processes) are not made offline behind its back."""
    import os

    for name in ("HF_HUB_OFFLINE", "TRANSFORMERS_OFFLINE"):
        monkeypatch.delenv(name, raising=False)
    e = SentenceEncoder(cache=False)
    assert e.encode(["mug"]).shape == (1, 384) and e.model_loads == 1
    assert "HF_HUB_OFFLINE" not in os.environ and "TRANSFORMERS_OFFLINE" not in os.environ


def test_a_copy_of_an_encoder_finds_its_own_default_cache(monkeypatch, tmp_path) -> None:
    """An encoder sent to another process (a planner pickled for a worker) keeps a cache
    path it was given, but one it took by default is the receiver's default
    ($SGTOOL_CACHE there), not the sender's folder."""
    import pickle

    monkeypatch.setenv("SGTOOL_CACHE", str(tmp_path / "sender"))
    enc = SentenceEncoder()
    given = SentenceEncoder(EmbeddingCache(tmp_path / "mine.sqlite"))
    sent, sent_given = pickle.dumps(enc), pickle.dumps(given)
    monkeypatch.setenv("SGTOOL_CACHE", str(tmp_path / "receiver"))
    copy = pickle.loads(sent)
    assert copy.cache is not None
    assert copy.cache.path == tmp_path / "receiver" / "embeddings" / "embeddings.sqlite"
    assert copy.model_loads == 0  # nothing loaded until a text needs the model
    assert pickle.loads(sent_given).cache.path == tmp_path / "mine.sqlite"
