"""The input files of a batch command: files, folders and glob patterns, in a stable order.

``sgtool replay LOG... --out-dir DIR`` and ``sgtool eval`` take many logs at once. Each
argument is a file (kept as given), a folder (its files with one of the wanted suffixes,
sorted by name; with ``recursive``, as ``sgtool eval`` reads the ``PLANNER/HOUSE/`` folders
that ``bench --log-dir`` and ``run-bench`` write, those of its subfolders too, sorted by
path, hidden folders left out) or a glob pattern (``runs/*/log.mcap``, quoted so that the
shell leaves it alone; ``**`` matches any depth of folders, as in a shell with globstar;
matches sorted). Writers' partial files (``*.partial``) are never
inputs. A file named twice is kept once, at its first place.
"""

from __future__ import annotations

import glob
import os
from collections.abc import Sequence
from pathlib import Path

from sgtool.errors import SgtoolError

_GLOB_CHARS = frozenset("*?[")


def expand_inputs(items: Sequence[str | os.PathLike[str]], suffixes: Sequence[str],
                  what: str = "logs", recursive: bool = False) -> list[Path]:
    """Every input file of ``items`` (module doc); an argument that names nothing is one
    line naming it."""
    out: list[Path] = []
    seen: set[Path] = set()
    for item in items:
        text = str(item)
        p = Path(text)
        if p.is_dir():
            found = sorted(f for f in (p.rglob("*") if recursive else p.iterdir())
                           if f.is_file() and f.suffix.lower() in suffixes
                           and not any(part.startswith(".")
                                       for part in f.relative_to(p).parts))
            if not found:
                raise SgtoolError(f"{p}: no {what} there ({' or '.join(suffixes)} files"
                                  f"{', in it or its subfolders' if recursive else ''})")
        elif not p.exists() and _GLOB_CHARS & set(text):
            found = sorted(Path(m) for m in glob.glob(text, recursive=True)
                           if Path(m).is_file())
            found = [f for f in found if not f.name.endswith(".partial")]
            if not found:
                raise SgtoolError(f"{text}: the pattern matches no file")
        elif not p.exists():
            raise SgtoolError(f"{p}: no such file")
        else:
            found = [p]
        for f in found:
            key = f.resolve()
            if key not in seen:
                seen.add(key)
                out.append(f)
    return out
