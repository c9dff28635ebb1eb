"""Writing imported frames into an sgtool log, and the report of an import.

Every importer ends here: frames (depth, optional colour and instance ids, the source's
world_T_camera and the intrinsics) go through the world alignment and into
:class:`~sgtool.log.LogWriter` as sgtool frames (depth, rgb and ids at the same log time,
``/tf`` world -> camera). The writer is atomic, so an error half way (a corrupt image) leaves
no output file.

The log carries:
- metadata ``sgtool.import``: source path and kind, layout or topics, pose source, world
  alignment (matrix, source up direction, floor height, how each was found), depth scale,
  intrinsics source, whether instance ids exist, odometry drift (and what it was measured
  against) and failed odometry steps when poses were estimated;
- an ``episode`` record (kind ``import``) at the first frame (``started``) and at the last
  (``ended``, with the frame count and the notes of the import).
"""

from __future__ import annotations

import json
import sys
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TypedDict

import numpy as np

from sgtool.errors import SgtoolError
from sgtool.log.frame import CameraIntrinsics
from sgtool.log.records import Episode, Instances
from sgtool.log.schemas import IMPORT_METADATA_NAME
from sgtool.log.writer import LogWriter
from sgtool.recorders.importers.images import ResizeLog
from sgtool.recorders.importers.odometry import DriftReport, OdometryResult
from sgtool.recorders.importers.upright import WorldAlignment

IMPORT_METADATA = IMPORT_METADATA_NAME


@dataclass(frozen=True, eq=False)
class ImportFrame:
    time_ns: int
    depth: np.ndarray  # uint16 millimetres or float32 metres
    pose: np.ndarray  # world_T_camera in the SOURCE world
    intrinsics: CameraIntrinsics
    rgb: np.ndarray | None = None
    ids: np.ndarray | None = None


@dataclass(frozen=True)
class ImportReport:
    """What an import wrote (``sgtool import`` prints :meth:`lines`): the log ``output``,
    the ``source`` and its ``kind`` (``rgbd/tum``, ``bag/ros2``, ...), frames and poses
    written, the world alignment (up, floor), whether colour and instance ids were there,
    where the poses came from, their drift against a reference, odometry failures, where
    each camera parameter came from, notes and warnings."""

    output: Path
    source: str
    kind: str  # "rgbd/tum", "rgbd/7scenes", "rgbd/open3d", "bag/ros1", "bag/ros2"...
    frames: int
    poses: int
    alignment: WorldAlignment
    has_rgb: bool
    has_ids: bool
    pose_source: str
    drift: DriftReport | None = None
    odometry_failures: int | None = None
    notes: tuple[str, ...] = field(default_factory=tuple)
    # what the drift was measured against: "ground truth" (TUM, 7-Scenes) or another
    # reference, e.g. "the reference trajectory (reconstructed, not ground truth)"
    drift_reference: str = "ground truth"
    odometry_summary: str = ""  # OdometryResult.summary()
    odometry_reasons: tuple[tuple[str, int], ...] = ()  # failed steps per reason
    # (parameter, value, origin) of the intrinsics, depth scale, up and floor
    sources: tuple[tuple[str, str, str], ...] = ()
    warnings: tuple[str, ...] = ()
    # every resize of colour or id images to the depth images (:class:`~.images.ResizeLog`)
    resizes: tuple[str, ...] = ()
    resize_counts: tuple[dict[str, object], ...] = ()
    # the import's checks before the heavy work: (check, verdict) lines
    checks: tuple[tuple[str, str], ...] = ()

    def lines(self, warnings_shown: bool = False) -> list[str]:
        """The report, a line per fact; ``warnings_shown``: the warnings were shown
        already where these lines go (a terminal), so they are counted, not repeated."""
        a = self.alignment
        ux, uy, uz = a.up
        out = [
            f"wrote {self.output}: {self.frames} frames from {self.kind} {self.source}",
            f"poses: {self.pose_source}",
            f"world: source up ({ux:.3f}, {uy:.3f}, {uz:.3f}) [{a.up_method}] -> +z, "
            f"floor {a.floor:.3f} m [{a.floor_method}] -> z=0",
            "colour: " + ("yes" if self.has_rgb else "no")
            + "; instance ids: " + ("yes" if self.has_ids else "none (geometry only)"),
        ]
        out.extend(f"{name}: {value} [{origin}]" for name, value, origin in self.sources)
        if self.odometry_failures is not None:
            out.append("odometry: " + (self.odometry_summary or
                                       f"{self.odometry_failures} failed steps (previous "
                                       "motion kept)"))
        if self.drift is not None:
            out.append(f"drift against {self.drift_reference}: " + self.drift.summary())
        out.extend(f"check: {name}: {verdict}" for name, verdict in self.checks)
        out.extend(f"resized: {r}" for r in self.resizes)
        out.extend(f"note: {n}" for n in self.notes)
        if warnings_shown and self.warnings:
            n = len(self.warnings)
            out.append(f"{n} warning{'s' if n > 1 else ''}, shown above")
        elif not warnings_shown:
            out.extend(f"warning: {w}" for w in self.warnings)
        return out


COARSEST_VOXEL_M = 0.5  # m: the largest voxel edge a replay of an import is asked for


def far_camera_problem(pose: np.ndarray, what: str) -> str | None:
    """The problem of a camera so far from the world origin that replay's voxel map cannot
    hold what it sees at any voxel size (up to :data:`COARSEST_VOXEL_M`, seeing as far as
    its default range): every replay would refuse the log, so the import does; None when
    some replay can (one at the default voxel size may still refuse it, saying so)."""
    from sgtool.mapping.voxel_keys import OFFSET
    from sgtool.mapping.voxels import VoxelConfig

    reach = (OFFSET - 2) * COARSEST_VOXEL_M - VoxelConfig().max_range
    t = np.asarray(pose, dtype=np.float64)[:3, 3]
    if np.all(np.abs(t) < reach):
        return None
    return (f"{what}: the camera at ({', '.join(f'{v:.1f}' for v in t)}) m is beyond "
            f"+-{reach:.0f} m of the world origin, past what replay's voxel map holds; "
            "recentre the trajectory near the origin (subtract e.g. the first pose's "
            "position from every pose) and import it again; nothing written")


def write_log(
    out: Path,
    frames: Iterable[ImportFrame],
    *,
    alignment: WorldAlignment,
    metadata: dict[str, str],
    total: int | None = None,
    progress: bool = True,
    notes: Iterable[str] = (),
    compression: str = "zstd",
    resizes: ResizeLog | None = None,
    instances: Instances | None = None,
) -> tuple[int, bool, bool]:
    """Write the frames; returns (frame count, any colour, any ids). ``instances``, the
    table of the ids (what each stands for), is written at the first frame's time; ids
    the frames hold that it does not list are a note (a replay ignores them), added to
    ``notes`` when it is a list (the caller's report). Raises
    :class:`SgtoolError` (leaving no output) when there is no frame at all. Chunks are zstd
    by default (``compression``; "lz4" trades a larger log for a faster import, see
    ``docs/experiments/moved-from-docstrings.md``). The resizes
    counted in ``resizes`` while the frames were made go into the ``ended`` episode record."""
    from tqdm import tqdm

    out = Path(out)
    meta = dict(metadata)
    meta.update(alignment.metadata())
    n = 0
    has_rgb = has_ids = False
    seen: set[int] = set()  # the ids the frames hold (with a table to check them against)
    first_t = last_t = 0
    A = alignment.matrix  # noqa: N806
    with LogWriter(out, compression=compression) as w:
        w.add_metadata(IMPORT_METADATA, meta)
        bar = tqdm(total=total, unit="frame", desc="import", file=sys.stderr,
                   disable=None if progress else True, leave=False)
        try:
            for fr in frames:
                if n == 0:
                    first_t = fr.time_ns
                    w.write_record(Episode(kind="import", status="started",
                                           source=meta.get("source", ""), frames=0),
                                   fr.time_ns)
                    if instances is not None:
                        w.write_record(instances, fr.time_ns)
                pose = A @ fr.pose
                far = far_camera_problem(pose, f"frame {n} (t = {fr.time_ns} ns)")
                if far is not None:
                    raise SgtoolError(far)
                try:
                    w.write_frame(fr.time_ns, depth=fr.depth, pose=pose,
                                  intrinsics=fr.intrinsics, rgb=fr.rgb, ids=fr.ids)
                except ValueError as e:  # what the log would hold wrong (a depth scale)
                    raise SgtoolError(f"frame {n} (t = {fr.time_ns} ns): {e}; nothing "
                                      "written") from None
                has_rgb |= fr.rgb is not None
                has_ids |= fr.ids is not None
                if instances is not None and fr.ids is not None:
                    seen.update(np.unique(fr.ids).tolist())
                last_t = fr.time_ns
                n += 1
                bar.update(1)
        finally:
            bar.close()
        if n == 0:
            raise SgtoolError("nothing to import: no frame has both a depth image and a pose")
        if instances is not None:
            unlisted = _unlisted(seen, instances)
            if isinstance(notes, list):
                notes.extend(unlisted)  # the caller's report says it too
            else:
                notes = [*notes, *unlisted]
        w.write_record(Episode(
            kind="import", status="ended", source=meta.get("source", ""), frames=n,
            extra={"notes": list(notes), "instance_ids": has_ids, "colour": has_rgb,
                   **({"resizes": resizes.lines()} if resizes is not None and resizes.counts
                      else {})},
        ), max(last_t, first_t))
    return n, has_rgb, has_ids


def drift_metadata(drift: DriftReport | None, reference: str = "ground truth") -> dict[str, str]:
    if drift is None:
        return {}
    return {"odometry_drift": json.dumps(drift.as_dict(), sort_keys=True),
            "odometry_drift_reference": reference}


def odometry_metadata(res: OdometryResult) -> dict[str, str]:
    """The failed steps of an odometry run, for the log's import metadata."""
    return {"odometry_failures": json.dumps(
        {"steps": res.steps, "failed": res.failures, "by_reason": res.reasons(),
         "frames": [f.frame for f in res.failed]}, sort_keys=True)}


class OdometryReportFields(TypedDict, total=False):
    """The :class:`ImportReport` fields an odometry run fills (none without one)."""

    odometry_failures: int
    odometry_summary: str
    odometry_reasons: tuple[tuple[str, int], ...]


def odometry_report_fields(res: OdometryResult | None) -> OdometryReportFields:
    """The :class:`ImportReport` fields of an odometry run; empty when ``res`` is None."""
    if res is None:
        return {}
    return {"odometry_failures": res.failures, "odometry_summary": res.summary(),
            "odometry_reasons": tuple(res.reasons().items())}


def _unlisted(seen: set[int], instances: Instances) -> list[str]:
    """The note on ids the frames hold that the instance table does not list."""
    listed = {i.id for i in instances.instances}
    missing = sorted(seen - listed - {0})
    if not missing:
        return []
    shown = ", ".join(str(i) for i in missing[:8]) + (" ..." if len(missing) > 8 else "")
    return [f"{len(missing)} instance id(s) in the id images are not in the instance table "
            f"({shown}): a replay ignores them"]
