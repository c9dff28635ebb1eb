"""Many Foxglove primitives of one kind as protobuf wire bytes, built with numpy.

Building a ``Point3`` or a ``SpherePrimitive`` message per Voronoi node through the
protobuf API costs microseconds each in Python; a refresh draws hundreds. The records
here are fixed-size (every double written, tags and lengths constant), so they are one
byte template filled column by column. The caller parses them into its message
(``MergeFromString``): equal field values make an equal message, whose serialisation is
then the same bytes as that of the message built field by field (a 0.0 written here
reads back as the unset default).

A layout is a list of parts: ``bytes`` (constant) or a ``str`` (the name of a float64
column, 8 bytes little-endian).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

Layout = list[bytes | str]


def _size(layout: Layout) -> int:
    return sum(8 if isinstance(p, str) else len(p) for p in layout)


def field(number: int, layout: Layout) -> Layout:
    """A length-delimited field (a sub-message) holding ``layout`` (shorter than 128)."""
    n = _size(layout)
    if number >= 16 or n >= 128:  # one-byte tag and length only
        raise ValueError(f"field {number} of {n} bytes needs a longer header")
    return [bytes([(number << 3) | 2, n]), *layout]


def doubles(names: Sequence[str]) -> Layout:
    """Double fields 1, 2, ... named ``names`` (Point3, Vector3, Color, ...)."""
    out: Layout = []
    for i, name in enumerate(names):
        out += [bytes([((i + 1) << 3) | 1]), name]
    return out


POINT3 = doubles(("x", "y", "z"))
COLOR = doubles(("r", "g", "b", "a"))


def records(layout: Layout, columns: Mapping[str, np.ndarray | float], n: int) -> bytes:
    """``n`` records of ``layout`` back to back, each slot from its column (an array of
    ``n`` values or one value for all)."""
    size = _size(layout)
    out = np.empty((n, size), dtype=np.uint8)
    off = 0
    for p in layout:
        if isinstance(p, str):
            col = np.asarray(columns[p], dtype="<f8")
            out[:, off:off + 8] = np.broadcast_to(col, (n,)).reshape(n, 1).view(np.uint8)
            off += 8
        else:
            out[:, off:off + len(p)] = np.frombuffer(p, dtype=np.uint8)
            off += len(p)
    return out.tobytes()
