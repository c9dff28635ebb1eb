"""k-means with a deterministic farthest-point start: the one k-means of sgtool.

Used for the regions of a room being mapped (:mod:`sgtool.scenegraph.regions`: Voronoi
nodes, planar distance) and for the regions of a symbolic benchmark house
(:mod:`sgtool.recorders.symbolic_environment.furniture_regions`: furniture positions, squared
distance, k chosen by BIC). The result depends on the points, ``first`` and the metric
only:

- seeds: ``first``, then repeatedly the point farthest from the seeds so far (ties: the
  lowest index);
- Lloyd iterations: every point to its nearest centre (ties: the lowest centre), stop when
  no label changes, else every non-empty cluster's centre to the mean of its points (an
  empty cluster keeps its centre); at most ``iterations`` rounds.

The metric is part of the result: planar (``hypot``) and squared distances order
floating-point near-ties differently, so each caller keeps the one it was built with.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

Metric = Callable[[np.ndarray, np.ndarray], np.ndarray]


def planar_distances(points: np.ndarray, centres: np.ndarray) -> np.ndarray:
    """(n, k) Euclidean distances (``hypot``) of (n, 2) points to (k, 2) centres."""
    return np.hypot(points[:, None, 0] - centres[None, :, 0],
                    points[:, None, 1] - centres[None, :, 1])


def squared_distances(points: np.ndarray, centres: np.ndarray) -> np.ndarray:
    """(n, k) squared Euclidean distances of (n, d) points to (k, d) centres."""
    return ((points[:, None, :] - centres[None, :, :]) ** 2).sum(2)


def farthest_point_seeds(points: np.ndarray, k: int, first: int,
                         metric: Metric = planar_distances) -> list[int]:
    """Indices of ``k`` seed points: ``first``, then farthest-point (module doc)."""
    seeds = [int(first)]
    d = metric(points, points[[first]])[:, 0]
    while len(seeds) < k:
        j = int(np.argmax(d))  # ties: lowest index
        seeds.append(j)
        d = np.minimum(d, metric(points, points[[j]])[:, 0])
    return seeds


def kmeans(points: np.ndarray, k: int, first: int, *, metric: Metric = planar_distances,
           iterations: int = 20) -> tuple[np.ndarray, np.ndarray]:
    """(labels (n,), centres (k, d)) of ``points`` (n, d) in ``k`` clusters (module doc)."""
    seeds = farthest_point_seeds(points, k, first, metric)
    centres = points[seeds].astype(np.float64)
    labels = np.full(len(points), -1, dtype=np.int64)
    for _ in range(iterations):
        new = np.argmin(metric(points, centres), axis=1)
        if np.array_equal(new, labels):
            break
        labels = new
        for c in range(k):
            sel = labels == c
            if sel.any():
                centres[c] = points[sel].mean(axis=0)
    return labels, centres
