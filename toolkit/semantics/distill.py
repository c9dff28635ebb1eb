"""Distillation of the relational priors: data -> embeddings -> two MLPs -> safetensors + report.

Pipeline (SCOUT sec. IV-C and VI-A, with the offline knowledge source in place of the LLM):

1. the relational sets D_contain and D_co-occur (Eqs. 6-7) from the *training* split of the
   household knowledge only (:mod:`sgtool.datasets.relational`);
2. optionally (``holdout > 0``) a deterministic share of the training query categories is
   held out of training, for a second report group;
3. every distinct text is encoded once with the frozen encoder E (Eq. 8);
4. the two MLPs are trained (:mod:`sgtool.semantics.training`), containment with MSE and
   co-occurrence with BCE;
5. the weights are written as safetensors (never pickle) next to ``metadata.json``: data
   sizes, seed, hyper-parameters, losses, the split's fingerprint, the held-out queries,
   the training queries (the query texts the models were trained on, sorted: the
   vocabulary that makes a benchmark query "seen"), room types, the containment evidence
   per room type (:func:`room_evidence`, so a planner knows which room types the prior has
   learned anything about) and the quality report;
6. the report (SCOUT Fig. 7 as numbers): on query categories held out of training, ROC-AUC
   of the learned score and of raw SBERT cosine similarity for containment and
   co-occurrence. The main group is the unseen categories: objects of the *evaluation*
   part that no training record mentions (their pairs come from the evaluation part,
   which is only read for this report, never trained on), so the shipped models use every
   training query and are still judged on categories they never saw.

Everything is a function of the knowledge and the seed; no wall-clock enters the outputs,
so two runs write byte-identical files.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from sgtool.files import atomic_write
from sgtool.semantics.encoder import SentenceEncoder, default_encoder
from sgtool.semantics.metrics import separation_summary
from sgtool.semantics.mlp import RelationMLP, load_mlp, save_mlp
from sgtool.semantics.priors import CONTAINMENT_FILE, COOCCURRENCE_FILE, METADATA_FILE
from sgtool.semantics.relational_set import RelationalSet

# (containment, co-occurrence)
SetPair = tuple[RelationalSet, RelationalSet]

METADATA_VERSION = 4  # 3: room_evidence; 4: training_queries
FILES = {"containment": CONTAINMENT_FILE, "cooccurrence": COOCCURRENCE_FILE}


@dataclass(frozen=True)
class DistillConfig:
    seed: int = 0
    holdout: float = 0.0  # share of training queries held out of training (report only)
    epochs_containment: int = 30
    epochs_cooccurrence: int = 5
    batch_size: int = 256
    lr: float = 1e-3
    weight_decay: float = 0.0
    keep: str = "last"  # which epoch's weights: "last" or "best" validation loss
    val_fraction: float = 0.1
    threads: int = 1


def encode_set(encoder: SentenceEncoder, rs: RelationalSet) -> tuple[np.ndarray, np.ndarray]:
    """The sentence vectors of ``rs``'s node texts and of its query texts, in their
    order: shapes (len(rs.nodes), dim) and (len(rs.queries), dim)."""
    return encoder.encode(list(rs.nodes)), encoder.encode(list(rs.queries))


def evaluate_set(rs: RelationalSet, node_emb: np.ndarray, query_emb: np.ndarray,
                 mlp: RelationMLP) -> dict[str, Any]:
    """Learned score vs cosine similarity on the pairs of ``rs`` (binary label: target > 0)."""
    if len(rs) == 0:
        return {"pairs": 0}
    n = node_emb[rs.pairs[:, 0]]
    q = query_emb[rs.pairs[:, 1]]
    labels = rs.targets > 0
    learned = mlp.pairs(np.concatenate([n, q], axis=1))
    cos = (n * q).sum(axis=1).astype(np.float64)
    out: dict[str, Any] = {
        "pairs": len(rs),
        "queries": int(len(np.unique(rs.pairs[:, 1]))),
        "learned": separation_summary(learned, labels),
        "cosine": separation_summary(cos, labels),
    }
    if rs.relation == "containment":
        out["learned_mse"] = float(np.mean((learned - rs.targets) ** 2))
    return out


def distill(
    out_dir: str | Path,
    cfg: DistillConfig = DistillConfig(),
    *,
    sets: SetPair,
    split_fingerprint: str | None = None,
    room_types: tuple[str, ...] | None = None,
    encoder: SentenceEncoder | None = None,
    progress: bool = False,
    eval_sets: SetPair | None = None,
) -> dict[str, Any]:
    """Train both models into ``out_dir`` and return the metadata written there.

    ``sets`` = (containment set, co-occurrence set), e.g. those of
    :func:`sgtool.datasets.relational.training_sets`; the report covers ``eval_sets`` (e.g.
    the unseen query categories of :func:`sgtool.datasets.relational.evaluation_sets`) when
    given. With ``cfg.holdout > 0`` a share of the training queries is also held out of
    training and reported.
    """
    from sgtool.semantics.relational_set import holdout_queries
    from sgtool.semantics.training import TrainConfig, train_relation

    cont, cooc = sets
    encoder = encoder or default_encoder()
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)

    all_queries = sorted(set(cont.queries) | set(cooc.queries))
    held = holdout_queries(all_queries, cfg.holdout, cfg.seed) if cfg.holdout > 0 else set()
    train_q = set(all_queries) - held

    meta: dict[str, Any] = {
        "metadata_version": METADATA_VERSION,
        "encoder": encoder.model_id,
        "config": asdict(cfg),
        "split_fingerprint": split_fingerprint,
        "room_types": sorted(room_types or cont.nodes),
        "room_evidence": room_evidence(cont.subset_queries(train_q)),
        "heldout_queries": sorted(held),
        "training_queries": sorted(train_q),
        "models": {},
        "report": {},
    }
    mlps: dict[str, RelationMLP] = {}
    for rs, loss, epochs in ((cont, "mse", cfg.epochs_containment),
                             (cooc, "bce", cfg.epochs_cooccurrence)):
        node_emb, query_emb = encode_set(encoder, rs)
        train = rs.subset_queries(train_q)
        tcfg = TrainConfig(epochs=epochs, batch_size=cfg.batch_size, lr=cfg.lr,
                           weight_decay=cfg.weight_decay, val_fraction=cfg.val_fraction,
                           seed=cfg.seed, threads=cfg.threads, keep=cfg.keep)
        res = train_relation(rs.relation, node_emb, query_emb, train.pairs, train.targets,
                             loss, tcfg, progress=progress,
                             sample_weights=train.balanced_weights())
        path = out_dir / FILES[rs.relation]
        save_mlp(path, res.weights, res.biases, {
            "relation": rs.relation, "encoder": encoder.model_id, "loss": loss,
            "seed": str(cfg.seed), "data_fingerprint": rs.fingerprint(),
        })
        mlps[rs.relation] = load_mlp(path, rs.relation)
        meta["models"][rs.relation] = {
            "file": FILES[rs.relation],
            "loss": loss,
            "parameters": mlps[rs.relation].n_parameters,
            "data": {
                "pairs": len(rs), "positives": rs.positives, "nodes": len(rs.nodes),
                "queries": len(rs.queries), "fingerprint": rs.fingerprint(),
            },
            "train_pairs": res.n_train,
            "val_pairs": res.n_val,
            "best_epoch": res.best_epoch,
            "history": [{k: (round(v, 6) if isinstance(v, float) else v) for k, v in h.items()}
                        for h in res.history],
        }
    meta["report"] = _report(mlps, encoder, eval_sets, (cont, cooc), held)
    write_json_atomic(out_dir / METADATA_FILE, meta)
    return meta


def room_evidence(containment: RelationalSet) -> dict[str, Any]:
    """How much the containment pairs say about each room type: ``queries`` (the number of
    query categories with pairs) and ``positives`` (room type -> how many of them have a
    target above 0 there, i.e. are stated to be found in it)."""
    pos = containment.pairs[containment.targets > 0, 0]
    counts = np.bincount(pos, minlength=len(containment.nodes))
    return {"queries": int(len(np.unique(containment.pairs[:, 1]))),
            "positives": {n: int(c) for n, c in zip(containment.nodes, counts, strict=True)}}


def _report(mlps: dict[str, RelationMLP], encoder: SentenceEncoder, eval_sets: SetPair | None,
            train_sets: SetPair, held: set[str]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    if eval_sets is not None:
        names = {rs.queries[i] for rs in eval_sets for i in np.unique(rs.pairs[:, 1])}
        group: dict[str, Any] = {"queries": len(names)}
        for rs in eval_sets:
            group[rs.relation] = evaluate_set(rs, *encode_set(encoder, rs), mlps[rs.relation])
        out["unseen"] = group
    if held:
        group = {"queries": len(held)}
        for rs in train_sets:
            group[rs.relation] = evaluate_set(rs.subset_queries(held), *encode_set(encoder, rs),
                                              mlps[rs.relation])
        out["heldout"] = group
    return out


def write_json_atomic(path: Path, obj: object) -> None:
    atomic_write(path, json.dumps(obj, indent=1, sort_keys=True, allow_nan=True) + "\n")


def quality_report(
    weights_dir: str | Path,
    sets: SetPair,
    encoder: SentenceEncoder | None = None,
    eval_sets: SetPair | None = None,
) -> dict[str, Any]:
    """Recompute the report of the weights in ``weights_dir`` from the files themselves.

    Groups: ``unseen`` (``eval_sets``, when given: evaluation-part categories absent from
    training) and ``heldout`` (the queries of ``sets`` that the metadata's list held out).
    """
    weights_dir = Path(weights_dir)
    meta = json.loads((weights_dir / METADATA_FILE).read_text())
    encoder = encoder or default_encoder()
    mlps = {rel: load_mlp(weights_dir / f, rel) for rel, f in FILES.items()}
    rep = _report(mlps, encoder, eval_sets, sets, set(meta["heldout_queries"]))
    rep["encoder"] = encoder.model_id
    return rep


GROUP_TITLES = {
    "unseen": "query categories unseen in training (evaluation part)",
    "heldout": "training query categories held out of training",
}


def format_report(report: dict[str, Any]) -> str:
    """Text table per group: relation, pairs, AUC learned vs cosine, mean scores."""
    lines = []
    for key, title in GROUP_TITLES.items():
        group = report.get(key)
        if not group:
            continue
        lines.append(f"{title}: {group.get('queries')}")
        lines.append(
            f"  {'relation':<13} {'pairs':>6} {'pos':>5} {'AUC learned':>12} {'AUC cosine':>11}"
            f" {'mean+/- learned':>16} {'mean+/- cosine':>15}")
        for rel in ("containment", "cooccurrence"):
            r = group.get(rel)
            if not r or not r.get("pairs"):
                lines.append(f"  {rel:<13} {0:>6}")
                continue
            lr, cs = r["learned"], r["cosine"]
            lines.append(
                f"  {rel:<13} {r['pairs']:>6} {lr['n_pos']:>5} {lr['auc']:>12.3f} "
                f"{cs['auc']:>11.3f} {lr['mean_pos']:>8.3f}/{lr['mean_neg']:<7.3f} "
                f"{cs['mean_pos']:>7.3f}/{cs['mean_neg']:<7.3f}")
    return "\n".join(lines) if lines else "no report groups"
