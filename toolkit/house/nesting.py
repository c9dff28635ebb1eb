"""Validation of the containment tree of small objects: every parent exists, chains end at
furniture within the depth limit (no cycles), "inside" needs a container, an object is in
its furniture's room and where its relation says (:func:`sgtool.house.spec.placement_problem`);
and :func:`with_supporters`, the one completion of a file's affordances.

Linear time: each object's chain is walked once, memoised; a chain longer than the limit
is refused as soon as it is (a cycle is a chain that never ends, named as such).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import TypeVar

from sgtool.errors import SpecError
from sgtool.house.spec import Furniture, SmallObject, placement_problem
from sgtool.semantics.text import category_text

_Piece = TypeVar("_Piece", Furniture, SmallObject)


def with_supporters(furniture: Sequence[Furniture], objects: Sequence[SmallObject]
                    ) -> tuple[tuple[Furniture, ...], tuple[SmallObject, ...]]:
    """The pieces with "supporter" added where a file left it out: when something lies
    "ontop" of a piece that is neither a supporter nor a container, every piece of that
    category (:func:`~sgtool.semantics.text.category_text`; furniture and small objects
    apart) gains the affordance, as a robot knows what a kind of table can hold, not what
    one table holds. Without it nothing on such a piece could ever be found (no one walks
    up to look); by category, so the affordance does not mark the one table that holds
    something. Unknown parents are left to :func:`check_nesting`."""
    furn = {f.id: f for f in furniture}
    objs = {o.id: o for o in objects}
    bare = {"container", "supporter"}.isdisjoint
    lacking: set[tuple[bool, str]] = set()  # (is furniture, category text)
    for o in objects:
        if o.relation != "ontop":
            continue
        parent: Furniture | SmallObject | None = furn.get(o.parent) or objs.get(o.parent)
        if parent is not None and bare(parent.affordances):
            lacking.add((isinstance(parent, Furniture), category_text(parent.category)))
    if not lacking:
        return tuple(furniture), tuple(objects)

    def complete(p: _Piece, is_furniture: bool) -> _Piece:
        if (is_furniture, category_text(p.category)) not in lacking or not bare(p.affordances):
            return p
        return dataclasses.replace(p, affordances=tuple(sorted({*p.affordances, "supporter"})))

    return (tuple(complete(f, True) for f in furniture),
            tuple(complete(o, False) for o in objects))


def check_nesting(furniture: Sequence[Furniture], objects: Sequence[SmallObject],
                  max_depth: int) -> dict[str, int]:
    """Object id -> depth (1: its parent is furniture); raises :class:`SpecError` naming
    ``objects[i].<field>``."""
    furn = {f.id: f for f in furniture}
    index = {o.id: i for i, o in enumerate(objects)}
    depth: dict[str, int] = {}
    root: dict[str, Furniture] = {}
    for o in objects:
        path: list[SmallObject] = []
        on_path: set[str] = set()
        cur = o
        while cur.id not in depth:
            p = cur.parent
            if p in furn:
                depth[cur.id], root[cur.id] = 1, furn[p]
                break
            i = index.get(cur.id)
            if p not in index:
                raise SpecError(f"objects[{i}].parent: {p[:40]!r} is not a furniture or "
                                "object id")
            if p in on_path or p == cur.id:
                raise SpecError(f"objects[{i}].parent: {p!r} makes a cycle (an object "
                                "inside itself)")
            path.append(cur)
            on_path.add(cur.id)
            if len(path) > max_depth:
                raise SpecError(f"objects[{index[o.id]}].parent: nested more than "
                                f"{max_depth} levels deep (the limit)")
            cur = objects[index[p]]
        for c in reversed(path):
            depth[c.id], root[c.id] = depth[c.parent] + 1, root[c.parent]
            if depth[c.id] > max_depth:
                raise SpecError(f"objects[{index[c.id]}].parent: nested more than "
                                f"{max_depth} levels deep (the limit)")
    for i, o in enumerate(objects):
        where = f"objects[{i}]"
        parent = furn.get(o.parent) or objects[index[o.parent]]
        if o.relation == "inside" and not parent.is_container:
            raise SpecError(f"{where}.parent: {o.parent} ({parent.category}) is not a "
                            "container, so nothing can be inside it")
        home = root[o.id]
        if o.room != home.room:
            what = "its parent's" if parent is home else f"its furniture {home.id}'s"
            raise SpecError(f"{where}.room: {o.room!r} differs from {what} room {home.room!r}")
        problem = placement_problem(o, parent, home.yaw)
        if problem:
            raise SpecError(f"{where}.position: {problem}")
    return depth
