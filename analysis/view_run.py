"""`sgtool view` after its checks: a log drawn in Rerun (:mod:`sgtool.analysis.rerun_view`),
written to a recording or streamed live, with a progress bar of frames.

The command checks the target (a file through the one output check, or a viewer) and
builds the request; ``show`` receives the result line (stdout), ``note`` the notes
(stderr).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
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
