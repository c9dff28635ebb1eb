"""``esc``: ESC-Interactive, MoMa-LLM's baseline after "Exploration with Soft Commonsense
Constraints" (ESC, Zhou et al., ICML 2023).

ESC scores frontiers with commonsense knowledge and combines it by probabilistic soft logic
(PSL): rules whose bodies are soft truth values in [0, 1], each with a weight, and a MAP
state of "Choose(n)" over the candidates. MoMa-LLM's "ESC-Interactive" extends the choice
to interactive actions (opening containers and doors). Our reading on a scene graph, with
the candidates of :func:`~sgtool.planning.candidates.actionable` (frontiers, unexplored rooms,
entrance doors, unexplored carriers):

- R1, *object co-occurrence*: ``NearObj(n, o) ∧ CoOccur(o, q) -> Choose(n)``; the truth of
  the body for a frontier is T_obj(n) = max over objects o within ``radius`` of n of the
  co-occurrence prior p_co(o, q) (exploring there may reveal the target beside o). For a
  carrier the body is about the carrier itself, T_obj(n) = p_co(n, q): checking a carrier
  looks into or onto that one piece, not its neighbours, so a piece does not borrow the
  score of a likely neighbour (in dense houses the max over neighbours gives whole
  clusters of unlikely pieces the score of the one likely piece among them). A candidate
  with no object near it (an unexplored room, a door, a bare frontier)
  gets the mean co-occurrence of the objects seen so far (ESC's "unknown" frontier:
  neither near likely nor unlikely things);
- R2, *room*: ``InRoom(n, r) ∧ Contains(r, q) -> Choose(n)``; T_room(n) = p_contains(r, q)
  of n's room, the mean over the prior's room types for unexplored or unscorable rooms and
  for space behind a door or a leading-out frontier;
- R3, *distance*: ``ShortDist(n) -> Choose(n)``; T_dist(n) = 1 - d(n) / max_m d(m).

We do not solve PSL's hinge-loss MAP problem (with Σ_n Choose(n) = 1 it only ranks the
candidates, and ESC picks the best one); we rank by the linear (Łukasiewicz) reading of the
rules, the weighted sum of their body truths,

    score(n) = w_obj T_obj(n) + w_room T_room(n) + w_dist T_dist(n),

and choose its argmax (nearer, then smaller id, among equals). Like ESC, the choice is
greedy (no planning over sequences) and the knowledge enters only through the scores; the
priors stand in for ESC's LLM and detector.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sgtool.planning.belief import BeliefParams, known_room_mean, room_probabilities
from sgtool.planning.candidates import Candidate
from sgtool.planning.planners import ScoringPlanner
from sgtool.planning.utility import objects_within
from sgtool.scenegraph.graph import ObjectNode, RegionNode, SceneGraph
from sgtool.semantics.priors import RelationScorer

_RAW = BeliefParams(room_floor=0.0, object_floor=0.0)


@dataclass(frozen=True)
class EscParams:
    w_obj: float = 1.0  # R1
    w_room: float = 1.0  # R2
    w_dist: float = 0.5  # R3
    radius: float = 2.0  # metres: "near" of R1


def esc_scores(graph: SceneGraph, cands: list[Candidate], query: str, scorer: RelationScorer,
               params: EscParams) -> np.ndarray:
    """score(n) of the module doc for each candidate."""
    objs = list(graph.objects)
    co = scorer.objects([o.category for o in objs], query) if objs else np.zeros(0)
    co_of = {o.id: float(s) for o, s in zip(objs, co, strict=True)}
    unknown_obj = float(np.mean(co)) if objs else 0.5
    unknown_room = known_room_mean(scorer, query, _RAW)
    rooms = room_probabilities(graph, query, scorer, _RAW, unknown_room)
    obj_xy = [(o.id, float(o.position[0]), float(o.position[1])) for o in objs]
    d_max = max((c.distance for c in cands), default=0.0) or 1.0
    members: tuple[RegionNode | ObjectNode, ...] = (*graph.regions, *objs)
    nodes = {n.id: n for n in members}
    out = np.zeros(len(cands))
    for k, c in enumerate(cands):
        if c.kind == "object":
            t_obj = co_of.get(c.node_id, unknown_obj)
        else:
            near = [co_of[i] for i in objects_within(obj_xy, c.position, params.radius)]
            t_obj = max(near) if near else unknown_obj
        node = nodes.get(c.node_id)
        leading_out = getattr(node, "frontier_type", None) == "leading out"
        room = getattr(node, "room", None) if c.kind in ("object", "frontier") else None
        t_room = unknown_room if room is None or leading_out else rooms.get(room, unknown_room)
        t_dist = 1.0 - c.distance / d_max
        out[k] = params.w_obj * t_obj + params.w_room * t_room + params.w_dist * t_dist
    return out


class EscPlanner(ScoringPlanner[EscParams]):
    """ESC-Interactive: soft commonsense constraints over frontiers and carriers (a utility
    planner whose utility is the rule score and whose selection is the plain argmax)."""

    def __init__(self, scorer: RelationScorer, params: EscParams = EscParams(),
                 name: str = "esc", max_failures: int = 2) -> None:
        super().__init__(name, scorer, params, max_failures)

    def choose(self, graph: SceneGraph, cands: list[Candidate]
               ) -> tuple[int, str, dict[str, float]]:
        s = esc_scores(graph, cands, self.query, self.scorer, self.params)
        i = min(range(len(cands)), key=lambda k: (-s[k], cands[k].distance, cands[k].node_id))
        scores = {c.node_id: round(float(v), 4) for c, v in zip(cands, s, strict=True)}
        return i, f"score={s[i]:.3f}, d={cands[i].distance:.2f} m", scores
