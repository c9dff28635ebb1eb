"""The refresh schedule of scene-graph building, shared by replay and the live closed loop.

:class:`SceneGraphStream` wraps a :class:`~sgtool.scenegraph.builder.SceneGraphBuilder` and
is fed the events of a log in the order they were written:

- :meth:`~SceneGraphStream.instances`: a new ``sgtool.Instances`` table (a door or a
  container changed state: the builder drops that instance's voxels);
  :meth:`~SceneGraphStream.instance_table` takes it already read;
- :meth:`~SceneGraphStream.frame`: a camera frame, integrated into the voxel map; every
  ``every`` frames the graph layers refresh (reason ``"every"``);
- :meth:`~SceneGraphStream.action`: an ``sgtool.Action`` record: the graph refreshes now
  (reason ``"action"``), so there is a graph for every decision point;
- :meth:`~SceneGraphStream.finish`: the end of the log: a last refresh when anything was
  integrated since the previous one (reason ``"end"``).

A refresh that would see nothing new (no frame and no instance change since the last one)
is not repeated: :meth:`action` then returns ``None`` and :attr:`current` stays the graph
in force. The room and frontier ids of the builder are history (they follow the previous
refresh), so two consumers get the same graphs exactly when they call the same methods in
the same order with the same frames; replay (:mod:`sgtool.replayers.derived_log`) and the live
closed loop both go through this class, and the closed loop feeds it frames as the log
will hold them (:func:`sgtool.log.echo.as_logged`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Literal

from sgtool.log.frame import Frame
from sgtool.log.records import Instances
from sgtool.scenegraph.builder import BuilderConfig, MapLayers, SceneGraphBuilder
from sgtool.scenegraph.categories import RoomClassifier
from sgtool.scenegraph.graph import SceneGraph
from sgtool.scenegraph.instances import InstanceInfo, instances_from_record

Reason = Literal["every", "action", "end"]


@dataclass(frozen=True, eq=False)
class Refresh:
    """One refresh: the graph and the map layers it was built from."""

    index: int  # 0, 1, ... in the order of refreshes
    time_ns: int
    frames: int  # frames integrated so far
    reason: Reason
    graph: SceneGraph
    layers: MapLayers | None = field(repr=False)  # grids and arrays: too big to print


class SceneGraphStream:
    """Feeds a builder in log order and refreshes on schedule (module doc)."""

    def __init__(self, instances: Mapping[int, InstanceInfo] | None = None,
                 classifier: RoomClassifier | None = None,
                 config: BuilderConfig | None = None) -> None:
        self.builder = SceneGraphBuilder(instances, classifier, config)
        self.count = 0  # refreshes so far
        self.frames = 0
        self._current: Refresh | None = None
        self._dirty = False
        self._last_time = 0

    @property
    def config(self) -> BuilderConfig:
        return self.builder.config

    @property
    def current(self) -> Refresh | None:
        """The last refresh (None before the first)."""
        return self._current

    def instances(self, t_ns: int, record: Instances) -> list[int]:
        """A new instance table (an ``sgtool.Instances`` record); returns the instances whose
        state changed."""
        return self.instance_table(t_ns, instances_from_record(record.to_json()))

    def instance_table(self, t_ns: int, table: Mapping[int, InstanceInfo]) -> list[int]:
        """:meth:`instances` of the table already read
        (:func:`~sgtool.scenegraph.instances.instances_from_record` of the record's JSON
        form, e.g. the one the log writer returned when it wrote it)."""
        first = not self.builder.instances
        changed = self.builder.set_instances(table)
        if changed or (first and self.frames):
            self._dirty = True
        return changed

    def frame(self, frame: Frame) -> Refresh | None:
        """Integrate ``frame``; the refresh when ``every`` frames have passed, else None."""
        self.builder.integrate(frame)
        self.frames += 1
        self._dirty = True
        self._last_time = int(frame.time_ns)
        if self.builder.due():
            return self._refresh(int(frame.time_ns), "every")
        return None

    def action(self, t_ns: int) -> Refresh | None:
        """An action was logged at ``t_ns``: refresh now, unless nothing is new."""
        if not self._dirty:
            return None
        return self._refresh(max(int(t_ns), self._last_time), "action")

    def finish(self, t_ns: int | None = None) -> Refresh | None:
        """The log ended: a last refresh when anything is new."""
        if not self._dirty:
            return None
        return self._refresh(max(int(t_ns or 0), self._last_time), "end")

    def _refresh(self, t_ns: int, reason: Reason) -> Refresh:
        graph = self.builder.refresh(t_ns)
        r = Refresh(self.count, t_ns, self.frames, reason, graph, self.builder.layers)
        self.count += 1
        self._current = r
        self._dirty = False
        return r
