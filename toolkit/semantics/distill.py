"""Distillation of the relational priors: data -> embeddings -> two MLPs -> safetensors + report.

Pipeline (SCOUT sec. IV-C and VI-A, with the offline knowledge source in place of the LLM):

1. the relational sets D_contain and D_co-occur (Eqs. 6-7) from the *training* split of the
   household knowledge only (:mod:`sgtool.datasets.relational`);
2. a deterministic share of query categories is held out of training (for the report);
3. every distinct text is encoded once with the frozen encoder E (Eq. 8);
4. the two MLPs are trained (:mod:`sgtool.semantics.training`), containment with MSE and
   co-occurrence with BCE;
5. the weights are written as safetensors (never pickle) next to ``metadata.json``: data
   sizes, seed, hyper-parameters, losses, the split's fingerprint, the held-out queries,
   room types, and the quality report;
6. the report (SCOUT Fig. 7 as numbers): on the held-out queries, ROC-AUC of the learned
   score and of raw SBERT cosine similarity for containment and co-occurrence.

Everything is a function of the knowledge and the seed; no wall-clock enters the outputs,
so two runs write byte-identical files.
"""

from __future__ import annotations

import json
import os
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from sgtool.semantics.encoder import SentenceEncoder, default_encoder
from sgtool.semantics.metrics import separation_summary
from sgtool.semantics.mlp import load_mlp, save_mlp
from sgtool.semantics.priors import CONTAINMENT_FILE, COOCCURRENCE_FILE, METADATA_FILE

METADATA_VERSION = 1


@dataclass(frozen=True)
class DistillConfig:
    seed: int = 0
    holdout: float = 0.15  # share of query categories held out of training for the report
    epochs_containment: int = 20
    epochs_cooccurrence: int = 15
    batch_size: int = 256
    lr: float = 1e-3
    weight_decay: float = 0.0
    val_fraction: float = 0.1
    threads: int = 1


def _encode_set(encoder: SentenceEncoder, rs) -> tuple[np.ndarray, np.ndarray]:
    return encoder.encode(list(rs.nodes)), encoder.encode(list(rs.queries))


def evaluate_set(rs, node_emb: np.ndarray, query_emb: np.ndarray, mlp) -> dict[str, Any]:
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
    sets: tuple[Any, Any] | None = None,
    split_fingerprint: str | None = None,
    room_types: tuple[str, ...] | None = None,
    encoder: SentenceEncoder | None = None,
    progress: bool = False,
) -> dict[str, Any]:
    """Train both models into ``out_dir`` and return the metadata written there.

    ``sets`` = (containment set, co-occurrence set); by default built from
    ``sgtool.datasets.split.training_knowledge()``.
    """
    from sgtool.datasets.relational import holdout_queries
    from sgtool.semantics.training import TrainConfig, train_relation

    if sets is None:
        from sgtool.datasets.relational import training_sets

        built = training_sets(seed=cfg.seed)
        sets = (built.containment, built.cooccurrence)
        split_fingerprint = split_fingerprint or built.split_fingerprint
        room_types = room_types or built.room_types
    cont, cooc = sets
    encoder = encoder or default_encoder()
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)

    all_queries = sorted(set(cont.queries) | set(cooc.queries))
    held = holdout_queries(all_queries, cfg.holdout, cfg.seed)
    train_q = set(all_queries) - held

    meta: dict[str, Any] = {
        "metadata_version": METADATA_VERSION,
        "encoder": encoder.model_id,
        "config": asdict(cfg),
        "split_fingerprint": split_fingerprint,
        "room_types": sorted(room_types or cont.nodes),
        "heldout_queries": sorted(held),
        "models": {},
    }
    files = {"containment": CONTAINMENT_FILE, "cooccurrence": COOCCURRENCE_FILE}
    for rs, loss, epochs in ((cont, "mse", cfg.epochs_containment),
                             (cooc, "bce", cfg.epochs_cooccurrence)):
        node_emb, query_emb = _encode_set(encoder, rs)
        train = rs.subset_queries(train_q)
        tcfg = TrainConfig(epochs=epochs, batch_size=cfg.batch_size, lr=cfg.lr,
                           weight_decay=cfg.weight_decay, val_fraction=cfg.val_fraction,
                           seed=cfg.seed, threads=cfg.threads)
        res = train_relation(rs.relation, node_emb, query_emb, train.pairs, train.targets,
                             loss, tcfg, progress=progress)
        path = out_dir / files[rs.relation]
        save_mlp(path, res.weights, res.biases, {
            "relation": rs.relation, "encoder": encoder.model_id, "loss": loss,
            "seed": str(cfg.seed), "data_fingerprint": rs.fingerprint(),
        })
        mlp = load_mlp(path, rs.relation)
        meta["models"][rs.relation] = {
            "file": files[rs.relation],
            "loss": loss,
            "parameters": mlp.n_parameters,
            "data": {
                "pairs": len(rs), "positives": rs.positives, "nodes": len(rs.nodes),
                "queries": len(rs.queries), "fingerprint": rs.fingerprint(),
            },
            "train_pairs": res.n_train,
            "val_pairs": res.n_val,
            "best_epoch": res.best_epoch,
            "history": [{k: (round(v, 6) if isinstance(v, float) else v) for k, v in h.items()}
                        for h in res.history],
            "heldout": evaluate_set(rs.subset_queries(held), node_emb, query_emb, mlp),
        }
    write_json_atomic(out_dir / METADATA_FILE, meta)
    return meta


def write_json_atomic(path: Path, obj: Any) -> None:
    tmp = path.with_name(path.name + ".partial")
    tmp.write_text(json.dumps(obj, indent=1, sort_keys=True, allow_nan=True) + "\n")
    os.replace(tmp, path)


def quality_report(
    weights_dir: str | Path,
    sets: tuple[Any, Any] | None = None,
    encoder: SentenceEncoder | None = None,
) -> dict[str, Any]:
    """Recompute the held-out separation of the weights in ``weights_dir``.

    The held-out queries are read from the weights' metadata; the pairs are rebuilt from
    the training knowledge (or ``sets``), so the report checks the shipped files, not a
    number stored next to them.
    """
    from sgtool.datasets.relational import training_sets

    weights_dir = Path(weights_dir)
    meta = json.loads((weights_dir / METADATA_FILE).read_text())
    if sets is None:
        built = training_sets(seed=int(meta["config"]["seed"]))
        sets = (built.containment, built.cooccurrence)
    encoder = encoder or default_encoder()
    held = set(meta["heldout_queries"])
    out: dict[str, Any] = {"heldout_queries": len(held), "encoder": encoder.model_id}
    files = {"containment": CONTAINMENT_FILE, "cooccurrence": COOCCURRENCE_FILE}
    for rs in sets:
        node_emb, query_emb = _encode_set(encoder, rs)
        mlp = load_mlp(weights_dir / files[rs.relation], rs.relation)
        out[rs.relation] = evaluate_set(rs.subset_queries(held), node_emb, query_emb, mlp)
    return out


def format_report(report: dict[str, Any]) -> str:
    """A small text table: relation, pairs, AUC learned vs cosine, mean scores."""
    lines = [
        f"held-out query categories: {report.get('heldout_queries')}",
        f"{'relation':<13} {'pairs':>7} {'pos':>6} {'AUC learned':>12} {'AUC cosine':>11} "
        f"{'mean+ / mean- learned':>22} {'mean+ / mean- cosine':>21}",
    ]
    for rel in ("containment", "cooccurrence"):
        r = report.get(rel)
        if not r or not r.get("pairs"):
            lines.append(f"{rel:<13} {'0':>7}")
            continue
        lr, cs = r["learned"], r["cosine"]
        lines.append(
            f"{rel:<13} {r['pairs']:>7} {lr['n_pos']:>6} {lr['auc']:>12.3f} {cs['auc']:>11.3f} "
            f"{lr['mean_pos']:>10.3f} / {lr['mean_neg']:<9.3f} "
            f"{cs['mean_pos']:>9.3f} / {cs['mean_neg']:<9.3f}"
        )
    return "\n".join(lines)
