"""A transform tree over time, as ``tf2`` keeps it: resolve a frame's pose in another frame
at a given time, interpolating each dynamic link between its samples.

Links come from ``/tf`` (dynamic, time-stamped by each ``TransformStamped`` header) and
``/tf_static`` (constant). A lookup walks from both frames up to their common ancestor and
composes ``root_T_target = inv(ancestor_T_root) @ ancestor_T_target``; it fails (None) when
the frames are not connected or a dynamic link has no sample near the time (no
extrapolation beyond the track's tolerance). Frame names are normalised without a leading
``/`` (ROS 1 bags often write ``/world``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sgtool.log.poses import PoseTrack


def frame_name(name: str) -> str:
    return str(name).lstrip("/")


@dataclass(frozen=True)
class Link:
    parent: str
    static: np.ndarray | None  # parent_T_child for a static link
    track: PoseTrack | None  # parent_T_child over time for a dynamic link

    def at(self, t_ns: int) -> np.ndarray | None:
        if self.static is not None:
            return self.static
        assert self.track is not None
        return self.track.at(t_ns)


class TfTree:
    """Collect transforms with :meth:`add`, then :meth:`freeze` and look them up."""

    def __init__(self, *, max_gap_ns: int = 500_000_000, tolerance_ns: int = 50_000_000) -> None:
        self.max_gap_ns = max_gap_ns
        self.tolerance_ns = tolerance_ns
        self._static: dict[str, tuple[str, np.ndarray]] = {}
        self._samples: dict[str, tuple[str, list[tuple[int, np.ndarray]]]] = {}
        self.reparented: set[str] = set()
        self.links: dict[str, Link] = {}

    def add(self, parent: str, child: str, t_ns: int, T: np.ndarray, *, static: bool) -> None:  # noqa: N803
        parent, child = frame_name(parent), frame_name(child)
        if static:
            self._static[child] = (parent, np.asarray(T, dtype=np.float64))
            return
        cur = self._samples.get(child)
        if cur is None or cur[0] != parent:
            if cur is not None:
                self.reparented.add(child)  # a frame that changed parent: the last one wins
            cur = (parent, [])
            self._samples[child] = cur
        cur[1].append((int(t_ns), np.asarray(T, dtype=np.float64)))

    def freeze(self) -> TfTree:
        links: dict[str, Link] = {}
        for child, (parent, samples) in self._samples.items():
            links[child] = Link(parent, None, PoseTrack.from_samples(
                samples, max_gap_ns=self.max_gap_ns, tolerance_ns=self.tolerance_ns))
        for child, (parent, T) in self._static.items():  # noqa: N806
            links[child] = Link(parent, T, None)  # static wins, as in tf2
        self.links = links
        return self

    # ----- structure --------------------------------------------------------------------
    def frames(self) -> list[str]:
        names = set(self.links)
        names.update(link.parent for link in self.links.values())
        return sorted(names)

    def ancestors(self, frame: str) -> list[str]:
        """``frame`` and its ancestors up to the root."""
        out = [frame_name(frame)]
        while out[-1] in self.links and len(out) < 64:
            nxt = self.links[out[-1]].parent
            if nxt in out:
                break  # a cycle in a broken bag
            out.append(nxt)
        return out

    def root_of(self, frame: str) -> str:
        return self.ancestors(frame)[-1]

    def roots(self) -> list[str]:
        return sorted({self.root_of(f) for f in self.frames()})

    def path(self, root: str, target: str) -> tuple[list[str], list[str]] | None:
        """(links up from target to the common ancestor, links up from root to it), or
        None when the frames are not connected."""
        up_t = self.ancestors(target)
        up_r = self.ancestors(root)
        common = next((f for f in up_t if f in up_r), None)
        if common is None:
            return None
        return up_t[: up_t.index(common)], up_r[: up_r.index(common)]

    def describe(self) -> list[str]:
        lines = []
        for child in sorted(self.links):
            link = self.links[child]
            kind = "static" if link.static is not None else f"{len(link.track or ())} samples"
            lines.append(f"{link.parent} -> {child} ({kind})")
        return lines

    def sample_times(self, root: str, target: str) -> list[int]:
        """Times of the dynamic link samples on the path (where the pose is measured)."""
        p = self.path(root, target)
        if p is None:
            return []
        times: set[int] = set()
        for child in p[0] + p[1]:
            track = self.links[child].track
            if track is not None:
                times.update(track.times)
        return sorted(times)

    # ----- lookup -----------------------------------------------------------------------
    def _to_ancestor(self, chain: list[str], t_ns: int) -> np.ndarray | None:
        T = np.eye(4)  # noqa: N806
        for child in chain:
            M = self.links[child].at(t_ns)  # noqa: N806
            if M is None:
                return None
            T = M @ T  # noqa: N806
        return T

    def lookup(self, root: str, target: str, t_ns: int) -> np.ndarray | None:
        """root_T_target at ``t_ns`` (the pose of ``target`` in ``root``) or None."""
        p = self.path(frame_name(root), frame_name(target))
        if p is None:
            return None
        a_t = self._to_ancestor(p[0], t_ns)
        a_r = self._to_ancestor(p[1], t_ns)
        if a_t is None or a_r is None:
            return None
        return np.linalg.inv(a_r) @ a_t
