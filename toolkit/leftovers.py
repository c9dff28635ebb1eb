"""What a run killed outright (SIGKILL, a power cut) leaves beside its outputs: the
hidden staging folders of :func:`sgtool.files.output_folder` and the hidden temporary
files of :func:`sgtool.files.atomic_write` (``.NAME.XXXXXXXX.partial``, the names of
:func:`sgtool.files.temp_beside`), found so that a command can name them or a resumed run
remove them."""

from __future__ import annotations

import os
from pathlib import Path

from sgtool.files import TEMP_RANDOM, temp_prefix


def _leftovers(target: str | os.PathLike[str], *, folders: bool) -> list[Path]:
    """The hidden temporary entries beside ``target`` (``.NAME.XXXXXXXX.partial``,
    :func:`~sgtool.files.temp_beside`'s names), folders or files, sorted by name."""
    path = Path(target)
    head, tail = temp_prefix(path.name, ".partial"), ".partial"
    if not path.parent.is_dir():
        return []
    return sorted(p for p in path.parent.iterdir()
                  if p.name.startswith(head) and p.name.endswith(tail)
                  and len(p.name) == len(head) + TEMP_RANDOM + len(tail)
                  and (p.is_dir() if folders else p.is_file()))


def leftover_stages(target: str | os.PathLike[str]) -> list[Path]:
    """The hidden staging folders of :func:`~sgtool.files.output_folder` beside ``target``
    (``.NAME.XXXXXXXX.partial``) that no run removed: a run killed outright (SIGKILL, a
    power cut) leaves one; sorted by name."""
    return _leftovers(target, folders=True)


def leftover_temps(target: str | os.PathLike[str]) -> list[Path]:
    """The hidden temporary files of :func:`~sgtool.files.atomic_write` (and
    :func:`~sgtool.files.atomic_output`)
    beside ``target`` (``.NAME.XXXXXXXX.partial``) that no writer removed: a process
    killed outright while it wrote ``target`` leaves one; sorted by name."""
    return _leftovers(target, folders=False)


def leftover_notes(target: str | os.PathLike[str]) -> list[str]:
    """One note per :func:`leftover_stages` folder beside ``target``, for a command to
    show after its run."""
    return [f"sgtool: note: {stale} is the unfinished output of a run that was killed (or "
            "one still running); remove it when none is" for stale in leftover_stages(target)]
