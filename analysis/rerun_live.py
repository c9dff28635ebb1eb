"""Watching sgtool in Rerun while it runs: where a recording stream goes (``--rerun``),
and a live view of a replay's refreshes.

``--rerun`` takes one of:

- ``spawn``: start a native Rerun viewer (needs a display and ``rerun`` on PATH);
- ``connect`` or ``connect:URL``: stream to a running viewer (default
  ``rerun+http://127.0.0.1:9876/proxy``, what ``rerun`` listens on);
- ``serve``, ``serve:WEB_PORT`` or ``serve:WEB_PORT:GRPC_PORT``: serve the recording over
  gRPC (port :data:`GRPC_PORT`) and a web viewer over HTTP (port :data:`WEB_PORT`) from
  this process, for a headless machine: open ``http://HOST:WEB_PORT`` in a browser (forward the two
  ports over SSH). The server lives as long as the command; ``serve`` waits for Ctrl-C
  after the work is done so the recording stays viewable.

:class:`LiveReplay` logs each refresh of a replay (occupancy, Voronoi graph, rooms, the
scene graph as points and as a graph view, the robot's position), each decision of a
closed-loop run (the graph, the robot, the action) or each frame of a recording (camera
images, robot, path), on the ``frame`` and ``sim_time`` timelines, with the default
blueprint of :mod:`sgtool.analysis.rerun_view`. A replay of a log is shown on the
timelines ``sgtool view`` gives that log (it shares their recording id): ``frame`` the
index of the last camera frame a refresh integrated, ``sim_time`` log time since the
log's first message. A recording's frames carry their own index and time; a closed-loop
run's decisions are counted on ``frame``.
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from sgtool.analysis.rerun_view import (
    RobotPath,
    _log_scene_graph,
    _scene_update_strips,
    blueprint,
    frame_at,
    log_camera,
    log_labels,
    new_stream,
)
from sgtool.errors import SgtoolError

GRPC_PORT = 9876
WEB_PORT = 9090
DEFAULT_CONNECT = f"rerun+http://127.0.0.1:{GRPC_PORT}/proxy"
FLUSH_S = 30.0  # the longest a finished command waits for its stream to reach the viewer


def log_clock(log: Any) -> tuple[list[int], int]:
    """(camera frame times, first message's time) of the log at ``log``: what puts a live
    replay's refreshes on the timelines ``sgtool view`` gives that log."""
    from sgtool.log import LogReader
    from sgtool.log import schemas as S

    with LogReader(log) as r:
        tr = r.time_range()
        return (r.frame_times() if r.has(S.DEPTH) else []), (tr[0] if tr else 0)


@dataclass(frozen=True)
class LiveTarget:
    """Where a live recording goes: ``mode`` (spawn, connect, serve), the viewer ``url``
    for connect, the HTTP ``web_port`` and gRPC ``grpc_port`` for serve."""

    mode: str
    url: str = DEFAULT_CONNECT
    web_port: int = WEB_PORT
    grpc_port: int = GRPC_PORT


def parse_target(text: str, option: str = "--rerun") -> LiveTarget:
    """``spawn``, ``connect[:URL]``, ``serve[:WEB_PORT[:GRPC_PORT]]`` (module doc); a bare
    ``rerun+http://...`` URL means connect. Anything else is one line."""
    mode, sep, arg = text.partition(":")
    if text.startswith("rerun+http") or text.startswith("rerun://"):
        return LiveTarget("connect", url=text)
    if mode == "spawn" and not sep:
        return LiveTarget("spawn")
    if mode == "connect":
        return LiveTarget("connect", url=arg or DEFAULT_CONNECT)
    if mode == "serve":
        if not sep:
            return LiveTarget("serve")
        ports = arg.split(":")
        if len(ports) <= 2 and all(p.isdigit() and 0 < int(p) < 65536 for p in ports):
            web = int(ports[0])
            return LiveTarget("serve", web_port=web,
                              grpc_port=int(ports[1]) if len(ports) == 2 else GRPC_PORT)
        raise SgtoolError(f"{option} {text}: give serve:WEB_PORT or serve:WEB_PORT:GRPC_PORT "
                          "with port numbers 1..65535")
    raise SgtoolError(f"{option} {text!r}: give spawn, connect[:URL] or "
                      "serve[:WEB_PORT[:GRPC_PORT]]")


def has_display() -> bool:
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def viewer_address(url: str) -> tuple[str, int]:
    """(host, port) of a viewer URL (``rerun+http://HOST:PORT/proxy``, ``rerun://...``;
    the port :data:`GRPC_PORT` when it names none)."""
    from urllib.parse import urlsplit

    parts = urlsplit(url.replace("rerun+", "", 1))
    try:
        port = parts.port
    except ValueError:
        port = None
    return parts.hostname or "127.0.0.1", port or GRPC_PORT


def check_target(target: LiveTarget, option: str = "--rerun", probe_s: float = 2.0) -> None:
    """Refuse in one line what cannot work here: spawning without a display or without
    the ``rerun`` viewer on PATH (naming ``serve`` for a headless machine), connecting to
    a viewer that does not answer on its port within ``probe_s`` seconds (the stream
    would fail, or wait without end, only after the work)."""
    if target.mode == "connect":
        import socket

        host, port = viewer_address(target.url)
        try:
            socket.create_connection((host, port), timeout=probe_s).close()
        except OSError:
            raise SgtoolError(f"{option} connect: no Rerun viewer answers at {target.url}; "
                              f"start `rerun` there first, or use {option} serve or write a "
                              "file") from None
        return
    if target.mode != "spawn":
        return
    if not has_display():
        raise SgtoolError(f"{option} spawn: no display to open the Rerun viewer on; on a "
                          f"headless machine use {option} serve (a web viewer on port "
                          f"{WEB_PORT}) or write a file")
    if shutil.which("rerun") is None:
        raise SgtoolError(f"{option} spawn: the `rerun` viewer is not on PATH; use "
                          f"{option} serve or write a file")


def open_stream(target: LiveTarget, recording_id: str) -> tuple[Any, str | None]:
    """A Rerun recording stream sent to ``target`` with the default blueprint, and for
    serve the web viewer's address to tell the user."""
    import rerun as rr

    check_target(target)
    rec = new_stream(recording_id)
    bp = blueprint()
    where = None
    if target.mode == "spawn":
        rec.spawn(default_blueprint=bp)
    elif target.mode == "connect":
        rec.connect_grpc(target.url, default_blueprint=bp)
    else:
        url = rec.serve_grpc(grpc_port=target.grpc_port, default_blueprint=bp)
        rr.serve_web_viewer(web_port=target.web_port, open_browser=False, connect_to=url)
        where = f"http://localhost:{target.web_port}/?url={url}"
    return rec, where


class LiveReplay:
    """Logs a replay's refreshes to a live recording (module doc): pass :meth:`refresh`
    (or :meth:`chain`) as ``replay``'s ``on_refresh``, then call :meth:`finish`."""

    def __init__(self, rec: Any, target: LiveTarget | None = None,
                 frame_times: Sequence[int] = (), start_ns: int = 0) -> None:
        """``frame_times`` and ``start_ns``: the camera frames' times and the first
        message's time of the log being replayed (none: refreshes are counted on
        ``frame`` and ``sim_time`` is their time)."""
        import rerun as rr

        self.rec = rec
        self.target = target
        self.frame_times = list(frame_times)
        self.start_ns = int(start_ns)
        self.refreshes = 0
        self.path = RobotPath()
        self._instances: Any = None  # the instance table the segmentation is labelled by
        self._dense: np.ndarray | None = None
        rec.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)

    @classmethod
    def start(cls, text: str, source: Any, echo: Callable[[str], None]) -> LiveReplay:
        """Parse ``--rerun TEXT``, open the stream and tell the user where to look through
        ``echo``. The recording id comes from ``source``: a log's bytes (a path to an
        existing file), else the text given (a run's description)."""
        import hashlib
        from pathlib import Path

        from sgtool.analysis.rerun_view import recording_id

        target = parse_target(text)
        rid = (recording_id(Path(source)) if Path(str(source)).is_file()
               else hashlib.sha256(str(source).encode()).hexdigest()[:32])
        clock = log_clock(Path(source)) if Path(str(source)).is_file() else ([], 0)
        rec, where = open_stream(target, rid)
        if where is not None:
            echo(f"rerun: web viewer at {where} (gRPC port {target.grpc_port})")
        return cls(rec, target, *clock)

    def chain(self, other: Callable[[Any, Any], None] | None) -> Callable[[Any, Any], None]:
        """An ``on_refresh`` that logs the refresh and then calls ``other`` (if any)."""
        def both(ref: Any, stream: Any) -> None:
            self.refresh(ref, stream)
            if other is not None:
                other(ref, stream)
        return both

    def finish(self, echo: Callable[[str], None], wait: Callable[[], None] | None = None
               ) -> None:
        """Flush; for serve, keep serving until Ctrl-C (``wait``: how to wait, by default
        sleeping until a KeyboardInterrupt) so the recording stays viewable."""
        import time

        self.close()
        if self.target is None or self.target.mode != "serve":
            return
        echo("rerun: done; still serving the recording, press Ctrl-C to stop")
        try:
            if wait is not None:
                wait()
            else:
                while True:
                    time.sleep(1.0)
        except KeyboardInterrupt:
            pass

    def refresh(self, ref: Any, stream: Any) -> None:
        import rerun as rr

        from sgtool.log import codec
        from sgtool.scenegraph.derived_layers import (
            occupancy_message,
            rooms_message,
            voronoi_message,
        )

        rec = self.rec
        frame = frame_at(self.frame_times, int(ref.time_ns))
        rr.set_time("frame", sequence=self.refreshes if frame is None else frame,
                    recording=rec)
        rr.set_time("sim_time", duration=np.timedelta64(int(ref.time_ns) - self.start_ns, "ns"),
                    recording=rec)
        self.refreshes += 1
        grid = occupancy_message(ref)
        if grid is not None:
            cells, origin, res = codec.decode_grid(grid)
            h, w = cells.shape
            rec.log("world/map/occupancy", rr.GridMap(
                data=cells.tobytes(), format=rr.components.ImageFormat(
                    width=w, height=h, color_model="L", channel_datatype="U8"),
                cell_size=res, translation=[origin[0], origin[1], -0.01],
                colormap=rr.components.Colormap.RvizMap))
        for entity, make in (("world/map/voronoi", voronoi_message),
                             ("world/map/rooms", rooms_message)):
            upd = make(ref)
            if upd is not None:
                strips, colors = _scene_update_strips(upd)
                rec.log(entity, rr.LineStrips3D(strips, colors=colors, radii=0.02)
                        if strips else rr.Clear(recursive=False))
        g = ref.graph.to_dict()
        _log_scene_graph(rec, g)
        self._robot(g)

    def frame(self, fr: Any, instances: Any = None) -> None:
        """A recorded frame: the camera (pose, pinhole, RGB, depth, segmentation) and the
        robot with its path, at the frame's index and time. ``instances``: the instance
        table in force (an ``sgtool.Instances``), whose categories label the segmentation
        when it changes."""
        import rerun as rr

        if instances is not None and instances is not self._instances:
            self._instances = instances
            self._dense = log_labels(self.rec, {int(i.id): i.category
                                                for i in instances.instances})
        rr.set_time("frame", sequence=int(fr.index), recording=self.rec)
        rr.set_time("sim_time", duration=np.timedelta64(int(fr.time_ns), "ns"),
                    recording=self.rec)
        log_camera(self.rec, fr, self._dense)
        self.path.log(self.rec, self.path.add(fr))

    def observer(self) -> Any:
        """A simulation observer that shows each frame the log recorder has just written
        (pass it to ``record_house``'s ``observers``, after the recorder)."""
        from sgtool.recorders.sim.events import SimObserver
        from sgtool.recorders.sim.recording import LogRecorder

        live = self

        class Frames(SimObserver):
            def __init__(self) -> None:
                self.last: Any = None

            def on_tick(self, sim: Any) -> None:
                rec = next((o for o in sim.observers if isinstance(o, LogRecorder)), None)
                fr = rec.last_frame if rec is not None else None
                if fr is not None and fr is not self.last:
                    self.last = fr
                    live.frame(fr, rec.last_instances if rec is not None else None)

        return Frames()

    def decision(self, graph: Any, action: Any) -> None:
        """A closed-loop decision (``run_episode``'s ``on_decision``): the scene graph it
        was made on, the robot and the action chosen, at the graph's time."""
        import rerun as rr

        g = graph.to_dict()
        t = int(g.get("time_ns") or 0)
        rr.set_time("frame", sequence=self.refreshes, recording=self.rec)
        rr.set_time("sim_time", duration=np.timedelta64(t, "ns"), recording=self.rec)
        self.refreshes += 1
        _log_scene_graph(self.rec, g)
        self._robot(g)
        text = f"{action.skill}({action.target or ''})"
        if action.reason:
            text += f": {action.reason}"
        self.rec.log("actions", rr.TextLog(text, level="INFO"))

    def _robot(self, g: dict[str, Any]) -> None:
        import rerun as rr

        robot = g.get("robot") or {}
        if robot.get("position"):
            x, y = robot["position"][:2]
            self.rec.log("world/robot", rr.Points3D([(x, y, 0.02)], radii=0.15,
                                                    colors=[(230, 80, 40)]))

    def close(self) -> None:
        """Flush the stream: a viewer lost on the way is one line, and a flush that cannot
        finish stops waiting after :data:`FLUSH_S` seconds."""
        try:
            self.rec.flush(timeout_sec=FLUSH_S)
        except Exception as e:  # noqa: BLE001 - Rerun's own error types (a lost viewer,
            # a timeout) are not part of its API; each is one line here
            where = self.target.url if self.target is not None else "the viewer"
            raise SgtoolError(f"--rerun: the stream to {where} did not finish within "
                              f"{FLUSH_S:g} s or lost its viewer "
                              f"({str(e).splitlines()[0] if str(e) else type(e).__name__})"
                              ) from None
