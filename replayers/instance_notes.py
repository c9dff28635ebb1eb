"""What a replay says of a log's instance ids and table when they cannot give semantics.

Semantics come from instance ids through the log's instance table (``/sgtool/instances``,
:mod:`sgtool.scenegraph.instances`): an id the table does not hold is ignored, and rooms
are cut only at instances of kind ``door``. A log written by other software can miss
either without any other sign (a map of one room, fewer objects, exit 0), so
:func:`instance_notes` says it, one line each.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from sgtool.scenegraph.instances import InstanceInfo

SHOWN = 5  # ids named in a note


def instance_notes(seen_ids: np.ndarray, table: Mapping[int, InstanceInfo],
                   rooms: int) -> list[str]:
    """Lines for the ids ``seen_ids`` in the images (0 and negative ids are "none") that
    the instance ``table`` lacks, and for a table without a door when the graph ended
    with at most one room (``rooms``; an open-plan house of several is no surprise)."""
    ids = sorted({int(i) for i in np.asarray(seen_ids).tolist() if int(i) > 0})
    if not ids:
        return []
    if not table:
        return [f"the images hold {len(ids)} instance ids but the log has no instance table "
                "(/sgtool/instances): they are ignored, so the graph has no objects, doors "
                "or room categories"]
    out = []
    missing = [i for i in ids if i not in table]
    if missing:
        shown = ", ".join(str(i) for i in missing[:SHOWN])
        more = f", ... ({len(missing)} in all)" if len(missing) > SHOWN else ""
        out.append(f"{len(missing)} of {len(ids)} instance ids in the images have no entry in "
                   f"the instance table and are ignored: {shown}{more}")
    if rooms <= 1 and not any(v.kind == "door" for v in table.values()):
        out.append("one room: the instance table names no door (kind 'door'), and rooms are "
                   "cut at doors only, so floor joined through doorways is one room")
    return out
