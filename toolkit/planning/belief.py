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
  finds about half of what its mass says (how the value was chosen:
  docs/experiments/moved-from-docstrings.md);
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

**Furniture-level queries.** About a third of the bench's episodes ask for a piece of
furniture ("find a dishwasher"). Such a target is a first-level piece: it is seen as soon
as the space around it is revealed, and no carrier ever holds it, so (B2) spends mass on
checking carriers that cannot pay. With φ(q) = P(q is a first-level piece | its name), a
prior handed in by the caller (:mod:`sgtool.planning.furniture_prior`; the shipped table
is (F1) of :mod:`sgtool.datasets.furniture_level`: 0 for a name outside the vocabulary of
furniture and floor-standing holders, else the Beta-smoothed share of the name's
BEHAVIOR-1K occurrences that stand alone), the belief is the mixture

    P(n) = (1 - φ) P_O(n) + φ P_F(n),                                                (B6)
    P_F(frontier f of r) ∝ R(r) / F_r,  P_F(room u) ∝ R̄,  P_F(door / out) ∝ R̄ · beyond,
    P_F(carrier o) = 0,

each component normalised over the candidates (P_O the object model (B1)-(B4)); when
nothing is left to reveal, P = P_O. φ = 0 (a small object's name, or no prior) is the
object model unchanged.

**Room types already explored** (``seen_type_weight`` η, 1 = off). A house holds few
rooms of a type (one kitchen, as a rule), so a room of a type already explored is less
likely behind the next door. With n_t the explored rooms of type t in the graph,

    R̄ = Σ_t η^{n_t} R(t) / Σ_t η^{n_t}                                               (B7)

over the scored room types: for a kitchen thing, the unknown rooms lose mass once the
kitchen is explored (its own carriers gain it), and gain it while no kitchen has been
seen. η = 1 is the plain mean of :func:`known_room_mean`.

**Many carriers of one kind** (``instance_exponent`` γ, 1 = off). C(o) scores a carrier's
category ("is a spatula found with a cabinet"), not one instance of it: a kitchen with
twenty closed cabinets and one countertop would hold twenty times the cabinet's mass and
send the search through every cabinet before the countertop. With n the carriers of o's
category in o's room (checked ones included, as in Z_r),

    C'(o) = C(o) · n^(γ - 1)                                                         (B8)

so the n together hold C · n^γ: γ = 1 is (B2) unchanged, γ = 0 gives the category one share
whatever its count, γ = 0.5 grows it with the square root of the count.

**Many openings of one room** (``leading_out_exponent`` δ, 1 = off). On a live map a
room's border with unknown space is cut into several leading-out frontiers (one opening
seen past furniture in pieces, long borders split), each of which (B4) would weigh as a
whole unknown room. With L_r the leading-out frontiers of room r,

    P(leading-out frontier f of r) ∝ R̄ · beyond · L_r^(δ - 1)                         (B10)

so the L_r together hold R̄ · beyond · L_r^δ: δ = 1 is (B4) unchanged, δ = 0 gives the
space past a room one unknown room's worth. The symbolic environment shows no leading-out
frontiers (its unknown space is behind doors and unexplored rooms), so (B10) changes only
the closed loop.

**Bayes update.** A checked place that was empty leaves the candidate set while its C(o)
stays in Z_r, so renormalising over the remaining candidates,

    P(n | checked set S empty) = P(n) / (1 - Σ_{s∈S} P(s)),                          (B5)

is the posterior of perfect detection. A place the planner tried and failed on (it could not
reach it, the graph lagged) stays a candidate with its mass times ``miss`` per failure,
the imperfect-detection update P(n) (1 - β) / (1 - β P(n)) up to normalisation.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from sgtool.planning.calibration import calibrate
from sgtool.planning.candidates import Candidate, is_carrier
from sgtool.planning.utility import UNKNOWN_ROOM
from sgtool.scenegraph.graph import ObjectNode, RegionNode, SceneGraph
from sgtool.semantics.priors import RelationScorer, can_score_room
from sgtool.semantics.text import category_text


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
    seen_type_weight: float = 1.0  # η of (B7): weight of a room type per sighting; 1: off
    instance_exponent: float = 1.0  # γ of (B8): mass of n like carriers ∝ n^γ; 1: off
    # δ of (B10): the L leading-out frontiers of one room hold R̄ · beyond · L^δ; 1: off
    leading_out_exponent: float = 1.0


def known_room_mean(scorer: RelationScorer, query: str, params: BeliefParams) -> float:
    """R̄: mean calibrated containment over the room types the scorer knows and scores."""
    types = [t for t in getattr(scorer, "room_types", ()) if can_score_room(scorer, t)]
    if not types:
        return params.fallback_room
    return float(np.mean(calibrate(scorer.rooms(types, query), params.room_floor,
                                   params.sharpness)))


def unexplored_room_mean(graph: SceneGraph, scorer: RelationScorer, query: str,
                         params: BeliefParams) -> float:
    """R̄ of (B7): the mean calibrated containment over the scored room types, each type
    weighted by η^(number of explored rooms of that type); R̄ of :func:`known_room_mean`
    when η = 1 or the scorer lists no room types."""
    types = [t for t in getattr(scorer, "room_types", ()) if can_score_room(scorer, t)]
    eta = params.seen_type_weight
    if not types or eta >= 1.0:
        return known_room_mean(scorer, query, params)
    seen = Counter(category_text(r.category) for r in graph.rooms if r.explored)
    w = np.array([eta ** seen[category_text(t)] for t in types])
    r = calibrate(scorer.rooms(types, query), params.room_floor, params.sharpness)
    return float(np.dot(w, r) / w.sum())


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


def furniture_masses(graph: SceneGraph, cands: Sequence[Candidate],
                     rooms: dict[str, float], unknown: float, params: BeliefParams) -> np.ndarray:
    """P_F of (B6): the target is a first-level piece, seen when its space is revealed, so
    no carrier holds it; a room's mass R(r) is split over its unexplored-area frontiers,
    unexplored rooms get R̄ and space behind doors / leading-out frontiers R̄ · beyond.
    Unnormalised (all zeros when nothing is left to reveal)."""
    nodes = {n.id: n for n in graph.regions}
    inner = [f for f in graph.regions
             if f.kind == "frontier" and f.frontier_type != "leading out"]
    per_room: dict[str, int] = {}
    for f in inner:
        per_room[f.room] = per_room.get(f.room, 0) + 1
    share = leading_out_shares(graph, params)
    out = np.zeros(len(cands))
    for i, c in enumerate(cands):
        node = nodes.get(c.node_id)
        if c.kind == "object":
            continue
        if c.kind == "frontier" and node is not None and \
                getattr(node, "frontier_type", None) != "leading out":
            out[i] = rooms.get(node.room, unknown) / per_room.get(node.room, 1)
        elif c.kind == "room":
            out[i] = unknown
        else:
            out[i] = unknown * params.beyond * share.get(c.node_id, 1.0)
    return out


def place_masses(graph: SceneGraph, cands: Sequence[Candidate], query: str,
                 scorer: RelationScorer, params: BeliefParams,
                 failures: Sequence[int] | None = None,
                 furniture: float = 0.0) -> np.ndarray:
    """P(target at candidate) for each candidate, (B1)-(B6); sums to 1 (all zeros for none).
    ``furniture``: φ(q) of (B6), the prior that the query is a first-level piece."""
    if not cands:
        return np.zeros(0)
    unknown = unexplored_room_mean(graph, scorer, query, params)
    rooms = room_probabilities(graph, query, scorer, params, unknown)
    out = _object_masses(graph, cands, query, scorer, params, rooms, unknown)
    if furniture > 0.0:
        pf = furniture_masses(graph, cands, rooms, unknown, params)
        if pf.sum() > 0 and out.sum() > 0:
            out = (1.0 - furniture) * out / out.sum() + furniture * pf / pf.sum()
        elif pf.sum() > 0:
            out = pf
    if failures is not None:
        out = out * params.miss ** np.asarray(failures, dtype=float)
    total = float(out.sum())
    return out / total if total > 0 else np.full(len(cands), 1.0 / len(cands))


def leading_out_shares(graph: SceneGraph, params: BeliefParams) -> dict[str, float]:
    """(B10): frontier id -> L_r^(δ - 1) for each leading-out frontier of a room with L_r
    of them; empty when δ = 1."""
    if params.leading_out_exponent == 1.0:
        return {}
    out = [f for f in graph.regions
           if f.kind == "frontier" and f.frontier_type == "leading out"]
    n = Counter(f.room for f in out)
    return {f.id: float(n[f.room]) ** (params.leading_out_exponent - 1.0) for f in out}


def split_instances(carriers: Sequence[ObjectNode], c_of: dict[str, float],
                    gamma: float) -> dict[str, float]:
    """(B8): each of the n carriers of one category in one room gets C · n^(γ - 1)."""
    n: Counter[tuple[str, str]] = Counter((o.room, category_text(o.category)) for o in carriers)
    return {o.id: c_of[o.id] * n[(o.room, category_text(o.category))] ** (gamma - 1.0)
            for o in carriers}


def _object_masses(graph: SceneGraph, cands: Sequence[Candidate], query: str,
                   scorer: RelationScorer, params: BeliefParams, rooms: dict[str, float],
                   unknown: float) -> np.ndarray:
    """P_O of (B1)-(B4), unnormalised."""
    carriers = [o for o in graph.objects if is_carrier(o)]
    c_of: dict[str, float] = {}
    if carriers:
        cs = calibrate(scorer.objects([o.category for o in carriers], query),
                       params.object_floor, params.object_sharpness)
        c_of = {o.id: float(c) for o, c in zip(carriers, cs, strict=True)}
        if params.instance_exponent != 1.0:
            c_of = split_instances(carriers, c_of, params.instance_exponent)
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
    members: tuple[RegionNode | ObjectNode, ...] = (*graph.regions, *graph.objects)
    nodes = {n.id: n for n in members}
    share = leading_out_shares(graph, params)
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
            out[i] = unknown * params.beyond * share.get(c.node_id, 1.0)
    return out
