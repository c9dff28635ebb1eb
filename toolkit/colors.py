"""One palette for every view: a stable colour per id or name.

The derived log layers (Foxglove ``SceneUpdate``), the voxel snapshots and the Rerun export
all colour a room, an object or an instance id with :func:`color_for`, so the same room has
the same colour wherever it is drawn.
"""

from __future__ import annotations

import colorsys
import hashlib


def color_for(
    key: int | str, saturation: float = 0.65, value: float = 0.95
) -> tuple[int, int, int]:
    """A stable, well-spread colour for an id or name (golden-ratio hue steps)."""
    if isinstance(key, str):
        key = int.from_bytes(hashlib.blake2s(key.encode(), digest_size=4).digest(), "little")
    h = (int(key) * 0.618033988749895) % 1.0
    r, g, b = colorsys.hsv_to_rgb(h, saturation, value)
    return int(r * 255), int(g * 255), int(b * 255)
