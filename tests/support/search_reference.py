"""The plain form of bayes-search's look-ahead value: one ordering at a time, a Python loop
over its legs (the reference :func:`sgtool.planning.search_theory.sequence_values` is
checked against, bit for bit)."""

from __future__ import annotations

import itertools
from collections.abc import Sequence

import numpy as np


def sequence_value(order: Sequence[int], p: np.ndarray, first_cost: np.ndarray,
                   legs: np.ndarray) -> float:
    """V of (S2) (:mod:`sgtool.planning.search_theory`) for an ordering of candidate
    indices: detection probability summed over the ordering per expected cost, a leg paid
    only with the probability that the places before it were empty."""
    cost = float(first_cost[order[0]])
    left = 1.0
    for a, b in itertools.pairwise(order):
        left -= float(p[a])
        cost += max(left, 0.0) * float(legs[a, b])
    return float(sum(p[i] for i in order)) / cost
