"""Validation of the containment tree of small objects: every parent exists, chains end at
furniture within the depth limit (no cycles), "inside" needs a container, an object is in
its furniture's room and where its relation says (:func:`sgtool.house.spec.placement_problem`).

Linear time: each object's chain is walked once, memoised; a chain longer than the limit
is refused as soon as it is (a cycle is a chain that never ends, named as such).
"""

from __future__ import annotations

from collections.abc import Sequence

from sgtool.errors import SpecError
from sgtool.house.spec import Furniture, SmallObject, placement_problem


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
