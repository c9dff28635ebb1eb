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


FPS_RANGE = (0.1, 1000.0)  # frames per second, as `sgtool run` takes them
MAX_FLOOR_M = 10_000.0  # |--floor|: a height in a building's (or a map's) frame
MAX_DT_S = 60.0  # --max-dt: pairing colour with depth
MAX_TF_TOLERANCE_S = 3600.0  # --tf-tolerance
DEPTH_SCALE_RANGE = (1.0, 1e6)  # raw units per metre: metres to micrometres


def check_range(value: float, flag: str, lo: float, hi: float, unit: str = "") -> float:
    """``value`` if it is a finite number within ``lo``..``hi``."""
    if not _is_number(value) or not lo <= float(value) <= hi:
        raise SgtoolError(f"{flag} {_show(value)}: must be a number from {lo:g} to {hi:g}"
                          + (f" ({unit})" if unit else ""))
    return float(value)


def seconds_option_ns(value: float, flag: str, hi: float) -> int:
    """A duration flag in seconds (0..``hi``) -> integer nanoseconds."""
    return int(check_range(value, flag, 0.0, hi, "seconds") * 1e9)


def check_floor(value: float | None) -> float | None:
    """``--floor`` in metres: finite, within +-:data:`MAX_FLOOR_M` (None = auto or none)."""
    if value is None:
        return None
    return check_range(value, "--floor", -MAX_FLOOR_M, MAX_FLOOR_M,
                       "metres along up; or auto, or none")


def check_depth_scale(value: float | None) -> float | None:
    """``--depth-scale``: raw 16-bit depth units per metre (None = the source's)."""
    if value is None:
        return None
    if not _is_number(value) or not DEPTH_SCALE_RANGE[0] <= float(value) <= DEPTH_SCALE_RANGE[1]:
        raise SgtoolError(
            f"--depth-scale {_show(value)}: give the raw depth units per metre, a positive "
            "number (1000 for millimetres, 5000 for TUM RGB-D) from "
            f"{DEPTH_SCALE_RANGE[0]:g} to {DEPTH_SCALE_RANGE[1]:g}"
        )
    return float(value)


def check_counts(every: int, limit: int | None) -> None:
    """``--every`` >= 1 and ``--limit`` >= 1 (or None)."""
    if every < 1:
        raise SgtoolError(f"--every {every}: must be >= 1")
    if limit is not None and limit < 1:
        raise SgtoolError(f"--limit {limit}: must be >= 1")


def check_height_band(band: tuple[float, float]) -> tuple[float, float]:
    """``--camera-height MIN:MAX``: 0 <= MIN < MAX, in metres."""
    lo, hi = band
    if not (_is_number(lo) and _is_number(hi)) or not 0.0 <= float(lo) < float(hi):
        raise SgtoolError(f"--camera-height {_show(lo)}:{_show(hi)}: give MIN:MAX in metres "
                          "with 0 <= MIN < MAX")
    return float(lo), float(hi)


def parse_height_band(text: str) -> tuple[float, float]:
    """``--camera-height`` text ``MIN:MAX`` (metres) -> the checked band."""
    parts = text.replace(",", ":").split(":")
    try:
        if len(parts) != 2:
            raise ValueError
        band = (float(parts[0]), float(parts[1]))
    except ValueError as e:
        raise SgtoolError(f"--camera-height {text!r}: give MIN:MAX in metres, e.g. "
                          "0.45:2.2") from e
    return check_height_band(band)


def check_intrinsics(value: object) -> None:
    """``intrinsics`` set from Python: None or a
    :class:`~sgtool.recorders.importers.textformats.PinholeParams` (a string is a one-line
    error naming the parser, not an AttributeError while frames are read)."""
    from sgtool.recorders.importers.textformats import PinholeParams

    if value is not None and not isinstance(value, PinholeParams):
        raise SgtoolError(f"intrinsics: give a PinholeParams (sgtool.parse_intrinsics reads "
                          f"'fx,fy,cx,cy' or a file), got a {type(value).__name__}")
