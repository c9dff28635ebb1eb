"""Checks of the numeric import options shared by the bag and folder importers.

Each check returns the value or raises a one-line :class:`SgtoolError` naming the flag,
the value and what is expected; the importers run them before they read or write
anything, so a bad option leaves no output file.
"""

from __future__ import annotations

import math

from sgtool.errors import SgtoolError


def _is_number(value: float) -> bool:
    try:
        return math.isfinite(float(value))
    except (TypeError, ValueError):
        return False


def _show(value: float) -> str:
    try:
        return f"{float(value):g}"
    except (TypeError, ValueError):
        return repr(value)


def check_positive(value: float, flag: str, unit: str = "") -> float:
    """``value`` if it is a finite number > 0."""
    if not _is_number(value) or float(value) <= 0.0:
        raise SgtoolError(
            f"{flag} {_show(value)}: must be a positive number" + (f" ({unit})" if unit else "")
        )
    return float(value)


def check_non_negative(value: float, flag: str, unit: str = "") -> float:
    """``value`` if it is a finite number >= 0."""
    if not _is_number(value) or float(value) < 0.0:
        raise SgtoolError(
            f"{flag} {_show(value)}: must be zero or a positive number"
            + (f" ({unit})" if unit else "")
        )
    return float(value)


def check_depth_scale(value: float | None) -> float | None:
    """``--depth-scale``: raw 16-bit depth units per metre (None = the source's)."""
    if value is None:
        return None
    if not _is_number(value) or float(value) <= 0.0:
        raise SgtoolError(
            f"--depth-scale {_show(value)}: give the raw depth units per metre, a positive "
            "number (1000 for millimetres, 5000 for TUM RGB-D)"
        )
    return float(value)


def check_counts(every: int, limit: int | None) -> None:
    """``--every`` >= 1 and ``--limit`` >= 1 (or None)."""
    if every < 1:
        raise SgtoolError(f"--every {every}: must be >= 1")
    if limit is not None and limit < 1:
        raise SgtoolError(f"--limit {limit}: must be >= 1")
