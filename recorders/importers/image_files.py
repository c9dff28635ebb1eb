"""The image files of an RGB-D folder: in frame order, the depth images among them, and
the name a colour image pairs with a depth image by."""

from __future__ import annotations

import re
from collections import Counter
from decimal import Decimal
from pathlib import Path

from sgtool.errors import SgtoolError

IMAGE_EXT = (".png", ".jpg", ".jpeg", ".ppm", ".bmp", ".tif", ".tiff")
_NUMBER = re.compile(r"(\d+(?:\.\d+)?)")  # digits, with a fraction after one dot


def natural_key(name: str) -> tuple[tuple[int, Decimal | str], ...]:
    """Sort key of a file name by its numbers' values: "2.png" before "10.png", as Open3D's
    ``sorted_alphanum``; a number with a fraction ("1305031103.05.png", a time stamp) is
    one decimal number, so "X.05" comes before "X.1" as in time (``sorted_alphanum`` would
    compare 5 with 1)."""
    return tuple((0, Decimal(t)) if _NUMBER.fullmatch(t) else (1, t)
                 for t in _NUMBER.split(name) if t)


def images(folder: Path) -> list[Path]:
    """The image files of ``folder`` in natural order (names numbered without zero padding
    sort by value); names whose numbers tie ("1.png" and "01.png", "2.5.png" and "2.50.png")
    are an error."""
    found = sorted((p for p in folder.iterdir() if p.suffix.lower() in IMAGE_EXT
                    and not p.name.startswith(".")),  # hidden (macOS "._0001.png")
                   key=lambda p: (natural_key(p.name), p.name))
    for a, b in zip(found, found[1:], strict=False):
        if natural_key(a.name) == natural_key(b.name):
            raise SgtoolError(f"{folder}: {a.name} and {b.name} have the same number; the "
                              "frame order is ambiguous (keep one naming)")
    return found


def depth_images(folder: Path, notes: list[str]) -> list[Path]:
    """The depth images of ``folder``: those of its most common lossless image type (JPEG
    never holds depth: previews beside PNG depth are no frames, however many), the others
    left out with a note; .tif/.tiff and .jpg/.jpeg are one type."""
    found = images(folder)

    def kind(p: Path) -> str:
        s = p.suffix.lower()
        return {".tiff": ".tif", ".jpeg": ".jpg"}.get(s, s)

    kinds = Counter(kind(p) for p in found)
    if len(kinds) < 2:
        return found
    main = max(sorted(kinds), key=lambda k: (k != ".jpg", kinds[k]))
    stray = [p for p in found if kind(p) != main]
    notes.append(f"{len(stray)} file(s) in {folder.name}/ are not {main} images as the "
                 f"{kinds[main]} depth images are, and were left out (first: {stray[0].name})")
    return [p for p in found if kind(p) == main]


def pair_name(p: Path) -> str:
    """The name an image pairs by: its stem, a number without its zero padding ("00007.jpg"
    pairs with "7.png", as ``pose/000007.txt`` poses it)."""
    return str(int(p.stem)) if p.stem.isascii() and p.stem.isdigit() else p.stem


def frame_slots(names: list[Path], every: list[Path]) -> dict[Path, float] | None:
    """Each of ``names``' frame slot, its time in frame periods from the first image of
    ``every`` (all images of the folder, colour or depth), when every name is a plain
    number: ``(n - first) / step``, ``step`` the most common gap between consecutive
    numbers (a folder of every fifth frame is 1/fps apart, as a dense one). A frame left out
    of the numbering (no image of any kind) or without depth thus keeps the frames after it
    at their times. None when some name is not a plain number (frames then sit at their
    position in the list)."""
    numbers = sorted({int(p.stem) for p in every if p.stem.isascii() and p.stem.isdigit()})
    if not names or len(numbers) != len({pair_name(p) for p in every}):
        return None
    gaps = Counter(b - a for a, b in zip(numbers, numbers[1:], strict=False))
    step = min(gaps, key=lambda g: (-gaps[g], g)) if gaps else 1
    if any((n - numbers[0]) % step for n in numbers):  # time stamps, not frame numbers
        return None
    return {p: (int(p.stem) - numbers[0]) / step for p in names}
