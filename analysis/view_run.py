"""`sgtool view` after its checks: a log drawn in Rerun (:mod:`sgtool.analysis.rerun_view`),
written to a recording or streamed live, with a progress bar of frames.

The command checks the target (a file through the one output check, or a viewer) and
builds the request; ``show`` receives the result line (stdout), ``note`` the notes
(stderr).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sgtool.files import quoted
from sgtool.log.schemas import DEPTH

Echo = Callable[[str], None]


@dataclass(frozen=True)
class ViewRequest:
    """A checked `sgtool view`: ``log`` drawn every ``every`` camera frames (at most
    ``max_frames``), with the voxel map when ``voxels``, into the recording ``output`` or
    to the live target ``live`` (:class:`sgtool.analysis.rerun_live.LiveTarget`); the
    paths as the user gave them."""

    log: str
    output: str | None
    every: int = 1
    max_frames: int | None = None
    voxels: bool = True
    live: Any = None


def view_log(request: ViewRequest, show: Echo, note: Echo) -> None:
    """Draw the log as ``request`` says; a served recording stays up until Ctrl-C."""
    from tqdm import tqdm

    from sgtool.analysis.rerun_view import export
    from sgtool.log import LogReader

    with LogReader(request.log) as r:
        total = r.frame_count() if r.has(DEPTH) else 0
    if request.max_frames is not None:
        total = min(total, request.max_frames)
    live = request.live
    with tqdm(total=total, unit="frame", desc="view", disable=None) as bar:
        export(request.log, request.output, every=request.every,
               max_frames=request.max_frames, progress=bar.update,
               voxels=_voxel_source(request), live=live,
               warn=lambda m: note(f"note: {m}"),
               hold=(lambda: _serve_until_interrupted(note))
               if live is not None and live.mode == "serve" else None)
    if request.output:
        show(f"wrote {request.output}; open it with: rerun {quoted(request.output)}")


def write_rerun(log: str | os.PathLike[str], output: str | os.PathLike[str], *,
                every: int = 1, max_frames: int | None = None, voxels: bool = True,
                overwrite: bool = False, progress: Callable[[int], None] | None = None,
                warn: Callable[[str], None] | None = None) -> Path:
    """Write ``log`` as a Rerun recording ``output`` (``.rrd``, atomically), as ``sgtool
    view LOG -o OUTPUT`` does: camera images, the voxel map (unless not ``voxels``), the
    maps, graphs, rooms, objects, doors, frontiers, path, actions and episode of a derived
    log, on a frame timeline; one camera frame in ``every``, at most ``max_frames``.
    ``progress`` is called with the frames drawn, ``warn`` with one-line notes about the
    log. An existing ``output`` is refused unless ``overwrite``; a foreign recording, a
    damaged log or an output that is the log is one :class:`~sgtool.errors.SgtoolError`
    line. Returns the path written."""
    from sgtool.analysis.rerun_view import export
    from sgtool.arg_checks import function
    from sgtool.arg_checks import progress as check_progress
    from sgtool.errors import SgtoolError
    from sgtool.extras import require
    from sgtool.output_check import check_output

    progress = check_progress("progress", progress, method="")
    function("warn", warn)
    require("rerun", api="sgtool.write_rerun")  # one line on a core install
    if every < 1 or (max_frames is not None and max_frames < 1):
        raise SgtoolError(f"every={every}, max_frames={max_frames}: each must be >= 1")
    if Path(output).resolve() == Path(log).resolve():
        raise SgtoolError("the output must not be the input log")
    check_output(output, force=overwrite, suffixes=(".rrd",), what="Rerun recording",
                 force_flag="--force (overwrite=)")
    request = ViewRequest(log=os.fspath(log), output=os.fspath(output), every=every,
                          max_frames=max_frames, voxels=voxels)
    written = export(log, output, every=every, max_frames=max_frames, progress=progress,
                     voxels=_voxel_source(request), warn=warn)
    assert written is not None  # a file was asked for
    return written


def _voxel_source(request: ViewRequest) -> Callable[[Any], Any] | None:
    """The voxel snapshots of a reader (None: no voxels asked for, or no mapping
    pipeline installed)."""
    if not request.voxels:
        return None
    try:
        from sgtool.replayers.voxel_timeline import voxel_snapshots
    except ImportError:
        return None

    def voxel_source(reader: Any) -> Any:
        if not reader.has(DEPTH):  # a trajectory: nothing to map
            return iter(())
        return voxel_snapshots(reader, every=max(request.every, 10),
                               max_frames=request.max_frames)
    return voxel_source


def _serve_until_interrupted(note: Echo) -> None:
    """Keep a served recording up until Ctrl-C."""
    import time

    note("rerun: everything sent; still serving, press Ctrl-C to stop")
    try:
        while True:
            time.sleep(1.0)
    except KeyboardInterrupt:
        pass
