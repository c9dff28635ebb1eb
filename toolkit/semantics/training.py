"""Training the relational MLPs (SCOUT sec. IV-C, VI-A) with torch on the CPU, deterministically.

Inputs are index pairs into two precomputed embedding tables (node texts, query texts), so
each text is encoded once and a batch is two gathers and a concatenation (Eq. 8). The
co-occurrence model is trained with binary cross entropy on the logit, the containment
model with mean squared error on the sigmoid output (SCOUT sec. IV-C). Adam, a fixed number
of epochs; the final weights are kept by default (``keep="last"``), or the epoch with the
lowest validation loss (``keep="best"``). Why "last": the validation pairs are random pairs
of training queries whose zero targets are often plausible places the knowledge happens not
to mention (a pillow in a living room), so validation loss rises while the model still
improves at what the planner needs (the comparison of the two checkpoints is in
docs/experiments/moved-from-docstrings.md).

Determinism: seeded torch and numpy generators, ``torch.use_deterministic_algorithms``,
one intra-op thread (different thread counts may sum in a different order), shuffling by
a seeded numpy permutation. Two runs on the same data give bit-identical weights.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from sgtool.semantics.mlp import LAYER_SIZES

if TYPE_CHECKING:
    import torch


@dataclass(frozen=True)
class TrainConfig:
    epochs: int = 25
    batch_size: int = 256
    lr: float = 1e-3
    weight_decay: float = 0.0
    val_fraction: float = 0.1
    seed: int = 0
    threads: int = 1
    keep: str = "best"  # "best": lowest validation loss; "last": the final epoch


@dataclass
class TrainResult:
    relation: str
    loss: str
    weights: list[np.ndarray]
    biases: list[np.ndarray]
    history: list[dict[str, float]] = field(default_factory=list)
    best_epoch: int = 0
    n_train: int = 0
    n_val: int = 0

    @property
    def best_val_loss(self) -> float:
        return self.history[self.best_epoch - 1]["val_loss"] if self.history else math.nan


def build_torch_mlp() -> torch.nn.Module:
    """The torch model of :class:`sgtool.semantics.mlp.RelationMLP` (untrained): the
    layers of ``LAYER_SIZES`` as ``net.0`` ... ``net.6``, ReLU between them; its forward
    pass gives logits (n,)."""
    import torch

    layers: list[torch.nn.Module] = []
    for i in range(len(LAYER_SIZES) - 1):
        layers.append(torch.nn.Linear(LAYER_SIZES[i], LAYER_SIZES[i + 1]))
        if i < len(LAYER_SIZES) - 2:
            layers.append(torch.nn.ReLU())

    class Net(torch.nn.Module):
        def __init__(self) -> None:
            super().__init__()
            self.net = torch.nn.Sequential(*layers)

        def forward(self, x: torch.Tensor) -> torch.Tensor:  # logits
            out: torch.Tensor = self.net(x).squeeze(-1)
            return out

    return Net()


def train_relation(
    relation: str,
    node_emb: np.ndarray,
    query_emb: np.ndarray,
    pairs: np.ndarray,
    targets: np.ndarray,
    loss: str,
    cfg: TrainConfig = TrainConfig(),
    progress: bool = False,
    sample_weights: np.ndarray | None = None,
) -> TrainResult:
    """Train one relational MLP.

    ``pairs[k] = (node index, query index)`` into ``node_emb`` / ``query_emb`` (unit
    vectors, 384-d); ``targets[k]`` in [0, 1]; ``loss`` is ``"bce"`` or ``"mse"``;
    ``sample_weights`` (optional, > 0) weigh each pair in the loss (training and
    validation alike: the loss of a batch is sum(w * l) / sum(w)).
    """
    import torch

    if loss not in ("bce", "mse"):
        raise ValueError(f"loss must be 'bce' or 'mse', not {loss!r}")
    pairs = np.asarray(pairs, dtype=np.int64)
    targets = np.asarray(targets, dtype=np.float32)
    if pairs.ndim != 2 or pairs.shape[1] != 2 or len(pairs) != len(targets):
        raise ValueError("pairs must be (K, 2) and match targets (K,)")
    if len(pairs) < 4:
        raise ValueError(f"{relation}: only {len(pairs)} training pairs")
    weights = (np.ones(len(pairs), np.float32) if sample_weights is None
               else np.asarray(sample_weights, dtype=np.float32))
    if weights.shape != targets.shape or not np.all(weights > 0):
        raise ValueError("sample_weights must be positive and match targets")

    prev_threads = torch.get_num_threads()
    prev_det = torch.are_deterministic_algorithms_enabled()
    torch.set_num_threads(max(1, int(cfg.threads)))
    torch.use_deterministic_algorithms(True)
    try:
        torch.manual_seed(cfg.seed)
        rng = np.random.default_rng(cfg.seed)
        order = rng.permutation(len(pairs))
        n_val = max(1, int(round(len(pairs) * cfg.val_fraction)))
        val_idx, tr_idx = np.sort(order[:n_val]), np.sort(order[n_val:])

        nodes = torch.from_numpy(np.ascontiguousarray(node_emb, np.float32))
        queries = torch.from_numpy(np.ascontiguousarray(query_emb, np.float32))
        p_all = torch.from_numpy(pairs)
        y_all = torch.from_numpy(targets)
        w_all = torch.from_numpy(weights)

        def inputs(idx: np.ndarray) -> torch.Tensor:
            p = p_all[torch.from_numpy(idx)]
            return torch.cat([nodes[p[:, 0]], queries[p[:, 1]]], dim=1)

        model = build_torch_mlp()
        opt = torch.optim.Adam(model.parameters(), lr=cfg.lr, weight_decay=cfg.weight_decay)

        def loss_fn(logits: torch.Tensor, y: torch.Tensor, w: torch.Tensor) -> torch.Tensor:
            if loss == "bce":
                per = torch.nn.functional.binary_cross_entropy_with_logits(
                    logits, y, reduction="none")
            else:
                per = (torch.sigmoid(logits) - y) ** 2
            return (per * w).sum() / w.sum()

        x_val = inputs(val_idx)
        y_val = y_all[torch.from_numpy(val_idx)]
        w_val = w_all[torch.from_numpy(val_idx)]
        history: list[dict[str, float]] = []
        best: tuple[float, int, dict] | None = None
        epochs = range(1, cfg.epochs + 1)
        if progress:
            from tqdm import tqdm

            epochs = tqdm(epochs, desc=f"train {relation}", unit="epoch", leave=False)
        for epoch in epochs:
            model.train()
            perm = tr_idx[rng.permutation(len(tr_idx))]
            total, count = 0.0, 0
            for s in range(0, len(perm), cfg.batch_size):
                b = perm[s : s + cfg.batch_size]
                x = inputs(b)
                bt = torch.from_numpy(b)
                opt.zero_grad(set_to_none=True)
                lval = loss_fn(model(x), y_all[bt], w_all[bt])
                lval.backward()
                opt.step()
                total += float(lval.detach()) * len(b)
                count += len(b)
            model.eval()
            with torch.no_grad():
                v = float(loss_fn(model(x_val), y_val, w_val))
            history.append({"epoch": epoch, "train_loss": total / max(count, 1), "val_loss": v})
            if best is None or v < best[0] or cfg.keep == "last":
                best = (v, epoch, {k: t.detach().clone() for k, t in model.state_dict().items()})
        assert best is not None
        state = best[2]
        ws = [state[f"net.{2 * i}.weight"].numpy().astype(np.float32)
              for i in range(len(LAYER_SIZES) - 1)]
        bs = [state[f"net.{2 * i}.bias"].numpy().astype(np.float32)
              for i in range(len(LAYER_SIZES) - 1)]
        return TrainResult(relation, loss, ws, bs, history, best[1], len(tr_idx), n_val)
    finally:
        torch.set_num_threads(prev_threads)
        torch.use_deterministic_algorithms(prev_det)
