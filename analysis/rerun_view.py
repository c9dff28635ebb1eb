"""Export a log to a Rerun recording (``.rrd``).

Rerun converts some Foxglove MCAP messages itself, but not Grid or SceneUpdate, and knows
nothing of sgtool's JSON records; so sgtool logs everything natively with the Rerun SDK:

- ``world/camera``: the camera pose (Transform3D), pinhole, RGB, depth and instance
  segmentation (class ids = instance ids, labelled with their categories);
- ``world/robot``: the base position and the path travelled so far;
- ``world/map/occupancy``: the BEV occupancy grid (``GridMap``);
- ``world/map/voronoi``: the Voronoi graph coloured by room (``LineStrips3D``);
- ``world/map/voxels``: the semantic voxel map when the caller passes one per refresh;
- ``world/graph/rooms|objects|doors|frontiers``: scene-graph nodes with labels (doors
  green when open, red when closed), cleared when a graph has none;
- ``graph``: the scene graph as ``GraphNodes``/``GraphEdges`` (rooms, regions, frontiers,
  objects and doors; edges object -> parent, region -> room, door -> rooms, room ->
  neighbour), for Rerun's graph view;
- ``actions``: the actions with their outcomes (``TextLog``);
- ``episode``: the Episode records (query, planner, status, steps, how it ended), as
  Markdown (``TextDocument``).

A log of a trajectory only (``sgtool import bag`` without ``--depth``) shows the path of
its world-parented ``/tf`` transforms. Segmentation class ids are the instance ids, or,
when a table holds ids past 65535, their ranks (:func:`class_ids`).

Every recording carries a default blueprint (:func:`blueprint`): the 3D map with the
robot and the graph, a bird's-eye view of the occupancy grid with the Voronoi graph and
rooms, the camera's RGB, depth and segmentation, the scene graph's graph view and the
action log.

Two timelines: ``frame`` (frame index) and ``sim_time`` (log time since the start; Rerun's
wall-clock ``log_time`` is turned off, :func:`new_stream`). What an export holds is a
function of the log: the recording id is derived from the log's bytes (:func:`recording_id`),
every entity, time and value follows from the log, the blueprint's containers and views have
fixed ids (:func:`blueprint`) and a file's rows are cut into chunks by size only, never by
the clock (:func:`new_stream`). The file's bytes are not, and Rerun gives no way to make
them so (:mod:`sgtool.analysis.rrd_contents` says why): two exports of one log differ under
``cmp``; compare their :func:`sgtool.analysis.rrd_contents.content_digest`. The robot's
path is logged in pieces of :data:`PATH_CHUNK` points (``world/robot/path/K``), each
re-logged only while it grows, so the recording grows linearly with the number of frames.

The ``.rrd`` is written atomically (:func:`sgtool.files.atomic_output`): an error or Ctrl-C
leaves nothing at its path. Rerun's file sink does not report write errors (on a full disk
it warns and its flush waits forever), so the export watches the free space of the
destination itself and stops with an :class:`~sgtool.files.OutputError` when less than
:data:`FREE_MARGIN` bytes are left.
"""

from __future__ import annotations

import bisect
import contextlib
import errno
import hashlib
import os
import uuid
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from sgtool.colors import color_for
from sgtool.errors import SgtoolError
from sgtool.files import atomic_output, output_error
from sgtool.log import LogReader, codec
from sgtool.log import schemas as S
from sgtool.log.frame import Frame
from sgtool.log.inspect import foreign_log_problem

APP_ID = "sgtool"
FREE_MARGIN = 16 * 1024 * 1024  # bytes that must stay free beside the .rrd while writing
FLUSH_TIMEOUT_S = 600.0
PATH_CHUNK = 100  # path points per ``world/robot/path/K`` entity (the path is logged in pieces)


def require_space(rrd_path: Path) -> None:
    """Raise an :class:`~sgtool.files.OutputError` when the folder of ``rrd_path`` has
    less than :data:`FREE_MARGIN` bytes free (Rerun would fail silently and hang)."""
    st = os.statvfs(rrd_path.parent)
    if st.f_bavail * st.f_frsize < FREE_MARGIN:
        raise output_error(OSError(errno.ENOSPC, os.strerror(errno.ENOSPC)), rrd_path)


def blueprint() -> Any:
    """The default layout of an sgtool recording (module doc)."""
    import rerun.blueprint as rrb

    cam = "world/camera/image"
    bp = rrb.Blueprint(rrb.Horizontal(
        rrb.Vertical(
            rrb.Spatial3DView(name="3D map", origin="world"),
            rrb.Spatial3DView(name="Bird's-eye map", origin="world", contents=[
                "+ world/map/occupancy", "+ world/map/voronoi/**", "+ world/map/rooms/**",
                "+ world/robot/**", "+ world/graph/**"]),
        ),
        rrb.Vertical(
            rrb.Horizontal(
                rrb.Spatial2DView(name="RGB", origin=cam, contents=[f"+ {cam}/rgb"]),
                rrb.Spatial2DView(name="Depth", origin=cam, contents=[f"+ {cam}/depth"]),
                rrb.Spatial2DView(name="Segmentation", origin=cam,
                                  contents=[f"+ {cam}/segmentation"]),
            ),
            rrb.GraphView(name="Scene graph", origin="graph"),
            rrb.TextLogView(name="Actions", origin="actions"),
            rrb.TextDocumentView(name="Episode", origin="episode"),
        ),
        column_shares=[3, 2],
    ), collapse_panels=False)
    _fixed_ids(bp.root_container, "root")
    return bp


BLUEPRINT_IDS = uuid.UUID("5b7c1f0e-3f44-4a52-9d7e-2a1c9b3e6d10")  # uuid5 namespace


def _fixed_ids(part: Any, where: str) -> None:
    """Give a container or view and everything in it an id that follows from its place
    in the layout (Rerun draws a random uuid4 for each, which would change the blueprint's
    entity paths from export to export)."""
    part.id = uuid.uuid5(BLUEPRINT_IDS, where)
    for k, sub in enumerate(getattr(part, "contents", None) or ()):
        if hasattr(sub, "blueprint_path"):
            _fixed_ids(sub, f"{where}/{k}")


def recording_id(log_path: Path) -> str:
    """The Rerun recording id of a log: the SHA-256 of its bytes (32 hex digits), so two
    different logs never merge in the viewer however they are named, and viewing the same
    log twice gives the same recording."""
    try:
        with open(log_path, "rb") as fh:
            return hashlib.file_digest(fh, "sha256").hexdigest()[:32]
    except OSError:
        return hashlib.sha256(str(log_path).encode()).hexdigest()[:32]  # the reader says why


def frame_at(frame_times: Sequence[int], t_ns: int) -> int | None:
    """The ``frame`` a layer logged at ``t_ns`` is shown at: the index of the last camera
    frame at or before it (the first frame for an earlier time); None for a log without
    frames (``frame_times`` empty)."""
    if not frame_times:
        return None
    return max(bisect.bisect_right(frame_times, t_ns) - 1, 0)


def _time(rec: Any, frame: int | None, t_ns: int) -> None:
    import rerun as rr

    if frame is not None:
        rr.set_time("frame", sequence=int(frame), recording=rec)
    rr.set_time("sim_time", duration=np.timedelta64(int(t_ns), "ns"), recording=rec)


def _scene_update_strips(msg: Any) -> tuple[list[np.ndarray], list[tuple[int, int, int]]]:
    """Foxglove SceneUpdate line primitives -> 2-point strips with colours."""
    strips: list[np.ndarray] = []
    colors: list[tuple[int, int, int]] = []
    for ent in msg.entities:
        for line in ent.lines:
            pts = np.array([[p.x, p.y, p.z] for p in line.points], np.float32)
            cols = list(line.colors)
            base = line.color
            if line.type == line.LINE_LIST:
                pairs = range(0, len(pts) - 1, 2)
                for i in pairs:
                    strips.append(pts[i : i + 2])
                    c = cols[i] if cols else base
                    colors.append((int(c.r * 255), int(c.g * 255), int(c.b * 255)))
            else:
                if line.type == line.LINE_LOOP and len(pts) > 2:
                    pts = np.concatenate([pts, pts[:1]])
                strips.append(pts)
                colors.append((int(base.r * 255), int(base.g * 255), int(base.b * 255)))
    return strips, colors


def export(
    log_path: str | os.PathLike[str],
    rrd_path: str | os.PathLike[str] | None,
    *,
    every: int = 1,
    max_frames: int | None = None,
    progress: Callable[[int], None] | None = None,
    voxels: Callable[[Any], Iterator[tuple[int, int, np.ndarray, np.ndarray, float]]]
    | None = None,
    spawn: bool = False,
    warn: Callable[[str], None] | None = None,
    live: Any = None,
    hold: Callable[[], None] | None = None,
) -> Path | None:
    """Write ``log_path`` as a Rerun recording to ``rrd_path`` (atomically), or stream it
    to a spawned viewer when ``spawn`` is set, or to ``live`` (a
    :class:`~sgtool.analysis.rerun_live.LiveTarget`: spawn, connect, serve; the web
    viewer's address goes to ``warn``). ``hold``, when given, is called after everything is
    sent and before the stream closes (a served recording lives until it returns).
    ``every`` logs one camera frame in K (maps, graphs and actions are always logged);
    ``max_frames`` stops after that many camera frames, and leaves out the maps, graphs and
    actions logged after them.
    ``voxels``, when given, is called with the open reader and yields (frame index, t_ns,
    voxel centres (N,3), colours (N,3) uint8, voxel size) to draw the semantic voxel map
    over time. ``warn``, when given, receives one-line notes about the log (frames without
    a camera pose). A recording that is not an sgtool log (a ROS bag, another tool's MCAP)
    is refused with :class:`~sgtool.errors.SgtoolError` naming the import that fits it."""

    log_path = Path(log_path)
    if (foreign := foreign_log_problem(log_path)) is not None:
        raise SgtoolError(foreign)
    rid = recording_id(log_path)
    if spawn and live is None:
        from sgtool.analysis.rerun_live import LiveTarget

        live = LiveTarget("spawn")
    out = None if live is not None or rrd_path is None else Path(rrd_path)
    target = contextlib.nullcontext(None) if out is None else atomic_output(out)
    with target as tmp:
        if live is not None:
            from sgtool.analysis.rerun_live import open_stream

            rec, where = open_stream(live, rid)
            if where is not None and warn is not None:
                warn(f"web viewer at {where}")
        else:
            rec = new_stream(rid, to_file=out is not None)
        if out is not None and tmp is not None:
            require_space(out)
            rec.save(tmp, default_blueprint=blueprint())
            progress = _watching_space(out, progress)
        with LogReader(log_path, verify=True) as r:  # a damaged chunk: one line, no .rrd
            unposed, framed = _export(rec, r, every=every, max_frames=max_frames,
                                      progress=progress, voxels=voxels)
            drawn = {S.TF, S.OCCUPANCY, S.VORONOI, S.ROOMS,
                     *(k.topic for n, k in S.RECORDS.items() if n != "instances")}
            if not framed and not r.topics() & drawn and warn is not None:
                warn(f"{log_path} holds nothing sgtool draws (no camera frames, /tf, maps "
                     "or records): the recording is empty")
        if unposed and warn is not None:
            warn(f"{unposed} of {framed} frames have no camera pose: {S.TF} has no chain "
                 f"{S.WORLD_FRAME} -> {S.CAMERA_FRAME} at their time (a missing link or a "
                 "cycle); they are shown without one")
        rec.flush(timeout_sec=FLUSH_TIMEOUT_S)
        if out is not None and tmp is not None:
            require_space(out)
        if hold is not None:
            hold()
        rec.disconnect()
    return out


FILE_FLUSH_TICK_S = 1e9  # no flush by the clock when writing a file (new_stream)


def new_stream(rid: str, *, to_file: bool = False) -> Any:
    """A Rerun recording stream of id ``rid`` on sgtool's timelines only (Rerun's own
    ``log_time``, the wall clock of the export, is left out: it would differ from export to
    export and squeeze the log's time into the export's). ``to_file``: rows are cut into
    chunks by size only (Rerun's batcher otherwise also cuts them at a tick of the wall
    clock, so a slower export holds other chunks); a live viewer keeps that tick, which is
    what makes it draw while the export runs."""
    import rerun as rr

    batching = (rr.ChunkBatcherConfig(flush_tick=FILE_FLUSH_TICK_S) if to_file else None)
    rec = rr.RecordingStream(APP_ID, recording_id=rid, send_properties=False,
                             batcher_config=batching)
    rec.set_log_time_enabled(False)
    return rec


def class_ids(instance_ids: Iterable[int]) -> np.ndarray | None:
    """How instance ids become Rerun's 16-bit class ids: None when every id fits (an id is
    its class id), else the sorted ids, whose position + 1 is the class id (ids of a table
    past 65535, as ``32SC1`` images hold them: never wrapped onto another's)."""
    ids = np.unique(np.asarray(list(instance_ids), dtype=np.int64))
    return None if ids.size == 0 or int(ids.max()) <= 65535 else ids


def log_labels(rec: Any, labels: Mapping[int, str]) -> np.ndarray | None:
    """The segmentation images' labels (instance id -> category) as the camera's static
    annotation context, "category #id" in the id's colour; returns the class ids of
    :func:`class_ids` that :func:`segmentation` takes."""
    import rerun as rr

    dense = class_ids(labels)
    ctx = [(0, "none", (0, 0, 0))] + [
        (iid if dense is None else k + 1, f"{cat} #{iid}", color_for(iid))
        for k, (iid, cat) in enumerate(sorted(labels.items()))
    ]
    rec.log("world/camera/image", rr.AnnotationContext(ctx), static=True)
    return dense


def segmentation(ids: np.ndarray, dense: np.ndarray | None) -> np.ndarray:
    """A frame's instance ids as class ids (:func:`class_ids`); an id without a class is
    0 (none)."""
    a = ids.astype(np.int64)
    if dense is None:
        return np.where((a > 0) & (a <= 65535), a, 0).astype(np.uint16)
    pos = np.searchsorted(dense, a)
    ok = (pos < dense.size) & (dense[np.minimum(pos, dense.size - 1)] == a) & (a > 0)
    return np.where(ok, pos + 1, 0).astype(np.uint16)


def log_camera(rec: Any, fr: Frame, dense: np.ndarray | None = None) -> None:
    """A frame's camera at the current time: its pose (when /tf gives one), pinhole, RGB,
    depth and instance segmentation."""
    import rerun as rr

    if np.all(np.isfinite(fr.pose)):
        rec.log("world/camera", rr.Transform3D(
            translation=fr.pose[:3, 3].astype(np.float32),
            mat3x3=fr.pose[:3, :3].astype(np.float32)))
    k = fr.intrinsics
    rec.log("world/camera/image", rr.Pinhole(
        image_from_camera=k.K.astype(np.float32), resolution=[k.width, k.height],
        camera_xyz=rr.ViewCoordinates.RDF, image_plane_distance=0.3))
    if fr.rgb is not None:
        rec.log("world/camera/image/rgb", rr.Image(fr.rgb))
    rec.log("world/camera/image/depth", rr.DepthImage(fr.depth, meter=1.0))
    if fr.ids is not None:
        rec.log("world/camera/image/segmentation",
                rr.SegmentationImage(segmentation(fr.ids, dense)))


class RobotPath:
    """The robot's path, logged in pieces of :data:`PATH_CHUNK` points
    (``world/robot/path/K``, module doc): :meth:`add` every frame, :meth:`log` when the
    frame is shown."""

    def __init__(self) -> None:
        self.points: list[tuple[float, float, float]] = []
        self.done = 0  # pieces before this one are complete in the recording

    def add(self, fr: Frame) -> tuple[float, float, float] | None:
        """The frame's base position (the camera's without a base pose), appended to the
        path; None when /tf does not give it."""
        return self.add_pose(fr.base_pose if fr.base_pose is not None else fr.pose)

    def add_pose(self, base: np.ndarray) -> tuple[float, float, float] | None:
        """The position of the pose ``base`` (world_T_frame), appended to the path; None
        when it is not finite."""
        if not np.all(np.isfinite(base)):
            return None
        here = (float(base[0, 3]), float(base[1, 3]), 0.02)
        self.points.append(here)
        return here

    def log(self, rec: Any, here: tuple[float, float, float] | None) -> None:
        """The robot at ``here`` (when known) and the pieces that changed since the last
        call: only the current one, plus any finished while frames were not shown."""
        import rerun as rr

        if here is not None:
            rec.log("world/robot", rr.Points3D([here], radii=0.15, colors=[(230, 80, 40)]))
        pts = self.points
        if len(pts) < 2:
            return
        last = (len(pts) - 2) // PATH_CHUNK
        for j in range(self.done, last + 1):
            # piece j: points j*C .. (j+1)*C, sharing its first with piece j - 1
            piece = pts[j * PATH_CHUNK:(j + 1) * PATH_CHUNK + 1]
            rec.log(f"world/robot/path/{j}", rr.LineStrips3D(
                [np.array(piece, np.float32)], radii=0.02, colors=[(230, 80, 40)]))
        self.done = last


def _watching_space(rrd_path: Path, progress: Callable[[int], None] | None
                    ) -> Callable[[int], None]:
    def tick(n: int) -> None:
        require_space(rrd_path)
        if progress is not None:
            progress(n)
    return tick


def _export(
    rec: Any, r: LogReader, *, every: int, max_frames: int | None,
    progress: Callable[[int], None] | None, voxels: Any,
) -> tuple[int, int]:
    """Log everything; returns (frames without a camera pose, frames logged)."""
    import rerun as rr

    tr = r.time_range()
    t0 = tr[0] if tr else 0

    def stamp(frame: int | None, t_ns: int) -> None:
        _time(rec, frame, t_ns - t0)

    rec.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
    instances = r.last_record("instances")
    dense = log_labels(rec, {int(i["id"]): i["category"] for i in instances["instances"]}
                       ) if instances else None
    # camera frames
    path = RobotPath()
    unposed = framed = 0  # frames whose camera pose /tf does not give (a missing link, a cycle)
    if r.has(S.DEPTH):
        for n, fr in enumerate(r.frames()):
            if max_frames is not None and n >= max_frames:
                break
            if progress:
                progress(1)
            framed += 1
            here = path.add(fr)
            unposed += not bool(np.all(np.isfinite(fr.pose)))
            if fr.index % every:
                continue
            stamp(fr.index, fr.time_ns)
            log_camera(rec, fr, dense)
            path.log(rec, here)
    elif r.has(S.TF):  # a trajectory without frames (`sgtool import bag` without --depth)
        for d in r.messages([S.TF]):
            if d.message.parent_frame_id == S.WORLD_FRAME:
                stamp(None, d.log_time_ns)
                path.log(rec, path.add_pose(codec.decode_transform(d.message)))
    # voxel map over time (computed by the caller)
    if voxels is not None:
        for idx, t_ns, centres, cols, size in voxels(r):
            stamp(idx, t_ns)
            rec.log("world/map/voxels", rr.Boxes3D(
                centers=centres.astype(np.float32),
                half_sizes=np.full((len(centres), 3), size / 2, np.float32),
                colors=cols, fill_mode="solid"))
    frame_times = r.frame_times() if r.has(S.DEPTH) else []
    # with max_frames, what was logged after the last frame shown is left out too
    end = (frame_times[max_frames] if max_frames is not None and max_frames < len(frame_times)
           else None)

    def frame_of(t: int) -> int | None:
        return frame_at(frame_times, t)

    # derived layers
    if r.has(S.OCCUPANCY):
        for d in r.messages([S.OCCUPANCY], end_ns=end):
            cells, origin, res = codec.decode_grid(d.message)
            stamp(frame_of(d.log_time_ns), d.log_time_ns)
            h, w = cells.shape
            rec.log("world/map/occupancy", rr.GridMap(
                data=cells.tobytes(),
                format=rr.components.ImageFormat(width=w, height=h, color_model="L",
                                                 channel_datatype="U8"),
                cell_size=res, translation=[origin[0], origin[1], -0.01],
                colormap=rr.components.Colormap.RvizMap))
    for topic, entity in ((S.VORONOI, "world/map/voronoi"), (S.ROOMS, "world/map/rooms")):
        if r.has(topic):
            for d in r.messages([topic], end_ns=end):
                strips, colors = _scene_update_strips(d.message)
                stamp(frame_of(d.log_time_ns), d.log_time_ns)
                rec.log(entity, rr.LineStrips3D(strips, colors=colors, radii=0.02)
                        if strips else rr.Clear(recursive=False))
    for t, g in r.records("scene_graph", end_ns=end):
        stamp(frame_of(t), t)
        _log_scene_graph(rec, g)
    for t, e in r.records("episode", end_ns=end):
        stamp(frame_of(t), t)
        rec.log("episode", rr.TextDocument(episode_text(e), media_type="text/markdown"))
    for t, a in r.records("action", end_ns=end):
        stamp(frame_of(t), t)
        level = "INFO" if a.get("outcome") == "success" else "WARN"
        text = f"{a.get('skill')}({a.get('target') or ''}) -> {a.get('outcome')}"
        if a.get("reason"):
            text += f": {a['reason']}"
        if a.get("travelled_m"):
            text += f" [{a['travelled_m']:.2f} m]"
        rec.log("actions", rr.TextLog(text, level=level))
    return unposed, framed


def episode_text(e: dict[str, Any]) -> str:
    """An Episode record as Markdown: what was searched for (or recorded) and how it
    ended."""
    keys = ("kind", "status", "query", "planner", "house_id", "steps", "travelled_m",
            "shortest_m", "frames")
    lines = [f"- **{k}**: {e[k]}" for k in keys if e.get(k) is not None]
    end = (e.get("extra") or {}).get("end")
    if end:
        lines.append(f"- **end**: {end}")
    return "\n".join(lines)


def graph_nodes_edges(g: dict[str, Any]) -> tuple[list[str], list[str], list[tuple[float, float]],
                                                   list[tuple[int, int, int]],
                                                   list[tuple[str, str]]]:
    """The scene graph record ``g`` as graph-view nodes (ids, labels, 2D positions,
    colours) and edges between node ids (module doc); an edge to a node the graph does not
    hold is left out."""
    ids: list[str] = []
    labels: list[str] = []
    pos: list[tuple[float, float]] = []
    cols: list[tuple[int, int, int]] = []

    def node(nid: str, label: str, xy: Any, col: tuple[int, int, int]) -> None:
        ids.append(nid)
        labels.append(label)
        pos.append((float(xy[0]), -float(xy[1])))  # the graph view's y points down
        cols.append(col)

    for rm in g.get("rooms") or ():
        node(rm["id"], f"{rm['id']} {rm.get('category') or ''}".strip(), rm["position"],
             color_for(rm["id"]))
    for x in g.get("regions") or ():
        kind = x.get("kind") or "region"
        col = ((40, 200, 255) if x.get("frontier_type") == "leading out" else (255, 200, 40)
               ) if kind == "frontier" else (150, 150, 150)
        node(x["id"], x["id"], x["position"], col)
    for o in g.get("objects") or ():
        state = f" ({o['state']})" if o.get("state") else ""
        node(o["id"], f"{o['category']}{state}", o["position"], color_for(o.get("room") or o["id"]))
    for d in g.get("doors") or ():
        node(d["id"], f"door ({d.get('state') or '?'})", d["position"],
             (50, 200, 50) if d.get("state") == "open" else (220, 50, 50))
    known = set(ids)
    edges: list[tuple[str, str]] = []
    for o in g.get("objects") or ():
        edges.append((o["id"], o.get("parent") or ""))
    for x in g.get("regions") or ():
        edges.append((x["id"], x.get("room") or ""))
    for d in g.get("doors") or ():
        edges.extend((d["id"], r) for r in d.get("rooms") or ())
    for rm in g.get("rooms") or ():
        edges.extend((rm["id"], n) for n in rm.get("neighbours") or () if rm["id"] < n)
    return ids, labels, pos, cols, [(a, b) for a, b in edges if a in known and b in known]


def _log_scene_graph(rec: Any, g: dict[str, Any]) -> None:
    import rerun as rr

    ids, labels, pos, cols, edges = graph_nodes_edges(g)
    if ids:
        rec.log("graph", rr.GraphNodes(ids, labels=labels, positions=pos, colors=cols),
                rr.GraphEdges(edges, graph_type="undirected"))
    else:
        rec.log("graph", rr.Clear(recursive=False))

    rooms = g.get("rooms", [])
    rec.log("world/graph/rooms", rr.Points3D(
        [(*rm["position"][:2], 1.5) for rm in rooms],
        labels=[f"{rm['id']}: {rm['category']}" for rm in rooms],
        colors=[color_for(rm["id"]) for rm in rooms], radii=0.12)
        if rooms else rr.Clear(recursive=False))
    objs = g.get("objects", [])
    rec.log("world/graph/objects", rr.Points3D(
        [o["position"] for o in objs],
        labels=[o["category"] + (f" ({o['state']})" if o.get("state") else "")
                for o in objs],
        colors=[color_for(o["room"]) for o in objs], radii=0.05)
        if objs else rr.Clear(recursive=False))
    doors = g.get("doors", [])
    rec.log("world/graph/doors", rr.Points3D(
        [(*d["position"][:2], 1.0) for d in doors],
        labels=[f"door ({d.get('state') or '?'})" for d in doors],
        colors=[(50, 200, 50) if d.get("state") == "open" else (220, 50, 50)
                for d in doors], radii=0.1)
        if doors else rr.Clear(recursive=False))
    fr = [x for x in g.get("regions", []) if x.get("kind") == "frontier"]
    if fr:
        rec.log("world/graph/frontiers", rr.Points3D(
            [(*x["position"][:2], 0.05) for x in fr],
            labels=[x.get("frontier_type") or "frontier" for x in fr],
            colors=[(40, 200, 255) if x.get("frontier_type") == "leading out"
                    else (255, 200, 40) for x in fr], radii=0.08))
    else:
        rec.log("world/graph/frontiers", rr.Clear(recursive=False))
