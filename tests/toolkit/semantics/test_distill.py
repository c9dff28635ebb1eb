"""Distillation: determinism, what is written, held-out report, the ``sgtool distill`` command."""

from __future__ import annotations

import hashlib
import json

import numpy as np
import pytest
from click.testing import CliRunner
from support.semantics_fixtures import encoder
from support.tiny_knowledge import tiny

from sgtool.datasets.relational import containment_set, cooccurrence_set
from sgtool.semantics.distill import DistillConfig, distill, quality_report
from sgtool.semantics.priors import LearnedPriors

FILES = ("containment.safetensors", "cooccurrence.safetensors", "metadata.json")
# seed 16 holds "refrigerator" out of training (of 6 queries; see holdout_queries)
CFG = DistillConfig(seed=16, holdout=0.3, epochs_containment=3, epochs_cooccurrence=3)


def tiny_sets():
    k = tiny()
    return containment_set(k, seed=16), cooccurrence_set(k, seed=16)


def digest(folder) -> dict[str, str]:
    return {f: hashlib.sha256((folder / f).read_bytes()).hexdigest() for f in FILES}


def test_distill_is_byte_identical_and_loadable(tmp_path) -> None:
    a, b = tmp_path / "a", tmp_path / "b"
    ma = distill(a, CFG, sets=tiny_sets(), split_fingerprint="tiny", encoder=encoder())
    distill(b, CFG, sets=tiny_sets(), split_fingerprint="tiny", encoder=encoder())
    assert digest(a) == digest(b)
    assert not list(a.glob("*.partial"))
    meta = json.loads((a / "metadata.json").read_text())
    assert meta == json.loads(json.dumps(ma))
    assert meta["config"]["seed"] == 16 and meta["split_fingerprint"] == "tiny"
    assert meta["heldout_queries"] == ["refrigerator"]
    # containment evidence of the 5 trained queries (refrigerator held out): kitchen for
    # apple, cabinet, plate, sink; dining room for cabinet, plate; bathroom for cabinet,
    # sink, toilet (test_semantics_relational.tiny)
    assert meta["room_evidence"] == {
        "queries": 5, "positives": {"bathroom": 3, "dining room": 2, "kitchen": 4}}
    held = meta["report"]["heldout"]
    assert held["queries"] == len(meta["heldout_queries"]) > 0
    assert "unseen" not in meta["report"]  # explicit sets, no evaluation sets given
    for rel, loss in (("containment", "mse"), ("cooccurrence", "bce")):
        m = meta["models"][rel]
        assert m["loss"] == loss and len(m["history"]) == 3 and m["best_epoch"] == 3
        # held-out queries never reach training
        assert m["train_pairs"] + m["val_pairs"] + held[rel].get("pairs", 0) == \
            m["data"]["pairs"]
    p = LearnedPriors(encoder(), weights_dir=a)
    s = p.rooms(["kitchen"], "plate")
    assert 0.0 <= s[0] <= 1.0
    # the stored numbers are what a fresh evaluation of the files gives
    rep = quality_report(a, sets=tiny_sets(), encoder=encoder())
    assert rep["heldout"] == held


def test_another_seed_gives_other_weights(tmp_path) -> None:
    distill(tmp_path / "a", CFG, sets=tiny_sets(), encoder=encoder())
    cfg = DistillConfig(seed=22, holdout=0.3, epochs_containment=3, epochs_cooccurrence=3)
    distill(tmp_path / "b", cfg, sets=tiny_sets(), encoder=encoder())
    assert digest(tmp_path / "a")["containment.safetensors"] != \
        digest(tmp_path / "b")["containment.safetensors"]


def test_cli_report_on_shipped_weights() -> None:
    from sgtool.commands.distill import command

    res = CliRunner().invoke(command, ["--report"])
    assert res.exit_code == 0, res.output
    assert "unseen in training" in res.output and "AUC learned" in res.output
    res = CliRunner().invoke(command, ["--report", "--json"])
    rep = json.loads(res.output)["unseen"]
    for rel in ("containment", "cooccurrence"):
        assert rep[rel]["learned"]["auc"] > rep[rel]["cosine"]["auc"]


def test_cli_trains_into_a_folder(tmp_path) -> None:
    from sgtool.commands.distill import command

    out = tmp_path / "w"
    res = CliRunner().invoke(command, ["--out", str(out), "--epochs-containment", "1",
                                       "--epochs-cooccurrence", "1"])
    assert res.exit_code == 0, res.output
    assert sorted(p.name for p in out.iterdir()) == sorted(FILES)  # no temp folder left
    assert "wrote" in res.output
    meta = json.loads((out / "metadata.json").read_text())
    assert meta["models"]["containment"]["data"]["pairs"] > 3000
    assert meta["report"]["unseen"]["queries"] > 20
    p = LearnedPriors(encoder(), weights_dir=out)
    assert np.isfinite(p.objects(["sink"], "toothbrush")[0])


@pytest.mark.ci_only
def test_shipped_weights_are_what_distill_writes(tmp_path) -> None:
    """`sgtool distill` with its defaults (about 20 s here) rebuilds the shipped weights:
    byte-identical on this machine type (measured), compared here within 1e-5 so that a
    machine with other CPU kernels does not fail for the last bits."""
    from safetensors.numpy import load_file

    from sgtool.commands.distill import command
    from sgtool.semantics.priors import WEIGHTS_DIR

    r = CliRunner().invoke(command, ["--out", str(tmp_path)])
    assert r.exit_code == 0, r.output
    for f in FILES:
        if not f.endswith(".safetensors"):
            continue
        new, shipped = load_file(tmp_path / f), load_file(WEIGHTS_DIR / f)
        assert new.keys() == shipped.keys()
        for k in new:
            assert np.allclose(new[k], shipped[k], atol=1e-5, rtol=0), (f, k)
