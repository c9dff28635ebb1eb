"""What a Rerun recording (``.rrd``) holds, as a digest that two writes of one content share.

Rerun (0.41) gives every row, every chunk and the store's ``SetStoreInfo`` a TUID
(wall-clock nanoseconds and a per-thread random counter), a blueprint store a random id
and its rows a ``log_time``, and writes the chunks flushed together and the columns of the
footer's manifest in an order that changes from run to run (as a randomly seeded hash map's
would); no setting of the SDK fixes them. So two exports of one log (``sgtool view``,
:mod:`sgtool.analysis.rerun_view`) differ under ``cmp``. :func:`content_digest` hashes
what they hold instead; :func:`summarize_rrd` is what ``sgtool info FILE.rrd`` prints.
"""

from __future__ import annotations

import hashlib
import os
import warnings
from pathlib import Path
from typing import Any

from sgtool.errors import SgtoolError

RRD_MAGIC = b"RRF"  # Rerun's file magic ("RRF2" since 0.17), then the encoding version
NOT_CONTENT_TIMELINES = frozenset({"log_time", "log_tick"})  # when it was written, not what


def is_rrd(path: str | os.PathLike[str]) -> bool:
    """Whether ``path`` is a file that starts as a Rerun recording does (a pipe or a
    device is not opened: the open would block)."""
    if not Path(path).is_file():
        return False
    try:
        with open(path, "rb") as f:
            return f.read(3) == RRD_MAGIC
    except OSError:
        return False


def content_digest(rrd_path: str | os.PathLike[str]) -> str:
    """The SHA-256 (hex) of what the Rerun recording ``rrd_path`` holds, the same for two
    exports of one log although their bytes differ (module doc): :func:`summarize_rrd`'s
    ``content_digest``."""
    return str(summarize_rrd(rrd_path)["content_digest"])


def summarize_rrd(rrd_path: str | os.PathLike[str]) -> dict[str, Any]:
    """What the Rerun recording ``rrd_path`` holds: ``path``, ``stores`` (per store, the
    recording's first, then the blueprint's: ``kind``, ``application_id``, ``recording_id``
    (a blueprint's is random: ""), ``entities`` and ``rows``) and ``content_digest``.

    The digest is a SHA-256 over, per store, its kind and ids and every row in the order it
    was logged (its row ids' order; the ids themselves left out), each row as its entity,
    its times on every timeline but ``log_time``/``log_tick``, and each non-null
    component's value (the Arrow IPC of the cell). Chunk ids, how rows are cut into chunks,
    the chunks' order, the SDK's version and the file's footer are left out. A file that is
    no Rerun recording, or one Rerun cannot read, is one :class:`SgtoolError` line."""
    p = Path(rrd_path)
    if not p.is_file():
        raise SgtoolError(f"{p}: no such file")
    if not is_rrd(p):
        raise SgtoolError(f"{p}: not a Rerun recording (it does not start with 'RRF')")
    from sgtool.extras import require

    require("rerun", api="sgtool.analysis.rrd_contents")
    from rerun.chunk import RrdReader

    h = hashlib.sha256()
    try:
        with warnings.catch_warnings():  # a damaged file: Rerun warns, then raises
            warnings.simplefilter("ignore")
            reader = RrdReader(p)
            stores = ([("recording", s) for s in sorted(reader.recordings(),
                                                        key=lambda s: s.recording_id)]
                      + [("blueprint", s) for s in reader.blueprints()])
            described = [_store(h, reader, kind, store) for kind, store in stores]
    except SgtoolError:
        raise
    except Exception as e:  # noqa: BLE001 - Rerun's reader raises its own kinds
        raise SgtoolError(f"{p}: Rerun cannot read it ({str(e).splitlines()[0]})") from None
    return {"path": str(p), "stores": described, "content_digest": h.hexdigest()}


def _store(h: Any, reader: Any, kind: str, store: Any) -> dict[str, Any]:
    """Hash one store into ``h`` (:func:`summarize_rrd`); its summary."""
    rid = store.recording_id if kind == "recording" else ""
    h.update(repr((kind, store.application_id, rid)).encode())
    rows: list[tuple[bytes, bytes]] = []
    entities: set[str] = set()
    for chunk in reader.stream(store=store):
        entities.add(str(chunk.entity_path))
        rows.extend(_chunk_rows(chunk))
    rows.sort()
    for _, digest in rows:
        h.update(digest)
    return {"kind": kind, "application_id": str(store.application_id), "recording_id": rid,
            "entities": len(entities), "rows": len(rows)}


def _chunk_rows(chunk: Any) -> list[tuple[bytes, bytes]]:
    """(row id, digest of the row's entity, times and values) for each row of ``chunk``."""
    import pyarrow as pa

    rb = chunk.to_record_batch()
    row_ids: list[bytes] | None = None
    times: list[tuple[str, list[Any]]] = []
    cells: list[tuple[str, Any, list[bool]]] = []
    for field, col in zip(rb.schema, rb.columns, strict=True):
        what = (field.metadata or {}).get(b"rerun:kind")
        if what == b"control":
            row_ids = col.to_pylist()
        elif what == b"index" and field.name not in NOT_CONTENT_TIMELINES:
            times.append((field.name, col.cast(pa.int64()).to_pylist()))
        elif what == b"data":
            name = (field.metadata or {}).get(b"rerun:component", field.name.encode())
            cells.append((name.decode(), col, col.is_valid().to_pylist()))
    if row_ids is None:
        raise SgtoolError(f"a chunk of {chunk.entity_path} has no row ids")
    times.sort()
    cells.sort(key=lambda c: c[0])
    out = []
    for i, row_id in enumerate(row_ids):
        row = hashlib.sha256(repr((str(chunk.entity_path), [
            (t, v[i]) for t, v in times if v[i] is not None])).encode())
        for name, col, valid in cells:
            if valid[i]:  # a component the row does not log is null in its chunk
                row.update(name.encode() + b"\0" + _cell_bytes(col.slice(i, 1)))
        out.append((bytes(row_id), row.digest()))
    return out


def _cell_bytes(cell: Any) -> bytes:
    """One component cell (a one-row slice of a chunk's column) as bytes that depend on its
    value only, not on where it sat in its chunk: the slice is copied into buffers of its
    own first (the IPC of a slice keeps traces of its offset in the column)."""
    import pyarrow as pa

    cell = pa.concat_arrays([cell])
    sink = pa.BufferOutputStream()
    batch = pa.record_batch([cell], schema=pa.schema([pa.field("v", cell.type)]))
    with pa.ipc.new_stream(sink, batch.schema) as w:
        w.write_batch(batch)
    return bytes(sink.getvalue())


def format_rrd(summary: dict[str, Any]) -> str:
    """:func:`summarize_rrd`'s summary as ``sgtool info`` prints it."""
    lines = [f"{summary['path']}: a Rerun recording"]
    for s in summary["stores"]:
        ids = f", recording {s['recording_id']}" if s["recording_id"] else ""
        lines.append(f"  {s['kind']} (application {s['application_id']}{ids}): "
                     f"{s['rows']} rows over {s['entities']} entities")
    lines.append(f"  content digest {summary['content_digest']} (the same for two exports "
                 "of one log; their bytes differ)")
    return "\n".join(lines)
