"""Separation metrics for relational scores (SCOUT Fig. 7 as numbers).

SCOUT shows histograms of scores for positive and negative pairs; we summarise the same
question (does the score separate them?) with ROC-AUC, the probability that a random
positive pair scores above a random negative one (ties count one half): 0.5 is no
separation, 1.0 perfect. Computed with the Mann-Whitney rank sum, exact with ties.
"""

from __future__ import annotations

import numpy as np
from scipy.stats import rankdata


def roc_auc(scores: np.ndarray, labels: np.ndarray) -> float:
    """ROC-AUC of ``scores`` for binary ``labels`` (1 positive, 0 negative); NaN if one
    class is empty."""
    s = np.asarray(scores, dtype=np.float64)
    y = np.asarray(labels).astype(bool)
    n_pos = int(y.sum())
    n_neg = int((~y).sum())
    if n_pos == 0 or n_neg == 0:
        return float("nan")
    ranks = rankdata(s)  # average ranks for ties
    return float((ranks[y].sum() - n_pos * (n_pos + 1) / 2.0) / (n_pos * n_neg))


def separation_summary(scores: np.ndarray, labels: np.ndarray) -> dict[str, float]:
    """AUC and the mean score of positives and negatives."""
    s = np.asarray(scores, dtype=np.float64)
    y = np.asarray(labels).astype(bool)
    return {
        "auc": roc_auc(s, y),
        "mean_pos": float(s[y].mean()) if y.any() else float("nan"),
        "mean_neg": float(s[~y].mean()) if (~y).any() else float("nan"),
        "n_pos": int(y.sum()),
        "n_neg": int((~y).sum()),
    }
