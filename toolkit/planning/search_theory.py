"""``bayes-search``: optimal-search theory over the scene graph.

The target's location is a distribution over the places the robot can check
(:mod:`sgtool.planning.belief`: calibrated containment and co-occurrence priors, Bayes
updates as places are found empty). Checking place i costs

    c_i = d_i + a + b·[open] + e·[reveal]                                             (S1)

metres-equivalent: d_i the travel distance, ``a`` the price of spending one action, ``b``
the extra of an open interaction, ``e`` the expected local travel still needed after
revealing a region or room (0 by default: what the reveal teaches about the room pays for
it). The episode has a step budget (``step_budget``, SymSearch's N_max = 50): when the mass
is spread over more places than there are steps left, an action becomes dearer,

    a_t = a · max(1, N_eff / steps_left),   N_eff = 1 / Σ_i p_i²                       (S3)

(N_eff, the effective number of places, is the inverse Simpson index of the belief). For
independent places with perfect detection and no switching cost the
expected cost to find is minimised by checking in decreasing order of p_i / c_i (the
classic ratio rule of search theory; Kadane & Simon 1977, Stone 1975). Travel costs are
not independent of the order, so the ratio only preselects: among the ``top_k`` places by
p_i / c_i, every ordering (i_1, .., i_h) of ``horizon`` of them is scored by its detection
probability per expected cost

    V = (Σ_j p_{i_j}) / E[cost],
    E[cost] = c_{i_1} + Σ_{j≥2} (1 - Σ_{l<j} p_{i_l}) · c(i_{j-1} -> i_j)            (S2)

(later legs are paid only if the earlier places were empty), with the leg cost
c(i -> j) = ρ·|x_i - x_j| + a + b·[open_j] + e·[reveal_j]; ρ, the detour factor, is the
median ratio of travel distance to straight-line distance over the current candidates
(≥ 1). The first place of the best ordering is checked; after the outcome the
distribution is rebuilt from the new graph (B5), so the plan is re-made at every step
(receding horizon). Everything is deterministic (ties broken by node id): the seed is not
used.

**Dense houses** (the bench's ``symsearch`` preset: many first-level pieces per room, most
of them empty, a fixed action budget) shape the defaults:

- the novelty blend of :mod:`~sgtool.planning.calibration` is gated by the weights' own
  held-out AUC, (C4), since a blend that gives unseen queries the cosine's flat room
  scores spreads the belief over rooms that do not hold the target;
- C is sharpened (exponent 2, a base-rate correction) and an unseen region counts at half
  its expected carrier mass (ω = 0.5), :mod:`~sgtool.planning.belief`: each checked piece
  costs an action and most are empty;
- the price of an action is a = 3 m: with few actions for many places the budget binds
  before the distance does; the look-ahead orders 3 of the best 5 places;
- furniture-level targets are found by revealing space, never inside a carrier, so the
  furniture-level prior φ(q) ((B6) of :mod:`~sgtool.planning.belief`, (F1) of
  :mod:`sgtool.datasets.furniture_level`) moves their mass to frontiers, rooms and doors;
  φ is 0 outside the vocabulary of furniture and floor-standing holders.

The runs that chose these values (SR/SPL per setting, houses and seeds) are in
docs/experiments/moved-from-docstrings.md.
"""

from __future__ import annotations

import functools
import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from sgtool.planning.belief import BeliefParams, place_masses
from sgtool.planning.candidates import Candidate
from sgtool.planning.furniture_prior import furniture_level
from sgtool.planning.planners import ScoringPlanner
from sgtool.scenegraph.graph import SceneGraph
from sgtool.semantics.priors import RelationScorer

REVEAL_KINDS = frozenset({"room", "frontier", "door"})


@dataclass(frozen=True)
class SearchParams:
    step_cost: float = 3.0  # a of (S1), metres per action
    open_cost: float = 0.5  # b of (S1)
    reveal_cost: float = 0.0  # e of (S1)
    top_k: int = 5
    horizon: int = 3
    step_budget: int = 50  # actions per episode (SymSearch's N_max); 0: no budget
    belief: BeliefParams = field(default_factory=BeliefParams)


def step_price(p: np.ndarray, steps_left: int | None, base: float) -> float:
    """a of (S1): ``base``, raised when the mass is spread over more places than there are
    steps left: a · max(1, N_eff / steps_left) with N_eff = 1 / Σ p² (module doc)."""
    if not steps_left or steps_left <= 0 or not len(p):
        return base
    return base * max(1.0, effective_places(p) / steps_left)


def effective_places(p: np.ndarray) -> float:
    """N_eff of (S3): 1 / Σ p², the inverse Simpson index of the belief."""
    return 1.0 / max(float(np.sum(p * p)), 1e-12)


def extra_cost(c: Candidate, params: SearchParams, step: float | None = None) -> float:
    """The part of (S1) besides travel (``step``: the price of an action, default a)."""
    step = params.step_cost if step is None else step
    return (step + (params.open_cost if c.skill == "open" else 0.0)
            + (params.reveal_cost if c.kind in REVEAL_KINDS else 0.0))


def detour_factor(cands: Sequence[Candidate], robot: tuple[float, float]) -> float:
    """ρ of (S2): median travel / straight-line distance, clipped to [1, 3]."""
    ratios = []
    for c in cands:
        e = math.hypot(c.position[0] - robot[0], c.position[1] - robot[1])
        if e > 0.5:
            ratios.append(c.distance / e)
    return float(np.clip(np.median(ratios), 1.0, 3.0)) if ratios else 1.0


def best_first(cands: Sequence[Candidate], p: np.ndarray, robot: tuple[float, float],
               params: SearchParams, steps_left: int | None = None) -> tuple[int, float]:
    """Index of the candidate to check first and the value of its ordering (module doc)."""
    step = step_price(p, steps_left, params.step_cost)
    extra = np.array([extra_cost(c, params, step) for c in cands])
    first = np.array([c.distance for c in cands]) + extra
    ratio = p / first
    ranked = sorted(range(len(cands)), key=lambda i: (-ratio[i], cands[i].node_id))
    top = ranked[: max(1, params.top_k)]
    h = min(params.horizon, len(top))
    if h <= 1:
        return top[0], float(ratio[top[0]])
    rho = detour_factor(cands, robot)
    xy = np.array([cands[i].position for i in range(len(cands))])
    legs = np.zeros((len(cands), len(cands)))
    for a in top:
        for b in top:
            legs[a, b] = rho * float(np.hypot(*(xy[a] - xy[b]))) + extra[b]
    orders = np.asarray(top)[_orderings(len(top), h)]
    v = sequence_values(orders, p, first, legs)
    # the best value; among equal values the ordering whose node ids sort first
    ties = np.flatnonzero(v == v.max())
    k = min(ties, key=lambda t: tuple(cands[i].node_id for i in orders[t]))
    return int(orders[k, 0]), float(v[k])


@functools.cache
def _orderings(n: int, h: int) -> np.ndarray:
    """Every ordering of ``h`` of ``range(n)``, one per row, in itertools order."""
    return np.array(list(itertools.permutations(range(n), h)), dtype=np.intp).reshape(-1, h)


def sequence_values(orders: np.ndarray, p: np.ndarray, first_cost: np.ndarray,
                    legs: np.ndarray) -> np.ndarray:
    """V of (S2) for every row of ``orders`` (candidate indices): ``p`` per candidate,
    ``first_cost`` the cost of reaching each first, ``legs[a, b]`` the leg from a to b. The
    legs are summed left to right, so a row's value is the same bit for bit as one
    ordering's loop."""
    pp = p[orders]
    cost = first_cost[orders[:, 0]].astype(np.float64)
    left = np.ones(len(orders))
    total = pp[:, 0].astype(np.float64)
    for j in range(1, orders.shape[1]):
        left = left - pp[:, j - 1]
        cost = cost + np.maximum(left, 0.0) * legs[orders[:, j - 1], orders[:, j]]
        total = total + pp[:, j]
    return np.asarray(total / cost)


class SearchTheoryPlanner(ScoringPlanner[SearchParams]):
    """Bayesian search with the p/c ratio rule and a short look-ahead (module doc).
    ``furniture_levels``: name -> φ of (B6) (:mod:`sgtool.planning.furniture_prior`);
    None: every query is taken for a small object."""

    def __init__(self, scorer: RelationScorer, params: SearchParams = SearchParams(),
                 name: str = "bayes-search", max_failures: int = 2,
                 furniture_levels: Mapping[str, float] | None = None) -> None:
        super().__init__(name, scorer, params, max_failures)
        self.steps = 0
        self.furniture_levels = furniture_levels
        self.furniture = 0.0

    def reset(self, query: str, seed: int = 0) -> None:
        super().reset(query, seed)
        self.steps = 0
        self.furniture = furniture_level(self.furniture_levels, query)

    def choose(self, graph: SceneGraph, cands: list[Candidate]
               ) -> tuple[int, str, dict[str, float]]:
        fails = [len(self.memory.failures.get(c.node_id, ())) for c in cands]
        p = place_masses(graph, cands, self.query, self.scorer, self.params.belief, fails,
                         self.furniture)
        budget = self.params.step_budget
        left = budget - self.steps if budget > 0 else None
        self.steps += 1
        i, value = best_first(cands, p, graph.robot.position, self.params, left)
        scores = {c.node_id: round(float(v), 4) for c, v in zip(cands, p, strict=True)}
        return i, f"p={p[i]:.3f}, d={cands[i].distance:.2f} m, value={value:.4f}", scores
