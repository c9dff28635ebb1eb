"""Instance-id images of an RGB-D folder (``sgtool import rgbd --ids DIR --instances FILE``):
one single-channel integer image per depth image, in ``DIR``, named as the depth image
(the same stem; ``.png``, ``.tif``/``.tiff`` or ``.npy``), 0 where no instance is, each
other value an id of the instance table (:mod:`.instance_table`), registered to the
depth image (the same size).

:func:`id_files` pairs the files with the frames before anything is written (a depth
image without its id image is one line naming how many and the first); :func:`read_ids`
reads one, refusing another size than the depth's, colour or float images. A folder that
looks like id images beside the depth (``instance``, ``instances``, ``ids``) is not read
without ``--ids``: :func:`unread_ids_note` says so.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from sgtool.errors import SgtoolError

SUFFIXES = (".png", ".tif", ".tiff", ".npy")
ID_FOLDERS = ("instance", "instances", "ids", "instance_ids")


def id_files(folder: Path, depth_files: Sequence[Path]) -> list[Path]:
    """The id image in ``folder`` of each depth file (its stem, any of :data:`SUFFIXES`,
    in that order); one :class:`SgtoolError` line when ``folder`` is no folder or a depth
    image has none."""
    if not folder.is_dir():
        raise SgtoolError(f"--ids {folder}: " + ("no such folder" if not folder.exists()
                                                  else "not a folder (give the folder of "
                                                  "the id images)"))
    by_stem: dict[str, Path] = {}
    ours = [p for p in folder.iterdir() if p.suffix.lower() in SUFFIXES]
    for p in sorted(ours, key=lambda p: (SUFFIXES.index(p.suffix.lower()), p.name)):
        if p.is_file():
            by_stem.setdefault(p.stem, p)
    missing = [d for d in depth_files if d.stem not in by_stem]
    if missing:
        raise SgtoolError(
            f"--ids {folder}: {len(missing)} of the {len(depth_files)} depth images have no "
            f"id image of the same name there (first: {missing[0].stem} with "
            f"{', '.join(SUFFIXES)}); an id image is named as its depth image")
    return [by_stem[d.stem] for d in depth_files]


def read_ids(path: Path, shape: tuple[int, int]) -> np.ndarray:
    """The instance ids of the image file ``path`` as int32 (0: no instance), which must
    be single-channel integers of ``shape`` (the depth image's (height, width))."""
    from sgtool.recorders.importers.images import read_image_file

    if path.suffix.lower() == ".npy":
        try:
            a = np.load(path, allow_pickle=False)
        except (OSError, ValueError) as e:
            raise SgtoolError(f"{path}: cannot read it as a NumPy array ({e})") from None
    else:
        a = read_image_file(path)
    if a.ndim != 2 and _palette_png(path):
        raise SgtoolError(f"{path}: a palette (indexed-colour) PNG, whose colours OpenCV "
                          "reads, not its indices: save the ids as a greyscale 8- or 16-bit "
                          "PNG (or .npy)")
    if a.ndim != 2 or a.dtype.kind not in "ui":
        raise SgtoolError(f"{path}: an id image must be single-channel integers (8, 16 or "
                          f"32 bit), this one is {a.dtype} with shape {a.shape}")
    if a.shape != shape:
        raise SgtoolError(f"{path}: {a.shape[1]}x{a.shape[0]} pixels, its depth image has "
                          f"{shape[1]}x{shape[0]} (id images are registered to the depth)")
    if a.dtype.kind == "i" and a.size and int(a.min()) < 0 or \
            a.size and int(a.max()) > np.iinfo(np.int32).max:
        raise SgtoolError(f"{path}: ids must be 0 (no instance) or positive 32-bit numbers")
    return a.astype(np.int32)


def _palette_png(path: Path) -> bool:
    """Whether ``path`` is a PNG of indexed colour (IHDR colour type 3)."""
    try:
        with open(path, "rb") as f:
            head = f.read(26)
    except OSError:
        return False
    return head[:8] == b"\x89PNG\r\n\x1a\n" and head[12:16] == b"IHDR" and head[25] == 3


def unread_ids_note(root: Path) -> str | None:
    """A note naming a folder of ``root`` that looks like id images (:data:`ID_FOLDERS`),
    read only with ``--ids``; None when there is none."""
    for name in ID_FOLDERS:
        if (root / name).is_dir():
            return (f"{name}/ not read: give --ids {root / name} --instances TABLE.json to "
                    "import its instance ids (docs: sgtool import rgbd --help)")
    return None
