"""The shipped distilled priors: scores a person can check, agreement with torch, the report."""

from __future__ import annotations

import json

import numpy as np
import pytest
from support.semantics_fixtures import encoder

from sgtool.semantics.priors import (
    MIN_ROOM_EVIDENCE,
    WEIGHTS_DIR,
    CosinePriors,
    LearnedPriors,
    unscored_room_types,
)


@pytest.fixture(scope="module")
def priors() -> LearnedPriors:
    return LearnedPriors(encoder())


@pytest.mark.parametrize(
    "query,better,worse",
    [
        ("frying pan", "kitchen", "bathroom"),
        ("plate", "kitchen", "bathroom"),
        ("book", "living_room", "kitchen"),
        ("milk", "kitchen", "bedroom"),
        ("something to cook with", "kitchen", "bedroom"),  # a descriptive query
    ],
)
def test_room_containment_ranks(priors: LearnedPriors, query: str, better: str,
                                worse: str) -> None:
    hi, lo = priors.rooms([better, worse], query)
    assert hi > lo, f"{query}: {better} {hi:.2f} <= {worse} {lo:.2f}"


@pytest.mark.parametrize(
    "query,better,worse",
    [
        ("toothbrush", "sink", "sofa"),  # toothbrush is held out of training
        ("frying pan", "stove", "sofa"),
        ("milk", "refrigerator", "sofa"),
        ("book", "bookcase", "stove"),
        ("plate", "dishwasher", "sofa"),
    ],
)
def test_object_cooccurrence_ranks(priors: LearnedPriors, query: str, better: str,
                                   worse: str) -> None:
    hi, lo = priors.objects([better, worse], query)
    assert hi > lo, f"{query}: {better} {hi:.2f} <= {worse} {lo:.2f}"


def test_scores_are_probabilities_and_memoised(priors: LearnedPriors) -> None:
    names = ["kitchen", "bathroom", "Living_Room", "garage"]
    a = priors.rooms(names, "Frying_Pan")
    assert a.shape == (4,) and np.all((a >= 0) & (a <= 1))
    b = priors.rooms(list(reversed(names)), "Frying_Pan")
    assert np.array_equal(a, b[::-1])
    # spelling does not matter: the canonical text is what gets embedded
    assert priors.rooms(["living room"], "frying pan")[0] == pytest.approx(a[2], abs=1e-7)


def test_numpy_inference_matches_torch(priors: LearnedPriors) -> None:
    import torch
    from safetensors.torch import load_file

    from sgtool.semantics.training import build_torch_mlp

    net = build_torch_mlp()
    net.load_state_dict(load_file(str(WEIGHTS_DIR / "cooccurrence.safetensors")))
    rng = np.random.default_rng(0)
    x = rng.normal(size=(32, 768)).astype(np.float32)
    with torch.no_grad():
        ref = torch.sigmoid(net(torch.from_numpy(x))).numpy()
    np.testing.assert_allclose(priors.cooccurrence.pairs(x), ref, atol=1e-5)
    assert priors.cooccurrence.n_parameters == 558_081  # SCOUT: 558K per relational model


def test_room_types_the_training_data_hardly_covers_are_unscored(priors: LearnedPriors
                                                                 ) -> None:
    ev = priors.metadata["room_evidence"]
    assert ev["queries"] > 500
    need = MIN_ROOM_EVIDENCE * ev["queries"]
    # a handful of training objects are stated to be found in a pantry, hundreds in a kitchen
    assert ev["positives"]["pantry room"] < need < 300 < ev["positives"]["kitchen"]
    for room in ("pantry_room", "storage room", "Closet", "television_room"):
        assert not priors.can_score_room(room), room
    # household rooms the data describes, and names it never saw (open vocabulary)
    for room in ("kitchen", "bedroom", "bathroom", "living_room", "childs_room", "corridor",
                 "laundry room"):
        assert priors.can_score_room(room), room
    # what "unscored" stands for: ~0 whatever the query, even for pantry things
    assert max(priors.rooms(["pantry room"], q)[0] for q in ("spatula", "flour sack")) < 0.05


def test_unscored_room_types_rule() -> None:
    ev = {"queries": 200, "positives": {"kitchen": 150, "Pantry_Room": 1, "hall": 2}}
    assert unscored_room_types(ev, 0.01) == {"pantry room"}  # 1 < 2 <= 2
    assert unscored_room_types(ev, 0.0) == frozenset()
    assert unscored_room_types(None, 0.01) == frozenset()  # weights without the field
    assert CosinePriors(encoder()).can_score_room("pantry room")  # cosine scores any name


def test_shipped_weights_match_the_current_training_data() -> None:
    """Fails when the knowledge or the set builders change without ``sgtool distill``."""
    from sgtool.datasets.relational import knowledge_fingerprint, training_sets
    from sgtool.datasets.split import training_knowledge
    from sgtool.semantics.distill import room_evidence

    meta = json.loads((WEIGHTS_DIR / "metadata.json").read_text())
    assert meta["split_fingerprint"] == knowledge_fingerprint(training_knowledge())
    assert meta["encoder"] == encoder().model_id
    sets = training_sets(seed=int(meta["config"]["seed"]))
    assert meta["models"]["containment"]["data"]["fingerprint"] == sets.containment.fingerprint()
    assert meta["models"]["cooccurrence"]["data"]["fingerprint"] == \
        sets.cooccurrence.fingerprint()
    assert meta["room_types"] == list(sets.room_types)
    assert meta["room_evidence"] == room_evidence(sets.containment)
    # the vocabulary of "seen" queries: every query of both sets (none held out)
    assert meta["heldout_queries"] == []
    assert meta["training_queries"] == sorted(set(sets.containment.queries) |
                                              set(sets.cooccurrence.queries))


def test_training_queries_are_the_seen_vocabulary(tmp_path) -> None:
    from sgtool.datasets.split import unseen_queries
    from sgtool.semantics.priors import PriorsVocabularyError, training_queries
    from sgtool.semantics.text import category_text

    shipped = training_queries()
    assert len(shipped) > 900 and "frying pan" in shipped
    # the split's unseen categories are exactly those no training record mentions
    assert not shipped & {category_text(q) for q in unseen_queries()}
    (tmp_path / "metadata.json").write_text(json.dumps(
        {"training_queries": ["Frying_Pan.n.01", "mug"]}))
    assert training_queries(tmp_path) == {"frying pan", "mug"}
    (tmp_path / "metadata.json").write_text(json.dumps({"metadata_version": 3}))
    with pytest.raises(PriorsVocabularyError, match="training_queries: missing"):
        training_queries(tmp_path)
    with pytest.raises(PriorsVocabularyError, match="no such file"):
        training_queries(tmp_path / "nowhere")


def test_shipped_report_learned_beats_cosine_on_unseen_queries() -> None:
    unseen = json.loads((WEIGHTS_DIR / "metadata.json").read_text())["report"]["unseen"]
    assert unseen["queries"] > 50
    for rel in ("containment", "cooccurrence"):
        r = unseen[rel]
        # SCOUT Fig. 7: learned priors separate related from unrelated pairs, cosine less so
        assert r["learned"]["auc"] > r["cosine"]["auc"] + 0.05
        assert r["learned"]["auc"] > 0.65


def test_cosine_priors_are_plain_similarity() -> None:
    cp = CosinePriors(encoder())
    v = encoder().encode(["kitchen", "frying pan"])
    assert cp.rooms(["kitchen"], "frying pan")[0] == pytest.approx(float(v[0] @ v[1]), abs=1e-6)
