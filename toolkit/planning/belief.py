"""Where the target is: a probability distribution over the places a planner can check.

The hypotheses are the actionable nodes (:func:`~sgtool.planning.candidates.actionable`):
"the target is in/on this unexplored carrier", "... in the unseen part of this room behind
this frontier", "... in the unknown space behind this unexplored room, closed door or
leading-out frontier". With R(r) the calibrated containment probability of room r
(:func:`~sgtool.planning.calibration.calibrate` of the prior's p_contains) and C(o) the
calibrated co-occurrence of carrier o:

    P(in r)            ∝ R(r)                                                        (B1)
    P(o | in r)        = C(o) / Z_r,    Z_r = Σ_{carriers o' of r} C(o') + F_r K      (B2)
    P(frontier f | r)  = K / Z_r                                                     (B3)
    P(unknown node u)  ∝ R̄ · beyond(u)                                               (B4)

- Z_r sums over *every* carrier of the room, checked ones included, and F_r is the number
  of its unexplored-area frontiers: an unseen region is expected to hold K carrier mass,
  K = ω · n̄ · C̄ (n̄ carriers per revealed region and C̄ the mean C of the carriers seen
  so far in the graph, so K adapts to sparse and dense houses alike). ω
  (``region_weight``, 0.5) discounts a region for the second action its carriers need:
  exploring it only reveals them, checking one is another step, so per action a region
  finds about half of what its mass says (0.5 measured best of 0.5, 1 and 2, below);
- R̄ is the mean calibrated containment over the room types the prior knows (what an
  unknown room is expected to be); ``beyond`` weights space that may hold more than one
  room (a leading-out frontier, a door);
- a room whose category the prior cannot score (or an unexplored one) gets R̄;
- (C1)'s floor and exponent are set apart for R (``room_floor``, ``sharpness``) and C
  (``object_floor``, ``object_sharpness``). C is sharpened (exponent 2): the co-occurrence
  model is trained on one negative per positive, a base rate of 1/2, while in a house a
  small share of the pieces holds the target; correcting a score for a lower base rate
  multiplies its odds by a constant, which for the low base rates of a dense house widens
  the ratios between pieces (odds(s) / odds(s') > s / s'); s² is the milder version of
  that correction (the full odds ratio overweights the model's mistakes).

Measured on the dense ``symsearch`` bench houses, one seed, 100 episodes per house range
(houses 0-4 / houses 100-104), SR / SPL of ``bayes-search`` with step cost 3: ω = 1,
sharpness 1: 0.690 / 0.247 (houses 0-4, step cost 3); ω = 1, C sharpness 2: 0.700 / 0.262
and 0.810 / 0.231; ω = 0.5: 0.720 / 0.271 and 0.760 / 0.236; ω = 2: 0.680 / 0.258 and
0.790 / 0.225; ``scout`` on the same episodes: 0.670 / 0.237 and 0.730 / 0.212.

**Bayes update.** A checked place that was empty leaves the candidate set while its C(o)
stays in Z_r, so renormalising over the remaining candidates,

    P(n | checked set S empty) = P(n) / (1 - Σ_{s∈S} P(s)),                          (B5)

is the posterior of perfect detection. A place the planner tried and failed on (it could not
reach it, the graph lagged) stays a candidate with its mass times ``miss`` per failure,
the imperfect-detection update P(n) (1 - β) / (1 - β P(n)) up to normalisation.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from sgtool.planning.calibration import calibrate
from sgtool.planning.candidates import Candidate, is_carrier
from sgtool.planning.utility import UNKNOWN_ROOM
from sgtool.scenegraph.graph import SceneGraph
from sgtool.semantics.priors import RelationScorer, can_score_room


@dataclass(frozen=True)
class BeliefParams:
    room_floor: float = 0.05  # (C1) floor of R
    object_floor: float = 0.05  # (C1) floor of C
    sharpness: float = 1.0  # (C1) exponent of R
    object_sharpness: float = 2.0  # (C1) exponent of C (module doc)
    beyond: float = 1.0  # weight of space behind a door / leading-out frontier, (B4)
    miss: float = 0.5  # mass factor per failed attempt on a node (1 - beta)
    fallback_room: float = 0.3  # R̄ when the prior lists no room types
    region_weight: float = 0.5  # ω of K = ω n̄ C̄, (B2)-(B3) (module doc)


def known_room_mean(scorer: RelationScorer, query: str, params: BeliefParams) -> float:
    """R̄: mean calibrated containment over the room types the scorer knows and scores."""
    types = [t for t in getattr(scorer, "room_types", ()) if can_score_room(scorer, t)]
    if not types:
        return params.fallback_room
    return float(np.mean(calibrate(scorer.rooms(types, query), params.room_floor,
                                   params.sharpness)))


def room_probabilities(graph: SceneGraph, query: str, scorer: RelationScorer,
                       params: BeliefParams, unknown: float) -> dict[str, float]:
    """R(r) for every room node: calibrated containment, ``unknown`` (R̄) where unscored."""
    known = [r for r in graph.rooms if r.explored and r.category.lower() not in UNKNOWN_ROOM
             and can_score_room(scorer, r.category)]
    out = {r.id: unknown for r in graph.rooms}
    if known:
        scores = calibrate(scorer.rooms([r.category for r in known], query),
                           params.room_floor, params.sharpness)
        out.update({r.id: float(s) for r, s in zip(known, scores, strict=True)})
    return out


def place_masses(graph: SceneGraph, cands: Sequence[Candidate], query: str,
                 scorer: RelationScorer, params: BeliefParams,
                 failures: Sequence[int] | None = None) -> np.ndarray:
    """P(target at candidate) for each candidate, (B1)-(B5); sums to 1 (all zeros for none)."""
    if not cands:
        return np.zeros(0)
    unknown = known_room_mean(scorer, query, params)
    rooms = room_probabilities(graph, query, scorer, params, unknown)
    carriers = [o for o in graph.objects if is_carrier(o)]
    c_of: dict[str, float] = {}
    if carriers:
        cs = calibrate(scorer.objects([o.category for o in carriers], query),
                       params.object_floor, params.object_sharpness)
        c_of = {o.id: float(c) for o, c in zip(carriers, cs, strict=True)}
    revealed = sum(1 for r in graph.regions if r.kind != "frontier")
    per_region = max(1.0, len(carriers) / max(1, revealed))
    mean_c = float(np.mean(list(c_of.values()))) if c_of else 0.5
    k_region = params.region_weight * per_region * mean_c  # K of (B2)-(B3)
    z: dict[str, float] = {}
    for o in carriers:
        z[o.room] = z.get(o.room, 0.0) + c_of[o.id]
    for f in graph.regions:
        if f.kind == "frontier" and f.frontier_type != "leading out":
            z[f.room] = z.get(f.room, 0.0) + k_region
    nodes = {n.id: n for n in (*graph.regions, *graph.objects)}
    out = np.zeros(len(cands))
    for i, c in enumerate(cands):
        node = nodes.get(c.node_id)
        room = getattr(node, "room", None)
        if c.kind == "object" and room is not None:
            zr = z.get(room) or c_of.get(c.node_id, 1.0)
            out[i] = rooms.get(room, unknown) * c_of.get(c.node_id, mean_c) / zr
        elif c.kind == "frontier" and room is not None and \
                getattr(node, "frontier_type", None) != "leading out":
            out[i] = rooms.get(room, unknown) * k_region / (z.get(room) or k_region)
        elif c.kind == "room":
            out[i] = unknown
        else:  # closed door, leading-out frontier: space beyond
            out[i] = unknown * params.beyond
        if failures is not None and failures[i]:
            out[i] *= params.miss ** failures[i]
    total = float(out.sum())
    return out / total if total > 0 else np.full(len(cands), 1.0 / len(cands))
