"""Regions of a symbolic house: furniture positions clustered by k-means, k by BIC (X-means).

Per room, the (x, y) positions of its furniture are clustered by the farthest-point k-means
of :mod:`sgtool.scenegraph.kmeans` (first seed: the point nearest the mean; squared
distances; at most 50 Lloyd rounds) with the number of clusters chosen by the Bayesian
Information Criterion of the matching spherical Gaussian mixture (Pelleg & Moore's
X-means), k in ``[1, min(4, n - 1)]``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from sgtool.scenegraph.kmeans import kmeans, squared_distances

MAX_REGIONS = 4
MIN_REGION_STD = 0.5  # m: the spread below which furniture counts as one place
KMEANS_ITERATIONS = 50


def _bic(points: np.ndarray, labels: np.ndarray, k: int, min_var: float) -> float:
    """BIC of a spherical Gaussian mixture with shared variance (Pelleg & Moore's X-means);
    lower is better. The variance is floored at ``min_var``."""
    n, d = points.shape
    counts = np.bincount(labels, minlength=k).astype(float)
    centres = np.array([points[labels == j].mean(0) if counts[j] else np.zeros(d)
                        for j in range(k)])
    sse = float(((points - centres[labels]) ** 2).sum())
    var = max(sse / max(d * (n - k), 1), min_var)
    nz = counts[counts > 0]
    loglik = (float(np.sum(nz * np.log(nz / n))) - n * d / 2.0 * math.log(2 * math.pi * var)
              - sse / (2.0 * var))
    params = (k - 1) + k * d + 1
    return -2.0 * loglik + params * math.log(n)


def cluster_regions(points: Sequence[Sequence[float]], max_k: int = MAX_REGIONS,
                    min_std: float = MIN_REGION_STD) -> np.ndarray:
    """Region label of each (x, y) point: k-means, k chosen by BIC in [1, min(max_k, n-1)].

    Labels are renumbered in order of first appearance, so they do not depend on k-means'
    internal order.
    """
    pts = np.asarray(points, float).reshape(-1, 2)
    n = pts.shape[0]
    if n <= 2:
        return np.zeros(n, int)
    best_labels, best_bic = np.zeros(n, int), _bic(pts, np.zeros(n, int), 1, min_std ** 2)
    first = int(np.argmin(squared_distances(pts, pts.mean(0)[None])[:, 0]))  # nearest the mean
    for k in range(2, min(max_k, n - 1) + 1):
        labels, _ = kmeans(pts, k, first, metric=squared_distances,
                           iterations=KMEANS_ITERATIONS)
        if len(set(labels.tolist())) < k:
            continue
        b = _bic(pts, labels, k, min_std ** 2)
        if b < best_bic - 1e-9:
            best_labels, best_bic = labels, b
    remap: dict[int, int] = {}
    return np.array([remap.setdefault(int(v), len(remap)) for v in best_labels], int)

