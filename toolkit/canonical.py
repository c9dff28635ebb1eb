"""Canonical numbers: the one rounding of every float that is digested or compared as text.

Scene graphs, house specs and benchmark results are written as canonical JSON and pinned by
sha256 digests (golden logs, results digests). Their floats keep :data:`DECIMALS` decimals
(0.1 mm for metres, 1e-4 for scores), with ``-0.0`` written as ``0.0`` so that a value that
rounds to zero from below digests like one from above. :func:`strict_json` turns NaN and
infinities into ``None`` for strict JSON output; :func:`json_text` is the one way a command
prints JSON.
"""

from __future__ import annotations

import json
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
    """NaN and infinities -> None, recursively through dicts, lists and tuples (for
    ``allow_nan=False``)."""
    if isinstance(x, float):
        return x if math.isfinite(x) else None
    if isinstance(x, dict):
        return {k: strict_json(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [strict_json(v) for v in x]
    return x


def json_text(doc: Any, *, indent: int | None = None, sort_keys: bool = True) -> str:
    """``doc`` as strict JSON text (what ``--json`` prints): NaN and infinities become
    ``null`` (``NaN`` is no JSON; a parser refuses it)."""
    return json.dumps(strict_json(doc), indent=indent, sort_keys=sort_keys, allow_nan=False)
