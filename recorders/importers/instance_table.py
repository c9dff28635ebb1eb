"""The instance table of an import's id images (``sgtool import bag --ids ... --instances
FILE``): what each instance id stands for, so a replay builds objects, furniture and doors
from the ids instead of geometry only.

The file is the JSON form of an ``sgtool.Instances`` record, the table a simulated
recording logs and ``LogWriter.write_record("instances", ...)`` takes::

    {"instances": [{"id": 1, "category": "chair", "kind": "furniture"},
                   {"id": 2, "category": "door", "kind": "door", "state": "open"},
                   {"id": 3, "category": "mug", "kind": "object", "parent": 4,
                    "relation": "ontop"}]}

``kind`` is one of ``object``, ``furniture``, ``door``, ``structure`` (floor, walls: never
an object of the graph); rooms are cut at ``door`` instances only. The table is checked as
a log reader checks the record (ids in range and given once, every field's type) and
written at the first frame's time.
"""

from __future__ import annotations

import json
from pathlib import Path

from sgtool.errors import LogFormatError, SgtoolError
from sgtool.log.records import Instances


def read_instance_table(path: str | Path, option: str = "--instances") -> Instances:
    """The ``sgtool.Instances`` record in the JSON file ``path`` (module doc); one
    :class:`SgtoolError` line naming ``option``, the file and what is wrong otherwise."""
    where = f"{option} {path}"
    try:
        text = Path(path).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as e:
        raise SgtoolError(f"{where}: cannot read it ({type(e).__name__}: {e})") from None
    try:
        doc = json.loads(text)
    except json.JSONDecodeError as e:
        raise SgtoolError(f"{where}: not JSON ({e})") from None
    if isinstance(doc, list):  # the items alone: the table
        doc = {"instances": doc}
    try:
        table = Instances.from_json(doc, where=where)
    except LogFormatError as e:
        raise SgtoolError(f"{e} (the file is an sgtool.Instances record: "
                          '{"instances": [{"id": 1, "category": "chair", '
                          '"kind": "furniture"}, ...]})') from None
    if not table.instances:
        raise SgtoolError(f"{where}: the table lists no instance")
    return table


def check_instances(table: object, ids: object, give_ids: str) -> None:
    """An import's options from Python: ``table`` (its ``instances``) is None or an
    :class:`Instances` (not a file's path: :func:`read_instance_table` reads one), given
    only with ``ids``; one :class:`SgtoolError` line naming what to give otherwise
    (``give_ids``: the ids option as the importer takes it)."""
    if table is not None and not isinstance(table, Instances):
        raise SgtoolError("instances: an sgtool.Instances (read_instance_table(path) of "
                          "sgtool.recorders.importers.instance_table reads the JSON file), "
                          f"got {type(table).__name__}")
    if table is not None and ids is None:
        raise SgtoolError(f"--instances is the table of the instance ids: give {give_ids}")
