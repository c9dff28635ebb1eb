"""``voi``: search by value of information, looking weighed against opening.

The belief is that of ``bayes-rooms`` ((B1)-(B8) of :mod:`sgtool.planning.belief`: (B7)
η = 0.3, (B8) γ = 0.5), kept per episode and updated from what changed,
:class:`EpisodeBelief`; it equals :func:`~sgtool.planning.belief.place_masses`. What
differs is what an action is worth. Every action costs one step of the budget and its
travel; what it buys differs by kind:

- checking a carrier o (``open`` a closed one, walk up to an open one) resolves p_o at
  once: the target is on or in it, or not;
- revealing space (an unexplored-area frontier, an unexplored room, a closed door, a
  leading-out frontier) shows first-level pieces: a furniture-level target is seen at
  once, a small object on or in a revealed piece only after a further check of that piece.

With p_i the belief mass of candidate i, split by (B6) into the part seen on arrival and
the part that needs follow-up checks,

    p_i = p_i^now + p_i^next,   p^now = φ P_F + (1 - φ) P_O [i a carrier],
                                p^next = (1 - φ) P_O [i reveals space]                (V1)

and c_i = d_i + a_t + b·[open] its cost in metres-equivalent (d_i travel, a_t the price of
an action, (S3) of :mod:`sgtool.planning.search_theory`, b the extra of an open), a reveal
is priced with the checks it needs:

    c'_i = c_i + f · a_t · p_i^next / p_i           (f = ``follow_steps`` when set)     (V2)

    f̂ = mean over revealed places of Σ_j j w_j                     (``follow_rule`` mean)  (V3)

    c'_i = p_i / max_{k=0..K} (p_i^now + p_i^next W̄_k) / (c_i + k a_t)
                                                              (``follow_rule`` prefix)  (V4)

A revealed place is the set of carriers sharing a parent (a region); w_j are its carriers'
C' shares in decreasing order (the order the ratio rule checks them), W̄_k the share its k
likeliest carriers hold, averaged over the revealed places (W̄_0 = 0, W̄_K = 1). (V3)
charges the expected number of checks; (V4), the default, values a reveal by its best
initial segment (reveal, then the k likeliest pieces), the ratio that orders a chain of
actions in optimal search under precedence constraints (Sidney 1975; Kadane & Simon 1977):
a reveal whose region's mass sits on one likely piece is nearly as good as checking that
piece, one whose mass is spread pays for the checks. The region's mass is what the belief
says (ω = 1 of (B2)-(B3)): what a reveal cannot buy at once is charged as cost instead
of a discount. So a room, door or frontier is worth its price exactly when its mass per
step-and-checks beats the best carrier's mass per step; and since the n carriers of one
category in a room hold C n^γ between them (B8), twenty closed cabinets do not outweigh
one countertop, and a likely room that has not been seen is worth its visit before the
cheap containers are exhausted. Places are ordered by (S2) (the best ordering of
``horizon`` of the ``top_k`` places by p/c', detection probability per expected cost),
with c' on every leg.

**The price of an action** (``step_rule``). SPL counts metres only; a = 3 m per action
stands for the step budget, which matters only when it can run out. (S3) of
:mod:`sgtool.planning.search_theory` raises a when the mass is spread over more places
than steps are left and never lowers it; the default, ``slack``, also lowers it while the
budget cannot bind:

    a_t = a · max(N_eff / s, min(1, N_rem / s)),                                       (V5)
    N_rem = #checks + #regions (1 + n̄) + #spaces m̄ (1 + n̄)

s the steps left, N_rem the actions that would check every place with mass: one per
carrier, a reveal and its n̄ carriers per unseen region (n̄ of (B2)), m̄ regions' worth
per unexplored room, closed door or leading-out frontier (m̄ the mean number of regions of
the rooms seen). In a small house with steps to spare the search orders by travel, as
SPL does; in a dense one, whose places outnumber the steps, (V5) is (S3).

Everything is deterministic (ties broken by node id); the seed is not used.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from sgtool.planning.belief import BeliefParams
from sgtool.planning.calibration import calibrate
from sgtool.planning.candidates import (
    Candidate,
    CandidateColumns,
    is_carrier,
)
from sgtool.planning.furniture_prior import furniture_level
from sgtool.planning.planners import ScoringPlanner
from sgtool.planning.search_theory import (
    _orderings,
    effective_places,
    sequence_values,
    step_price,
)
from sgtool.planning.utility import UNKNOWN_ROOM
from sgtool.scenegraph.graph import ObjectNode, RegionNode, RoomNode, SceneGraph
from sgtool.semantics.priors import RelationScorer, can_score_room
from sgtool.semantics.text import category_text

REVEAL_KINDS = frozenset({"room", "frontier", "door"})


def voi_belief() -> BeliefParams:
    """The belief of ``voi``: (B7) η = 0.3, (B8) γ = 0.5 as ``bayes-rooms``, ω = 1 (V2)."""
    return BeliefParams(region_weight=1.0, seen_type_weight=0.3, instance_exponent=0.5)


@dataclass(frozen=True)
class VoiParams:
    step_cost: float = 3.0  # a of (V2), metres per action
    open_cost: float = 0.5  # b of (V2)
    # f of (V2): actions after a reveal to check what it showed; None: f̂ of (V3)
    follow_steps: float | None = None
    follow_rule: str = "prefix"  # f unset: "prefix" (V4) or "mean" (V3)
    top_k: int = 5
    horizon: int = 3
    step_budget: int = 50  # actions per episode (N_max) of the step price (S3); 0: none
    step_rule: str = "slack"  # "slack": a_t of (V5); "floor": a_t of (S3)
    belief: BeliefParams = field(default_factory=voi_belief)


# what the belief needs of one node: (code, room id, carrier index or -1)
_CARRIER, _OBJECT, _INNER, _OUT = 0, 1, 2, 3


class EpisodeBelief:
    """(B1)-(B8) of :mod:`sgtool.planning.belief` for one episode and query, equal to
    :func:`~sgtool.planning.belief.place_masses` up to rounding, computed from what changed:
    the calibrated scores are kept per category, the carrier table per objects tuple, the
    frontier table per regions tuple, the room table per rooms tuple (an incremental graph
    passes the same tuple while nothing in it changed)."""

    def __init__(self, scorer: RelationScorer, query: str, params: BeliefParams,
                 furniture: float = 0.0) -> None:
        self.scorer = scorer
        self.query = query
        self.params = params
        self.furniture = furniture
        self._c: dict[str, float] = {}  # calibrated C per category as given
        self._r: dict[str, float] = {}  # calibrated R per room category as given
        self._types: tuple[list[str], np.ndarray] | None = None
        self._rbar: dict[tuple[int, ...], float] = {}
        self._objects: tuple[ObjectNode, ...] | None = None
        self._obj_table: tuple[dict[str, tuple[int, str, float]], dict[str, float], float,
                               int] = ({}, {}, 0.5, 0)
        self._regions: tuple[RegionNode, ...] | None = None
        self._reg_table: tuple[dict[str, tuple[int, str]], list[str], dict[str, int], int,
                               dict[str, int]] = ({}, [], {}, 0, {})
        self._rooms: tuple[RoomNode, ...] | None = None
        self._room_table: tuple[dict[str, float], float] = ({}, params.fallback_room)
        self._regions_per_room = 1.0  # m̄ of (V5) for the last regions tuple
        self._carrier_list: list[ObjectNode] = []  # the last objects tuple's carriers
        self._carrier_c: list[float] = []  # and their C' (B8)
        self._follow: float | None = None  # f̂ of (V3), computed when asked
        self._profile: np.ndarray | None = None  # W̄ of (V4), computed when asked
        self.remaining = 0.0  # N_rem of (V5) for the last candidates
        # id(node) -> (node, is a carrier, category text); holds the node, so the id stays
        self._nodes: dict[int, tuple[ObjectNode, bool, str]] = {}

    # ----- scores ----------------------------------------------------------------------
    def _carrier_scores(self, cats: Sequence[str]) -> list[float]:
        miss = sorted({c for c in cats if c not in self._c})
        if miss:
            p = self.params
            cs = calibrate(self.scorer.objects(miss, self.query), p.object_floor,
                           p.object_sharpness)
            self._c.update(zip(miss, map(float, cs), strict=True))
        return [self._c[c] for c in cats]

    def _room_score(self, cat: str) -> float:
        r = self._r.get(cat)
        if r is None:
            p = self.params
            r = self._r[cat] = float(calibrate(self.scorer.rooms([cat], self.query),
                                               p.room_floor, p.sharpness)[0])
        return r

    def _unknown(self, rooms: tuple[RoomNode, ...]) -> float:
        """R̄ of (B7)."""
        p = self.params
        if self._types is None:
            types = [t for t in getattr(self.scorer, "room_types", ())
                     if can_score_room(self.scorer, t)]
            cal = calibrate(self.scorer.rooms(types, self.query), p.room_floor,
                            p.sharpness) if types else np.zeros(0)
            self._types = (types, np.asarray(cal, dtype=np.float64))
        types, cal = self._types
        if not types:
            return p.fallback_room
        if p.seen_type_weight >= 1.0:
            return float(np.mean(cal))
        seen = Counter(category_text(r.category) for r in rooms if r.explored)
        key = tuple(seen[category_text(t)] for t in types)
        hit = self._rbar.get(key)
        if hit is None:
            w = np.array([p.seen_type_weight ** n for n in key])
            hit = self._rbar[key] = float(np.dot(w, cal) / w.sum())
        return hit

    # ----- tables per node tuple -------------------------------------------------------
    def _room_masses(self, graph: SceneGraph) -> tuple[dict[str, float], float]:
        if graph.rooms is not self._rooms:
            unknown = self._unknown(graph.rooms)
            out = {r.id: unknown for r in graph.rooms}
            for r in graph.rooms:
                if r.explored and r.category.lower() not in UNKNOWN_ROOM and \
                        can_score_room(self.scorer, r.category):
                    out[r.id] = self._room_score(r.category)
            self._rooms, self._room_table = graph.rooms, (out, unknown)
        return self._room_table

    def _carriers(self, graph: SceneGraph
                  ) -> tuple[dict[str, tuple[int, str, float]], dict[str, float], float, int]:
        """Per object id (code, room, C' of (B8)); Z_r's carrier part; C̄; carrier count."""
        if graph.objects is self._objects:
            return self._obj_table
        memo = self._nodes
        if len(memo) > 1 << 14:
            memo.clear()
        info = []
        for o in graph.objects:
            e = memo.get(id(o))
            if e is None or e[0] is not o:
                e = memo[id(o)] = (o, is_carrier(o), category_text(o.category))
            info.append(e)
        carriers = [e[0] for e in info if e[1]]
        c = self._carrier_scores([o.category for o in carriers])
        gamma = self.params.instance_exponent
        if gamma != 1.0 and carriers:
            keys = [(e[0].room, e[2]) for e in info if e[1]]
            n = Counter(keys)
            c = [v * n[k] ** (gamma - 1.0) for v, k in zip(c, keys, strict=True)]
        zc: dict[str, float] = {}
        for o, v in zip(carriers, c, strict=True):
            zc[o.room] = zc.get(o.room, 0.0) + v
        table = {o.id: (_OBJECT, o.room, 0.0) for o in reversed(graph.objects)}
        table.update((o.id, (_CARRIER, o.room, v)) for o, v in zip(carriers, c, strict=True))
        mean_c = float(np.mean(c)) if c else 0.5
        self._objects, self._obj_table = graph.objects, (table, zc, mean_c, len(carriers))
        self._carrier_list, self._carrier_c = carriers, c
        self._follow = self._profile = None
        return self._obj_table

    @property
    def follow(self) -> float:
        """f̂ of (V3) for the last objects tuple (1 before any)."""
        if self._follow is None:
            self._follow = expected_checks(self._carrier_list, self._carrier_c)
        return self._follow

    @property
    def profile(self) -> np.ndarray:
        """W̄ of (V4) for the last objects tuple ([1] before any)."""
        if self._profile is None:
            self._profile = share_profile(self._carrier_list, self._carrier_c)
        return self._profile

    def _frontiers(self, graph: SceneGraph
                   ) -> tuple[dict[str, tuple[int, str]], list[str], dict[str, int], int,
                              dict[str, int]]:
        """Per region id (code, room); the rooms of the inner frontiers in graph order,
        their count per room; the revealed regions' count; the leading-out frontiers'
        count per room."""
        if graph.regions is self._regions:
            return self._reg_table
        table: dict[str, tuple[int, str]] = {}
        inner: list[str] = []
        out: list[str] = []
        revealed = 0
        self._regions_per_room = len(graph.regions) / max(1, len({f.room for f in graph.regions}))
        for f in graph.regions:
            if f.kind != "frontier":
                revealed += 1
                code = _OBJECT  # a revealed region is no candidate; never read
            elif f.frontier_type != "leading out":
                inner.append(f.room)
                code = _INNER
            else:
                out.append(f.room)
                code = _OUT
            table.setdefault(f.id, (code, f.room))
        self._regions, self._reg_table = graph.regions, (table, inner, Counter(inner), revealed,
                                                          Counter(out))
        return self._reg_table

    # ----- the belief ------------------------------------------------------------------
    def masses(self, graph: SceneGraph, ids: Sequence[str], kinds: Sequence[str],
               failures: Sequence[int] | None = None) -> tuple[np.ndarray, np.ndarray]:
        """(P, P^next): the belief over the candidates ``ids`` (of ``kinds``), normalised,
        and the part of each that a follow-up check must find, (V1)."""
        n = len(ids)
        if not n:
            return np.zeros(0), np.zeros(0)
        p = self.params
        rooms, unknown = self._room_masses(graph)
        objs, zc, mean_c, ncar = self._carriers(graph)
        regs, inner, per_room, revealed, outs = self._frontiers(graph)
        delta = p.leading_out_exponent
        per_region = max(1.0, ncar / max(1, revealed))
        k = p.region_weight * per_region * mean_c  # K of (B2)-(B3)
        z = dict(zc)
        for r in inner:
            z[r] = z.get(r, 0.0) + k
        beyond = unknown * p.beyond
        po = np.empty(n)
        pf = np.zeros(n)
        reveal = np.zeros(n, dtype=bool)
        phi = self.furniture
        n_check = n_region = n_space = 0  # for N_rem of (V5)
        for i, (nid, kind) in enumerate(zip(ids, kinds, strict=True)):
            if kind == "object":
                code, room, c = objs.get(nid, (_OUT, "", 0.0))
                if code == _OUT:  # not a node of the graph: space beyond, as (B4)
                    po[i] = beyond
                    n_space += 1
                    continue
                n_check += 1
                zr = z.get(room) or (c if code == _CARRIER else 1.0)
                po[i] = rooms.get(room, unknown) * (c if code == _CARRIER else mean_c) / zr
                continue
            reveal[i] = True
            if kind == "frontier":
                code, room = regs.get(nid, (_OUT, ""))
                if code == _INNER:
                    n_region += 1
                    po[i] = rooms.get(room, unknown) * k / (z.get(room) or k)
                    if phi > 0.0:
                        pf[i] = rooms.get(room, unknown) / per_room.get(room, 1)
                    continue
            n_space += 1
            if kind == "room":
                po[i] = pf[i] = unknown
            elif kind == "frontier" and code == _OUT and delta != 1.0:  # (B10)
                po[i] = pf[i] = beyond * float(outs.get(room, 1)) ** (delta - 1.0)
            else:  # a closed door, a leading-out frontier: space beyond
                po[i] = pf[i] = beyond
        self.remaining = remaining_actions(n_check, n_region, n_space, per_region,
                                           self._regions_per_room)
        if phi > 0.0:
            so, sf = float(po.sum()), float(pf.sum())
            if sf > 0 and so > 0:
                po = (1.0 - phi) * po / so
                pf = phi * pf / sf
            elif sf > 0:
                po, pf = np.zeros(n), pf
            else:
                pf = np.zeros(n)
        else:
            pf = np.zeros(n)
        total_now = po + pf
        if failures is not None and any(failures):
            f = p.miss ** np.asarray(failures, dtype=float)
            po, pf, total_now = po * f, pf * f, total_now * f
        s = float(total_now.sum())
        if s <= 0:
            return np.full(n, 1.0 / n), np.zeros(n)
        nxt = np.where(reveal, po, 0.0) / s
        return total_now / s, nxt


def remaining_actions(checks: int, regions: int, spaces: int, per_region: float,
                      regions_per_room: float) -> float:
    """N_rem of (V5): the actions that would check every place the belief gives mass, one
    per carrier, 1 + n̄ per unseen region (the reveal and its carriers), m̄ (1 + n̄) per
    unexplored room or space beyond a door or leading-out frontier (m̄ regions per room)."""
    per_space = max(1.0, regions_per_room) * (1.0 + per_region)
    return checks + regions * (1.0 + per_region) + spaces * per_space


def slack_step_price(p: np.ndarray, steps_left: int | None, base: float,
                     remaining: float) -> float:
    """a_t of (V5): a · max(N_eff / s, min(1, N_rem / s)), s the steps left; ``base`` when
    there is no budget."""
    if not steps_left or steps_left <= 0 or not len(p):
        return base
    return base * max(effective_places(p) / steps_left, min(1.0, remaining / steps_left))


def expected_checks(carriers: Sequence[ObjectNode], c: Sequence[float]) -> float:
    """f̂ of (V3): the mean over revealed places (carriers grouped by parent: a region, or a
    piece holding small carriers) of the expected checks to find a target that is there,
    Σ_j j w_j with w_j the carriers' C' shares in decreasing order; 1 with no carriers."""
    ids = {o.id for o in carriers}
    groups: dict[str, list[float]] = {}
    for o, v in zip(carriers, c, strict=True):
        if o.parent not in ids:
            groups.setdefault(o.parent, []).append(v)
    if not groups:
        return 1.0
    total = 0.0
    for vals in groups.values():
        vals.sort(reverse=True)
        total += sum(j * w for j, w in enumerate(vals, 1)) / sum(vals)
    return total / len(groups)


def share_profile(carriers: Sequence[ObjectNode], c: Sequence[float],
                  longest: int = 32) -> np.ndarray:
    """W̄ of (V4): W̄_k, k = 1.., the share of a revealed place's mass that its k likeliest
    carriers hold (C' shares in decreasing order, summed), averaged over the revealed
    places (carriers grouped by parent, as :func:`expected_checks`); ends at 1, at most
    ``longest`` long; [1] with no carriers."""
    ids = {o.id for o in carriers}
    groups: dict[str, list[float]] = {}
    for o, v in zip(carriers, c, strict=True):
        if o.parent not in ids:
            groups.setdefault(o.parent, []).append(v)
    if not groups:
        return np.ones(1)
    m = min(longest, max(len(g) for g in groups.values()))
    out = [0.0] * m
    for vals in groups.values():
        total, cum = sum(vals), 0.0  # (the sum in graph order)
        vals.sort(reverse=True)
        for k in range(m):
            if k < len(vals):
                cum += vals[k]
                out[k] += cum / total
            else:
                out[k] += 1.0
    prof = np.asarray(out) / len(groups)
    prof[-1] = 1.0
    return prof


def prefix_costs(base: np.ndarray, p: np.ndarray, nxt: np.ndarray, profile: np.ndarray,
                 step: float) -> np.ndarray:
    """c_eff of (V4): p / max_k (p - p^next + p^next W̄_k) / (c + k a_t), k = 0..len(W̄)
    (W̄_0 = 0), the cost at which checking node i alone would be worth its best initial
    segment of reveal and checks; c where p^next = 0 (W̄ ends at 1, so c_eff <= c + K a_t
    for the profile's length K)."""
    out = base.copy()
    rows = np.flatnonzero(nxt > 0)
    if not len(rows):
        return out
    w = np.concatenate(([0.0], profile))
    k = np.arange(len(w), dtype=np.float64)
    now, later = p[rows] - nxt[rows], nxt[rows]
    v = (now[:, None] + later[:, None] * w[None, :]) / (base[rows, None] + k[None, :] * step)
    best = v.max(axis=1)
    out[rows] = np.where(best > 0, p[rows] / np.where(best > 0, best, 1.0), base[rows])
    return out


class VoiPlanner(ScoringPlanner[VoiParams]):
    """Value-of-information search (module doc). ``furniture_levels``: name -> φ of (B6)
    (:mod:`sgtool.planning.furniture_prior`); None: every query is a small object."""

    def __init__(self, scorer: RelationScorer, params: VoiParams = VoiParams(),
                 name: str = "voi", max_failures: int = 2,
                 furniture_levels: Mapping[str, float] | None = None) -> None:
        super().__init__(name, scorer, params, max_failures)
        self.steps = 0
        self.furniture_levels = furniture_levels
        self.belief = EpisodeBelief(scorer, "", params.belief)

    def reset(self, query: str, seed: int = 0) -> None:
        super().reset(query, seed)
        self.steps = 0
        self.belief = EpisodeBelief(self.scorer, query, self.params.belief,
                                    furniture_level(self.furniture_levels, query))

    def choose(self, graph: SceneGraph, cands: list[Candidate]
               ) -> tuple[int, str, dict[str, float]]:
        return self.choose_columns(graph, CandidateColumns.of(cands))

    def choose_columns(self, graph: SceneGraph, cols: CandidateColumns
                       ) -> tuple[int, str, dict[str, float]]:
        fails_of = self.memory.failures
        fails = [len(fails_of.get(i, ())) for i in cols.ids] if fails_of else None
        p, nxt = self.belief.masses(graph, cols.ids, cols.kinds, fails)
        budget = self.params.step_budget
        left = budget - self.steps if budget > 0 else None
        self.steps += 1
        i, value = self.best_first(cols, p, nxt, graph.robot.position, left)
        scores = dict(zip(cols.ids, np.round(p, 4).tolist(), strict=True))
        return i, (f"p={p[i]:.3f}, d={cols.distances[i]:.2f} m, "
                   f"value={value:.4f}"), scores

    def best_first(self, cols: CandidateColumns, p: np.ndarray, nxt: np.ndarray,
                   robot: tuple[float, float], steps_left: int | None) -> tuple[int, float]:
        """Index of the candidate to check first and the value of its ordering, (V2) and
        (S2)."""
        prm = self.params
        if prm.step_rule == "slack":
            step = slack_step_price(p, steps_left, prm.step_cost, self.belief.remaining)
        else:
            step = step_price(p, steps_left, prm.step_cost)
        opens = np.fromiter((s == "open" for s in cols.skills), dtype=bool, count=len(cols))
        share = np.divide(nxt, p, out=np.zeros_like(p), where=p > 0)
        dist = np.asarray(cols.distances, dtype=np.float64)
        if prm.follow_steps is None and prm.follow_rule == "prefix":
            base = dist + step + prm.open_cost * opens
            first = prefix_costs(base, p, nxt, self.belief.profile, step)
            extra = first - dist
        else:
            follow = self.belief.follow if prm.follow_steps is None else prm.follow_steps
            extra = step + prm.open_cost * opens + follow * step * share
            first = dist + extra
        ratio = p / first
        keys = cols.ids  # ties: node ids as strings, as (S2) of bayes-search
        k_top = max(1, prm.top_k)
        pool: Sequence[int] = range(len(cols))
        if len(cols) > k_top:  # only the places at or above the k-th best ratio can rank
            kth = np.partition(ratio, len(cols) - k_top)[len(cols) - k_top]
            pool = np.flatnonzero(ratio >= kth).tolist()
        top = sorted(pool, key=lambda k: (-ratio[k], keys[k]))[:k_top]
        h = min(prm.horizon, len(top))
        if h <= 1:
            return top[0], float(ratio[top[0]])
        xy = np.asarray(cols.positions, dtype=np.float64)
        rho = _detour(xy, dist, robot)
        sub = xy[top]
        legs_top = rho * np.hypot(sub[:, None, 0] - sub[None, :, 0],
                                  sub[:, None, 1] - sub[None, :, 1]) + extra[top][None, :]
        orders = _orderings(len(top), h)
        v = sequence_values(orders, p[top], first[top], legs_top)
        best = v.max()
        ties = np.flatnonzero(v == best)
        k = min(ties, key=lambda t: tuple(keys[top[j]] for j in orders[t]))
        return int(top[orders[k, 0]]), float(v[k])


def _detour(xy: np.ndarray, dist: np.ndarray, robot: tuple[float, float]) -> float:
    """ρ of (S2): median travel / straight-line distance, clipped to [1, 3]."""
    e = np.hypot(xy[:, 0] - robot[0], xy[:, 1] - robot[1])
    far = e > 0.5
    if not far.any():
        return 1.0
    r = dist[far] / e[far]
    n = len(r)
    mid = np.partition(r, [(n - 1) // 2, n // 2])  # the median, as np.median
    med = mid[n // 2] if n % 2 else 0.5 * (mid[n // 2 - 1] + mid[n // 2])
    return float(np.clip(med, 1.0, 3.0))


__all__ = ["REVEAL_KINDS", "EpisodeBelief", "VoiParams", "VoiPlanner", "voi_belief"]
