"""Canonical numbers: the one rounding of every float that is digested or compared as text.

Scene graphs, house specs and benchmark results are written as canonical JSON and pinned by
sha256 digests (golden logs, results digests). Their floats keep :data:`DECIMALS` decimals
(0.1 mm for metres, 1e-4 for scores), with ``-0.0`` written as ``0.0`` so that a value that
rounds to zero from below digests like one from above. :func:`strict_json` turns NaN into
``None`` for strict JSON output.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any

DECIMALS = 4


def canonical_float(x: float) -> float:
    """``x`` rounded to :data:`DECIMALS` decimals, never ``-0.0``."""
    v = round(float(x), DECIMALS)
    return 0.0 if v == 0 else v


def canonical_floats(xs: Iterable[float]) -> list[float]:
    return [canonical_float(x) for x in xs]


def strict_json(x: Any) -> Any:
    """NaN -> None, recursively through dicts, lists and tuples (for ``allow_nan=False``)."""
    if isinstance(x, float):
        return None if math.isnan(x) else x
    if isinstance(x, dict):
        return {k: strict_json(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [strict_json(v) for v in x]
    return x
