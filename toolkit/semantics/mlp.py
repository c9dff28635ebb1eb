"""The relational MLP f_theta of SCOUT Eq. 9, for inference in numpy.

Architecture (SCOUT sec. VI-A): input x = E(node) (+) E(query) in R^768 (Eq. 8), three
hidden layers 512 -> 256 -> 128 with ReLU, one output unit, a sigmoid to map into [0, 1]
(558K parameters). Both relations share it: co-occurrence was trained with binary cross
entropy on the logit, containment with mean squared error on the sigmoid output.

Weights are stored as safetensors (never pickle) with the tensor names of the torch
``nn.Sequential`` used for training (``net.0.weight`` ... ``net.6.bias``), so the same file
loads in torch (:mod:`sgtool.semantics.training`) and here. Inference runs in numpy: a
planner never needs to import torch, and a forward pass of 100 pairs takes well under a
millisecond. The first layer is split into node and query halves, so the query half is
computed once per query (:meth:`RelationMLP.query_bias`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from sgtool.errors import SgtoolError
from sgtool.files import atomic_write

LAYER_SIZES: tuple[int, ...] = (768, 512, 256, 128, 1)
TENSOR_NAMES = tuple(f"net.{2 * i}" for i in range(len(LAYER_SIZES) - 1))  # net.0, net.2 ...


@dataclass(frozen=True)
class RelationMLP:
    """A loaded relational model; ``weights[i]`` is (out, in), ``biases[i]`` is (out,)."""

    relation: str
    weights: tuple[np.ndarray, ...]
    biases: tuple[np.ndarray, ...]
    metadata: dict[str, str]
    # derived in __post_init__: the first layer's node and query halves and the later
    # layers, transposed, float32, contiguous (x @ W^T)
    _w_node: np.ndarray = field(init=False, repr=False, compare=False)
    _w_query: np.ndarray = field(init=False, repr=False, compare=False)
    _rest: tuple[np.ndarray, ...] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        dims = [self.weights[0].shape[1]] + [w.shape[0] for w in self.weights]
        if tuple(dims) != LAYER_SIZES:
            raise ValueError(f"{self.relation}: layer sizes {dims} != {list(LAYER_SIZES)}")
        half = LAYER_SIZES[0] // 2
        w0 = self.weights[0]
        object.__setattr__(self, "_w_node", np.ascontiguousarray(w0[:, :half].T, np.float32))
        object.__setattr__(self, "_w_query", np.ascontiguousarray(w0[:, half:].T, np.float32))
        object.__setattr__(
            self, "_rest", tuple(np.ascontiguousarray(w.T, np.float32) for w in self.weights[1:])
        )

    @property
    def n_parameters(self) -> int:
        return int(sum(w.size + b.size for w, b in zip(self.weights, self.biases, strict=True)))

    def query_bias(self, query_vec: np.ndarray) -> np.ndarray:
        """First-layer pre-activation contributed by the query (plus the bias)."""
        return (np.asarray(query_vec, np.float32) @ self._w_query + self.biases[0]).astype(
            np.float32
        )

    def logits(self, node_vecs: np.ndarray, query_vec: np.ndarray) -> np.ndarray:
        """Logits for every row of ``node_vecs`` (n, 384) against one query vector (384,)."""
        h = np.atleast_2d(np.asarray(node_vecs, np.float32)) @ self._w_node
        return self._tail(h + self.query_bias(query_vec))

    def _tail(self, h0: np.ndarray) -> np.ndarray:
        """Layers after the first pre-activation ``h0`` -> logits (n,)."""
        h = np.maximum(h0, 0.0)
        rest = self._rest
        for i, w in enumerate(rest):
            h = h @ w + self.biases[i + 1]
            if i < len(rest) - 1:
                h = np.maximum(h, 0.0)
        return h[:, 0].astype(np.float64)

    def __call__(self, node_vecs: np.ndarray, query_vec: np.ndarray) -> np.ndarray:
        """Scores in [0, 1] (SCOUT Eqs. 10-11)."""
        z = self.logits(node_vecs, query_vec)
        return 1.0 / (1.0 + np.exp(-z))

    def pairs(self, x: np.ndarray) -> np.ndarray:
        """Scores for rows of concatenated inputs (n, 768) (Eq. 8 layout)."""
        x = np.atleast_2d(np.asarray(x, np.float32))
        half = LAYER_SIZES[0] // 2
        h0 = x[:, :half] @ self._w_node + x[:, half:] @ self._w_query + self.biases[0]
        return 1.0 / (1.0 + np.exp(-self._tail(h0)))


def load_mlp(path: str | Path, relation: str | None = None) -> RelationMLP:
    """Load a relational MLP from a safetensors file."""
    from safetensors import safe_open

    path = Path(path)
    if not path.is_file():
        raise SgtoolError(f"relational model weights not found: {path}")
    try:
        with safe_open(str(path), framework="numpy") as f:
            meta = dict(f.metadata() or {})
            ws, bs = [], []
            for name in TENSOR_NAMES:
                ws.append(np.asarray(f.get_tensor(f"{name}.weight"), np.float32))
                bs.append(np.asarray(f.get_tensor(f"{name}.bias"), np.float32))
    except Exception as e:  # noqa: BLE001 - safetensors' own error types: a damaged file
        raise SgtoolError(f"{path}: not readable relational model weights "
                          f"({type(e).__name__}: {e}); `sgtool distill` writes them") from e
    try:
        return RelationMLP(
            relation=relation or meta.get("relation", path.stem),
            weights=tuple(ws),
            biases=tuple(bs),
            metadata=meta,
        )
    except ValueError as e:  # layer sizes of another model: not these weights
        raise SgtoolError(f"{path}: {e}; `sgtool distill` writes the weights sgtool "
                          "loads") from None


def save_mlp(
    path: str | Path,
    weights: list[np.ndarray],
    biases: list[np.ndarray],
    metadata: dict[str, str],
) -> None:
    """Write weights atomically (temp file beside the target, then rename), byte-stable.

    The safetensors writer keeps metadata in a hash map, so its header order changes from
    run to run; the header JSON is re-serialised with sorted keys (same length rules:
    padded with spaces to a multiple of 8), which the format allows.
    """
    import json

    from safetensors.numpy import save

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tensors: dict[str, np.ndarray] = {}
    for name, w, b in zip(TENSOR_NAMES, weights, biases, strict=True):
        tensors[f"{name}.weight"] = np.ascontiguousarray(w, np.float32)
        tensors[f"{name}.bias"] = np.ascontiguousarray(b, np.float32)
    raw = save(tensors, metadata={k: str(v) for k, v in sorted(metadata.items())})
    n = int.from_bytes(raw[:8], "little")
    header = json.dumps(json.loads(raw[8 : 8 + n]), sort_keys=True, separators=(",", ":"))
    hb = header.encode()
    hb += b" " * (-len(hb) % 8)
    atomic_write(path, len(hb).to_bytes(8, "little") + hb + raw[8 + n :])
