"""Parsing BEHAVIOR-1K activity definitions (``problem0.bddl``): every ``inside``, ``ontop``
and ``inroom`` atom of ``:init`` and ``:goal`` that is not under a ``not`` becomes a record
(instances such as ``apple.n.01_1`` and goal variables ``?apple.n.01`` resolve to their
synset; ``inroom`` of an object's parent chain gives the room type of a relation).
"""

from __future__ import annotations

import re
from collections import Counter, defaultdict
from dataclasses import dataclass
from typing import Any

RELATIONS = ("inside", "ontop")


@dataclass(frozen=True)
class RelationRecord:
    """One ``inside``/``ontop`` atom of one activity. ``room_type`` is where the parent is
    (from ``inroom`` of the parent or of what it rests on/in), None when not stated."""

    activity: str
    child: str
    relation: str
    parent: str
    section: str  # "init" | "goal"
    room_type: str | None


@dataclass(frozen=True)
class InRoomRecord:
    activity: str
    synset: str
    room_type: str

_TOKEN = re.compile(r"\(|\)|[^\s()]+")
_QUANT = {"forall", "exists", "forn", "forpairs", "fornpairs"}


def parse_sexp(text: str) -> list[Any]:
    """A BDDL file as nested lists of strings (comments after ';' dropped)."""
    text = re.sub(r";[^\n]*", "", text)
    stack: list[list[Any]] = [[]]
    for tok in _TOKEN.findall(text):
        if tok == "(":
            stack.append([])
        elif tok == ")":
            if len(stack) < 2:
                raise ValueError("unbalanced ')'")
            x = stack.pop()
            stack[-1].append(x)
        else:
            stack[-1].append(tok)
    if len(stack) != 1 or not stack[0]:
        raise ValueError("unbalanced '('")
    return stack[0][0]


def _section(tree: list[Any], key: str) -> list[Any]:
    for x in tree[1:]:
        if isinstance(x, list) and x and x[0] == key:
            return x[1:]
    return []


def _instance_synset(token: str) -> str:
    return re.sub(r"_\d+$", "", token.lstrip("?"))


def _atoms(expr: Any, out: list[tuple[str, ...]], negated: list[tuple[str, ...]],
           neg: bool = False) -> None:
    """Collect (predicate, args...) atoms of ``expr``; atoms under ``not`` go to
    ``negated``."""
    if not isinstance(expr, list) or not expr or not isinstance(expr[0], str):
        return
    head = expr[0]
    if head == "not":
        for x in expr[1:]:
            _atoms(x, out, negated, not neg)
        return
    if head in ("and", "or", "imply") or head in _QUANT:
        for x in expr[1:]:
            if head in _QUANT and isinstance(x, list) and "-" in x:
                continue  # a variable declaration (?x - synset)
            _atoms(x, out, negated, neg)
        return
    if all(isinstance(a, str) for a in expr[1:]):
        (negated if neg else out).append(tuple(expr))


def parse_activity(name: str, text: str) -> tuple[list[RelationRecord], list[InRoomRecord],
                                                   Counter[str]]:
    """Relations and inroom records of one ``problem0.bddl``, and the counts of negated
    relation atoms (which are not relations that hold)."""
    tree = parse_sexp(text)
    init_atoms: list[tuple[str, ...]] = []
    goal_atoms: list[tuple[str, ...]] = []
    neg: list[tuple[str, ...]] = []
    for a in _section(tree, ":init"):
        _atoms(a, init_atoms, neg)
    for a in _section(tree, ":goal"):
        _atoms(a, goal_atoms, neg)
    # where instances are: inroom, then propagated down inside/ontop chains of :init
    room_of: dict[str, str] = {}
    inroom: list[InRoomRecord] = []
    for a in init_atoms:
        if a[0] == "inroom" and len(a) == 3:
            room_of[a[1]] = a[2]
            inroom.append(InRoomRecord(name, _instance_synset(a[1]), a[2]))
    parent_of = {a[1]: a[2] for a in init_atoms if a[0] in RELATIONS and len(a) == 3}
    for _ in range(8):  # chains are short; a fixed bound also guards against cycles
        changed = False
        for child, parent in parent_of.items():
            if child not in room_of and parent in room_of:
                room_of[child] = room_of[parent]
                changed = True
        if not changed:
            break
    # a goal variable stands for every instance of its synset: its room when they agree
    rooms_by_synset: dict[str, set[str]] = defaultdict(set)
    for inst, room in room_of.items():
        rooms_by_synset[_instance_synset(inst)].add(room)

    def room_for(token: str) -> str | None:
        inst = token.lstrip("?")
        if inst in room_of:
            return room_of[inst]
        rs = rooms_by_synset.get(_instance_synset(token), set())
        return next(iter(rs)) if len(rs) == 1 else None

    rels: list[RelationRecord] = []
    for section, atoms in (("init", init_atoms), ("goal", goal_atoms)):
        for a in atoms:
            if a[0] in RELATIONS and len(a) == 3:
                rels.append(RelationRecord(name, _instance_synset(a[1]), a[0],
                                           _instance_synset(a[2]), section, room_for(a[2])))
    negated = Counter(a[0] for a in neg if a[0] in (*RELATIONS, "inroom"))
    return rels, inroom, negated
