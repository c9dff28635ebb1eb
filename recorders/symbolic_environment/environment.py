"""One SymSearch episode in a :class:`~sgtool.recorders.symbolic_environment.house.SymbolicHouse`.

**Roll-out** (SCOUT V.C, Fig. 4), :class:`SymbolicEnv`:

- start: a random region of a random room (rooms holding a target are avoided when others
  exist; only regions from which a target can be reached, so a walled-off room is no
  start for a target outside it, nor the house outside it for a target in it), drawn
  from the episode seed; the start room is explored: the agent sees the
  start region with its furniture, the room's other regions as frontiers ("unexplored
  area"), its doors, and the rooms behind its open doors and passages as unexplored rooms
  (``RoomNode(explored=False, category="unknown")``);
- ``explore`` (or ``navigate``) an unexplored room: the agent walks to the room's region
  nearest to it, which is revealed with its furniture; the room's other regions become
  frontiers; its doors and the rooms behind open doors/passages appear;
- ``explore`` (or ``navigate``) a frontier: the agent walks there; the region's furniture
  is revealed;
- walking up to a piece of furniture (``navigate`` to it or to an object on it,
  ``explore``, ``open``) reveals what is on its top face, even when it is closed; what is
  *enclosed* by it (``inside``, or ``ontop`` of a lower shelf:
  :func:`sgtool.house.spec.enclosed`) is revealed only when it is not closed: ``open`` a
  closed openable piece (walk there, open it, reveal its contents), or ``navigate`` to /
  ``explore`` a container/supporter that is not closed (look into / onto it);
- nesting (house spec 2): what is revealed is looked at in turn, by the same rule: the
  things on top of a revealed object are revealed with it, and its contents too unless
  it is closed; so nested containers open one at a time (a bowl inside a closed cabinet
  appears when the cabinet is opened, with the apple in it; an apple inside a closed
  lidded box inside the cabinet needs the box opened too: ``open`` an openable small
  object walks to its furniture and opens it); revealed objects stay revealed;
- ``open`` a closed door: walk to it and open it; the room beyond appears as an unexplored
  room. ``close`` closes an open object or door; ``navigate`` to anything else just walks;
- ``done``: ends the episode.

An action whose target is not a node of the observed graph (or is None, for anything but
``done``), or whose skill does not apply to that kind of node (open a room), is
**invalid**: a step is spent, nothing happens, feedback outcome "invalid". An action that
applies but has no effect (open an open fridge, a target that cannot be reached) is a
**failure**, also a spent step.

**End and success** (SCOUT V.C): the episode ends as soon as an object of the query
category is visible (success, even without ``done``: SymSearch terminates "when the target
object becomes visible"), on ``done`` (failure, since the target was not visible), or
after ``max_steps`` actions (failure; SymSearch's N_max = 50). Success therefore never
depends on a planner calling ``done``; MoMa-LLM's stricter rule (success only on an
explicit ``done()``) belongs to the closed loop.

Everything is deterministic: the start comes from ``numpy.random.default_rng`` seeded with
(seed, house seed, episode index); iteration is in id order.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import ClassVar, Literal

import numpy as np

from sgtool.planning.base import Action, Feedback, Outcome
from sgtool.recorders.symbolic_environment.house import SymbolicHouse, spec_state
from sgtool.recorders.symbolic_environment.observation import ObservedGraph
from sgtool.scenegraph.graph import SceneGraph
from sgtool.semantics.text import category_text

N_MAX = 50  # SymSearch's maximum episode length (SCOUT sec. VI / appendix C)

NodeKind = Literal["room", "region", "door", "furniture", "object"]
# a skill on one kind of node: (env, action, the node's index, distances) -> outcome
Handler = Callable[["SymbolicEnv", Action, int, np.ndarray], "StepOutcome"]


@dataclass(frozen=True)
class StepOutcome:
    """What one action did (besides the feedback the planner gets)."""

    feedback: Feedback
    opened: bool = False  # a successful open interaction (MoMa-LLM's open cost)


class SymbolicEnv:
    """One SymSearch episode in a :class:`SymbolicHouse` (rules in the module doc)."""

    def __init__(self, house: SymbolicHouse, query: str, seed: int = 0, episode_index: int = 0,
                 avoid_rooms: Sequence[str] = (), max_steps: int = N_MAX,
                 start_region: str | None = None):
        self.house = house
        self.spec = house.spec
        self.query = query
        self._query_text = category_text(query)
        self._target_furn = {i for i, c in enumerate(house.furn_cat) if c == self._query_text}
        self._target_obj = {j for j, c in enumerate(house.obj_cat) if c == self._query_text}
        self.max_steps = int(max_steps)
        self.steps = 0
        self.travelled = 0.0
        self.n_open = 0
        self.n_invalid = 0
        self.n_failure = 0
        self.ended = False
        self.success = False
        self.end_reason = ""
        # dynamic state
        self.open_doors: set[int] = set(house.initially_open())
        self.furn_state = [spec_state(f.state) for f in self.spec.furniture]
        self.obj_state = [spec_state(o.state) for o in self.spec.objects]
        self.furn_explored: set[int] = set()  # contents revealed (looked at, not closed)
        self.obj_explored: set[int] = set()
        self.seen_objects: set[int] = set()
        self.revealed_regions: set[int] = set()
        self.explored_rooms: set[int] = set()
        self.known_rooms: set[int] = set()
        self.visible_doors: set[int] = set()
        self._visible_furn: set[int] = set()  # furniture of the revealed regions
        self._view = ObservedGraph(self)  # told of every change below
        # start: a random region of a random room (SCOUT V.C)
        if start_region is not None:
            reg = next(i for i, r in enumerate(house.regions) if r.id == start_region)
        else:
            rng = np.random.default_rng([int(seed), int(self.spec.seed), int(episode_index)])
            avoid = {house.room_index[r] for r in avoid_rooms if r in house.room_index}
            starts = self._start_regions()
            ok = [ri for ri, regs in enumerate(starts) if regs] or \
                list(range(len(self.spec.rooms)))
            rooms = [ri for ri in ok if ri not in avoid] or ok
            ri = rooms[int(rng.integers(len(rooms)))]
            regs = starts[ri] or house.room_regions[ri]
            reg = regs[int(rng.integers(len(regs)))]
        self.start_region = house.regions[reg].id
        self.place = house.regions[reg].place
        self.start_place = self.place
        self._enter_room(house.regions[reg].room, reg)
        self._check_found()
        if self.success:
            self.end_reason = "found"

    def _start_regions(self) -> list[tuple[int, ...]]:
        """Per room, its regions from which a target can be reached with every door open
        (all of them in a house without walled-off rooms; none for a query the house
        lacks)."""
        h = self.house
        comp = h.place_component
        goal = {int(comp[h.furn_place[f]]) for f in self._target_furn}
        goal |= {int(comp[h.obj_place[j]]) for j in self._target_obj}
        return [tuple(k for k in regs if int(comp[h.regions[k].place]) in goal)
                for regs in h.room_regions]

    # ----- visibility -----------------------------------------------------------------
    def _enter_room(self, ri: int, region: int) -> None:
        self.explored_rooms.add(ri)
        self.known_rooms.add(ri)
        self._view.rooms_changed()
        self._view.doors_changed()
        self._reveal_region(region)
        for other, door in self.house.links[ri]:
            if door is not None:
                self.visible_doors.add(door)
                if door in self.open_doors:
                    self.known_rooms.add(other)
            else:
                self.known_rooms.add(other)

    def _reveal_region(self, region: int) -> None:
        self.revealed_regions.add(region)
        self._view.regions_changed(self.house.regions[region].room)
        for f in self.house.regions[region].furniture:
            self._visible_furn.add(f)
            self._view.show_furniture(f)

    def _look(self, f: int) -> list[int]:
        """Walk-up view of furniture ``f``: reveal what is on it, and what is in it when it
        is not closed, then what is on / in each revealed object by the same rule (module
        doc). Returns the newly revealed objects."""
        h = self.house
        closed = self.furn_state[f] == "closed"
        if not closed and h.explorable[f]:
            self.furn_explored.add(f)
        self._view.show_furniture(f)
        new: list[int] = []
        stack = [j for j in reversed(h.nested[f]) if not (closed and h.enclosed[j])]
        while stack:
            j = stack.pop()
            if j not in self.seen_objects:
                self.seen_objects.add(j)
                new.append(j)
            shut = self.obj_state[j] == "closed"
            if not shut:
                self.obj_explored.add(j)
            self._view.show_object(j)
            stack.extend(c for c in reversed(h.obj_children[j]) if not (shut and h.enclosed[c]))
        return new

    def _found(self, new: list[int]) -> str:
        names = sorted(self.house.obj_cat[j] for j in new)
        return f"found {', '.join(names)}" if names else "nothing inside or on top"

    def _check_found(self) -> None:
        if not (self._target_furn.isdisjoint(self._visible_furn) and
                self._target_obj.isdisjoint(self.seen_objects)):
            self.success = True
            self.ended = True

    # ----- observation ----------------------------------------------------------------
    def _distances(self) -> np.ndarray:
        return self.house.distances_from(self.place, frozenset(self.open_doors))

    def _room_place(self, ri: int, dist: np.ndarray) -> int:
        regs = self.house.room_regions[ri]
        return min((self.house.regions[r].place for r in regs), key=lambda p: (dist[p], p))

    def _door_place(self, di: int, dist: np.ndarray) -> int:
        a, b = self.house.door_sides[di]
        return a if (dist[a], a) <= (dist[b], b) else b

    def observe(self) -> SceneGraph:
        """The observed subgraph with travel distances from the agent (finite ones only),
        kept up to date with each step's changes
        (:class:`~sgtool.recorders.symbolic_environment.observation.ObservedGraph`)."""
        return self._view.graph(self._distances())

    # ----- acting ---------------------------------------------------------------------
    def _lookup(self, node_id: str | None) -> tuple[NodeKind, int] | None:
        """(kind, index) of an observed node, None when it is not in the observed graph."""
        if not node_id:
            return None
        prefix, _, number = node_id.partition(":")
        try:
            if prefix == "room":
                room = int(number)
                return ("room", room) if room in self.known_rooms else None
            if prefix == "region":
                region = self.house.region_index.get(node_id)
                if region is None or self.house.regions[region].room not in self.explored_rooms:
                    return None
                return "region", region
            if prefix == "door":
                door = int(number)
                return ("door", door) if door in self.visible_doors else None
            if prefix == "obj":  # obj:1.. are the furniture, then the small objects
                furniture = int(number) - 1
                n_furniture = len(self.spec.furniture)
                if 0 <= furniture < n_furniture:
                    return ("furniture", furniture) if furniture in self._visible_furn else None
                obj = furniture - n_furniture
                if 0 <= obj < len(self.spec.objects):
                    return ("object", obj) if obj in self.seen_objects else None
        except ValueError:
            return None
        return None

    def _move(self, place: int, dist: np.ndarray) -> float:
        d = float(dist[place])
        self.travelled += d
        self.place = place
        return d

    def step(self, action: Action) -> StepOutcome:
        """Execute ``action``; a step is spent whatever the outcome."""
        if self.ended:
            raise RuntimeError("the episode has ended")
        self.steps += 1
        out = self._execute(action)
        if out.feedback.outcome == "invalid":
            self.n_invalid += 1
        elif out.feedback.outcome == "failure":
            self.n_failure += 1
        if out.opened:
            self.n_open += 1
        if not self.ended:
            self._check_found()
            if self.success:
                self.end_reason = "found"
            elif self.steps >= self.max_steps:
                self.ended = True
                self.end_reason = "max_steps"
        return out

    def execute(self, action: Action) -> Feedback:
        """:meth:`step` as a :class:`~sgtool.planning.episode.SearchEnvironment`: the
        feedback only."""
        return self.step(action).feedback

    def _outcome(self, action: Action, outcome: Outcome, message: str, travelled: float = 0.0,
            opened: bool = False) -> StepOutcome:
        return StepOutcome(Feedback(action, outcome, message, travelled), opened)

    def _execute(self, action: Action) -> StepOutcome:
        """The action's effect: ``done`` ends the episode; any other skill goes to the
        handler of its target's node kind (:data:`_HANDLERS`), or is invalid when the
        target is not an observed node."""
        if action.skill == "done":
            self.ended = True
            self.end_reason = "gave_up" if action.target is None else "wrong_done"
            return self._outcome(action, "success", "episode ended by the planner")
        found = self._lookup(action.target)
        if found is None:
            return self._outcome(action, "invalid",
                                 f"{action.target!r} is not a node of the observed graph")
        node_kind, index = found
        return self._HANDLERS[node_kind](self, action, index, self._distances())

    def _unreachable(self, action: Action) -> StepOutcome:
        return self._outcome(action, "failure", f"{action.target} cannot be reached")

    def _act_on_room(self, action: Action, room: int, distances: np.ndarray) -> StepOutcome:
        """Walk to the room's nearest region; an unexplored room is entered (explored)."""
        house, skill = self.house, action.skill
        if skill in ("open", "close"):
            return self._outcome(action, "invalid", f"cannot {skill} a room")
        place = self._room_place(room, distances)
        if not math.isfinite(distances[place]):
            return self._unreachable(action)
        if room in self.explored_rooms:
            if skill == "explore":
                return self._outcome(action, "failure", f"{action.target} is already explored")
            return self._outcome(action, "success", f"at {action.target}",
                                 self._move(place, distances))
        region = next(r for r in house.room_regions[room] if house.regions[r].place == place)
        travelled = self._move(place, distances)
        self._enter_room(room, region)
        in_view = len(house.regions[region].furniture)
        return self._outcome(action, "success",
                             f"entered {house.room_names[room]}: {in_view} objects in view",
                             travelled)

    def _act_on_region(self, action: Action, index: int, distances: np.ndarray
                       ) -> StepOutcome:
        """Walk to a region; a frontier is revealed with its furniture."""
        region, skill = self.house.regions[index], action.skill
        if skill in ("open", "close"):
            return self._outcome(action, "invalid", f"cannot {skill} a region")
        if not math.isfinite(distances[region.place]):
            return self._unreachable(action)
        if index in self.revealed_regions:
            if skill == "explore":
                return self._outcome(action, "failure", f"{action.target} is already explored")
            return self._outcome(action, "success", f"at {action.target}",
                                 self._move(region.place, distances))
        travelled = self._move(region.place, distances)
        self._reveal_region(index)
        return self._outcome(action, "success", f"{len(region.furniture)} objects in view",
                             travelled)

    def _act_on_door(self, action: Action, door: int, distances: np.ndarray) -> StepOutcome:
        """Walk to the door's nearer side; open it (the rooms behind become known) or close
        it; any skill but explore, navigate and open closes."""
        place = self._door_place(door, distances)
        if not math.isfinite(distances[place]):
            return self._unreachable(action)
        skill, is_open = action.skill, door in self.open_doors
        if skill == "explore":
            return self._outcome(action, "invalid", "cannot explore a door; open it")
        if skill == "navigate":
            return self._outcome(action, "success", f"at {action.target}",
                                 self._move(place, distances))
        if skill == "open":
            if is_open:
                return self._outcome(action, "failure", f"{action.target} is already open")
            travelled = self._move(place, distances)
            self.open_doors.add(door)
            for room_id in self.spec.doors[door].rooms:
                self.known_rooms.add(self.house.room_index[room_id])
            self._view.rooms_changed()
            self._view.doors_changed()
            return self._outcome(action, "success", "door opened", travelled, opened=True)
        if not is_open:
            return self._outcome(action, "failure", f"{action.target} is already closed")
        travelled = self._move(place, distances)
        self.open_doors.discard(door)
        self._view.doors_changed()
        return self._outcome(action, "success", "door closed", travelled)

    def _act_on_furniture(self, action: Action, furniture: int, distances: np.ndarray
                          ) -> StepOutcome:
        """Open or close a piece (explore on a closed piece opens it), or walk up to it and
        look into / onto it (module doc)."""
        piece, place = self.spec.furniture[furniture], self.house.furn_place[furniture]
        if not math.isfinite(distances[place]):
            return self._unreachable(action)
        skill, state = action.skill, self.furn_state[furniture]
        if skill == "open" or (skill == "explore" and state == "closed"):
            if not piece.is_openable:
                return self._outcome(action, "failure", f"a {piece.category} cannot be opened")
            if state == "open":
                return self._outcome(action, "failure", f"the {piece.category} is already open")
            travelled = self._move(place, distances)
            self.furn_state[furniture] = "open"
            return self._outcome(action, "success", self._found(self._look(furniture)),
                                 travelled, opened=True)
        if skill == "close":
            if state != "open":
                return self._outcome(action, "failure", f"the {piece.category} is not open")
            travelled = self._move(place, distances)
            self.furn_state[furniture] = "closed"
            self._view.show_furniture(furniture)
            return self._outcome(action, "success", f"{piece.category} closed", travelled)
        # navigate / explore: walk up; look into / onto a piece that is not closed, onto
        # the top of a closed one
        fresh = (self.house.explorable[furniture] and furniture not in self.furn_explored
                 and state != "closed")
        if skill == "explore" and not fresh:
            return self._outcome(action, "failure",
                                 f"nothing left to explore at the {piece.category}")
        travelled = self._move(place, distances)
        revealed = self._look(furniture)
        if fresh:
            return self._outcome(action, "success", self._found(revealed), travelled)
        if revealed:
            return self._outcome(action, "success",
                                 f"at the {piece.category}; {self._found(revealed)}", travelled)
        return self._outcome(action, "success", f"at the {piece.category}", travelled)

    def _act_on_object(self, action: Action, index: int, distances: np.ndarray
                       ) -> StepOutcome:
        """A skill on a revealed small object: the agent walks to its furniture (and looks
        at it); only an openable object can be opened or closed, only a container
        explored."""
        obj, furniture = self.spec.objects[index], self.house.obj_furn[index]
        place = self.house.furn_place[furniture]
        skill, state = action.skill, self.obj_state[index]
        opens = skill == "open" or (skill == "explore" and state == "closed")
        applies = skill == "navigate" or (obj.is_openable and (opens or skill == "close")) or \
            (skill == "explore" and obj.is_container)
        if not applies:
            return self._outcome(action, "invalid", f"cannot {skill} a {obj.category}")
        if not math.isfinite(distances[place]):
            return self._unreachable(action)
        if opens and state == "open":
            return self._outcome(action, "failure", f"the {obj.category} is already open")
        if skill == "close" and state != "open":
            return self._outcome(action, "failure", f"the {obj.category} is not open")
        if skill == "explore" and not opens and index in self.obj_explored:
            return self._outcome(action, "failure",
                                 f"nothing left to explore at the {obj.category}")
        travelled = self._move(place, distances)
        if skill == "close":
            self.obj_state[index] = "closed"
            self._view.show_object(index)
            return self._outcome(action, "success", f"{obj.category} closed", travelled)
        if opens:
            self.obj_state[index] = "open"
            self._view.show_object(index)
        revealed = self._look(furniture)
        if opens or skill == "explore":
            return self._outcome(action, "success", self._found(revealed), travelled,
                                 opened=opens)
        if revealed:
            return self._outcome(action, "success", f"at {action.target}; "
                                 f"{self._found(revealed)}", travelled)
        return self._outcome(action, "success", f"at {action.target}", travelled)

    # the handler of each kind of node an action can target (:meth:`_lookup`'s kinds)
    _HANDLERS: ClassVar[Mapping[NodeKind, Handler]] = {
        "room": _act_on_room, "region": _act_on_region, "door": _act_on_door,
        "furniture": _act_on_furniture, "object": _act_on_object,
    }

    # ----- figures --------------------------------------------------------------------
    def shortest_path(self, targets: Sequence[str]) -> float | None:
        """Geodesic from the start to the nearest place a target is seen from, every door
        passable (an optimal agent opens the doors on its way); None when unreachable.
        The furniture of the query category counts as targets too, since finding one ends
        the episode as found."""
        h = self.house
        dist = h.distances_from(self.start_place, h.all_doors())
        best = math.inf
        furniture = {h.furn_index[t] for t in targets if t in h.furn_index} | self._target_furn
        for t in targets:
            if t in h.obj_index:
                best = min(best, float(dist[h.furn_place[h.obj_furn[h.obj_index[t]]]]))
        for f in furniture:
            best = min(best, float(dist[h.regions[h.region_of_furn[f]].place]),
                       float(dist[h.furn_place[f]]))
        return best if math.isfinite(best) else None

