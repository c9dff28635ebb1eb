"""Sparse semantic voxel map: packed int64 keys of (voxel, label) with vote counts.

MoMa-LLM fuses posed RGB-D frames with ground-truth semantics into a dense 0.075 m voxel
grid over 30 m (400^3 float32, ~256 MB; paper sec. III-B "Dynamic RGB-D mapping"). A house
occupies a tiny share of such a cube, so we keep only observed voxels: every back-projected
point becomes the key ``(ix, iy, iz, label)`` packed into one int64 (17 bits per axis,
offset by 2^16 so negative indices fit: +-3.2 km at 5 cm; 12 label bits), and the map is
the sorted array of distinct keys with the number of points that voted for each (and the
number of frames that did: :meth:`VoxelMap.frame_counts`). A voxel may carry votes for
several labels; its label is the one with most votes. Sorting puts
the keys of one (x, y) column next to each other, ordered by height, which is what the
bird's-eye view needs (:mod:`sgtool.mapping.bev`).

Labels are compact indices (1, 2, ... in order of first appearance; 0 = no instance) of
the instance ids of the frames, so ids of any size fit in 12 bits; more than 4,094
distinct instances share the overflow label 4,095 (geometry stays right, their semantics
are merged).

Integration (:meth:`VoxelMap.integrate`): valid depth in ``[min_range, max_range)``
(MoMa-LLM: 0-5 m), less the mixed pixels between two surfaces
(:mod:`sgtool.mapping.mixed_pixels`, unless ``mixed_pixels`` is off), is back-projected
with the intrinsics, moved to the world by the pose,
quantised and packed (a frame with points beyond the packing's range, or not finite, is
refused with :class:`~sgtool.mapping.backproject.MapRangeError`: never dropped silently;
the per-frame bound on the pose, :func:`~sgtool.mapping.backproject.within_packing`,
spares valid frames the per-point range); the frame's distinct keys with counts are kept
aside and merged into the map every few frames (one ``searchsorted`` + ``insert`` for
many frames, into a small sorted tail merged into the big array now and then:
:mod:`sgtool.mapping.vote_store`).
Per instance the map also keeps what the scene graph needs without scanning the voxels:
the points per frame (an object counts as *seen* when one frame shows it with at least
``min_points`` points; MoMa-LLM: > 50), the closest viewpoint it was seen from (MoMa-LLM
keeps the closest viewpoint per object, used by the object-to-room cost), and the number
and integer index sums of its voxels (its centroid, exact and independent of merge
batching).

Dynamic scenes: a door or a drawer that changes state leaves its old voxels behind;
:meth:`VoxelMap.forget_instance` drops every vote of an instance so that it is rebuilt
from the frames that follow (the scene-graph builder calls it when the instance table
reports a new state). Labels are votes over frames: a frame that dropped the instance's
label (id 0) or swapped it (another id) voted its voxels under another label, so the
instance takes along every voxel it *wins* (most votes, as :meth:`VoxelMap.voxels`) with
all the votes in it, not only its own label's entries. Free-space evidence from the
robot's body (:meth:`VoxelMap.clear_unlabelled_around`) drops the voxels that never had an
instance's label where the robot stood; free-space evidence from depth
(:meth:`VoxelMap.clear_seen_through`, :mod:`sgtool.mapping.free_space`) drops the weak
voxels that later views saw through.

Everything is exact integer arithmetic after the float64 back-projection (elementwise, no
BLAS; :mod:`sgtool.mapping.backproject` runs it in cache blocks, operation for operation),
so the same frames give the same map bit for bit. A frame's keys are counted by
:func:`sgtool.mapping.key_count.count_keys` (runs of equal neighbours collapsed first).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from sgtool.log.frame import CameraIntrinsics, Frame
from sgtool.mapping.backproject import Scratch, beyond_packing, within_packing, world_voxels
from sgtool.mapping.free_space import FreeSpaceConfig, View, seen_through
from sgtool.mapping.key_count import count_keys
from sgtool.mapping.label_stats import InstanceObservation, LabelStats, update_frame
from sgtool.mapping.mixed_pixels import mixed_pixels
from sgtool.mapping.vote_store import VoteStore, drain_keys, sorted_unique, spans
from sgtool.mapping.voxel_keys import (  # the key layout (callers import it from here too)
    AXIS_BITS,
    AXIS_MASK,
    COLUMN_SHIFT,
    LABEL_MASK,
    OFFSET,
    OVERFLOW_LABEL,
    SHIFT_X,
    SHIFT_Y,
    SHIFT_Z,
    VOXEL_SHIFT,
    pack,
    unpack,
    voxel_bounds,
    winning_entries,
)

_LUT_MAX = 1 << 22  # instance ids below this use a lookup table, above it np.unique
DENSE_SHARE = 0.875  # frames with this share of valid pixels are computed in place
_DROPPED = (1 << 63) - 1  # key of a discarded pixel: no voxel in the packing's range has it


@dataclass(frozen=True)
class VoxelConfig:
    resolution: float = 0.05  # m
    min_range: float = 0.1  # m; closer depth is ignored
    max_range: float = 5.0  # m; farther depth is ignored (MoMa-LLM: 0-5 m)
    min_points: int = 50  # an instance counts as seen with this many points in one frame
    flush_keys: int = 150_000  # merge pending frame keys into the map beyond this many
    mixed_pixels: bool = True  # leave out depth pixels between two surfaces (mixed_pixels)


class VoxelMap:
    """The sparse semantic voxel map (module doc). Not thread-safe."""

    def __init__(self, config: VoxelConfig | None = None) -> None:
        self.config = config or VoxelConfig()
        self._store = VoteStore()  # the sorted keys and counts, in two levels
        self._frames = VoteStore()  # the same keys, the number of frames that voted each
        self._pending: list[tuple[np.ndarray, np.ndarray]] = []
        self._pending_n = 0
        self._label_ids: list[int] = [0]  # label index -> instance id
        self._label_of: dict[int, int] = {0: 0}  # instance id -> label index
        self._lut = np.zeros(1, dtype=np.int64)  # instance id -> label index (ids < _LUT_MAX)
        self._stats = LabelStats()
        self._stats.grow(1)
        self._scratch = Scratch()
        self._rays: dict[tuple[int, int, float, float, float, float],
                         tuple[np.ndarray, np.ndarray]] = {}
        self.version = 0  # bumped whenever the voxels change
        self.removals = 0  # bumped by forget_instance (maps derived incrementally rebuild)
        self._new_keys: list[np.ndarray] = []  # entries new since the last drain
        self._removed_keys: list[np.ndarray] = []  # entries removed since the last drain
        self._zhist = np.zeros(1 << AXIS_BITS, dtype=np.int64)  # entries per height level
        # free-space evidence (clear_seen_through): entries new since its last call, and
        # the weak voxels it watches (sorted voxel keys) with their misses
        self._unwatched: list[np.ndarray] = []
        self._weak = np.zeros(0, dtype=np.int64)
        self._misses = np.zeros(0, dtype=np.int64)

    # ----- integration ------------------------------------------------------------------
    def _ray_table(self, k: CameraIntrinsics, h: int, w: int) -> tuple[np.ndarray, np.ndarray]:
        key = (h, w, k.fx, k.fy, k.cx, k.cy)
        t = self._rays.get(key)
        if t is None:
            u = (np.arange(w, dtype=np.float64) - k.cx) / k.fx
            v = (np.arange(h, dtype=np.float64) - k.cy) / k.fy
            t = (np.tile(u, h), np.repeat(v, w))
            self._rays[key] = t
        return t

    def labels_of(self, ids: np.ndarray) -> np.ndarray:
        """Label indices of instance ids (new ids get the next indices, in sorted order)."""
        ids = ids if ids.dtype.kind in "iu" else ids.astype(np.int64)  # ints index as they are
        if ids.size == 0:
            return np.zeros(0, dtype=np.int64)
        lo, hi = int(ids.min()), int(ids.max())
        if lo >= 0 and hi < _LUT_MAX:
            if hi >= len(self._lut):
                self._lut = np.concatenate(
                    [self._lut, np.full(max(hi + 1, 2 * len(self._lut)) - len(self._lut), -1)]
                )
            lab = self._lut[ids]
            if (lab < 0).any():
                for i in np.unique(ids[lab < 0]).tolist():
                    self._new_label(int(i))
                lab = self._lut[ids]
            return lab
        uniq, inv = np.unique(ids, return_inverse=True)
        out = np.empty(len(uniq), dtype=np.int64)
        for j, i in enumerate(uniq.tolist()):
            out[j] = self._label_of[i] if i in self._label_of else self._new_label(i)
        return out[inv]

    def _new_label(self, instance_id: int) -> int:
        if instance_id in self._label_of:
            return self._label_of[instance_id]
        idx = len(self._label_ids)
        if idx >= OVERFLOW_LABEL:
            idx = OVERFLOW_LABEL
            self._stats.grow(OVERFLOW_LABEL + 1)
        else:
            self._label_ids.append(instance_id)
            self._stats.grow(idx + 1)
        self._label_of[instance_id] = idx
        if 0 <= instance_id < _LUT_MAX:
            if instance_id >= len(self._lut):
                grow = max(instance_id + 1, 2 * len(self._lut)) - len(self._lut)
                self._lut = np.concatenate([self._lut, np.full(grow, -1)])
            self._lut[instance_id] = idx
        return idx

    def integrate(self, frame: Frame, viewpoint: tuple[float, float] | None = None) -> int:
        """Fuse one frame; returns the number of points used. ``viewpoint`` (x, y) is where
        the robot stood (default: the base pose if the frame has one, else the camera)."""
        depth = np.asarray(frame.depth)
        h, w = depth.shape
        ru, rv = self._ray_table(frame.intrinsics, h, w)
        d = depth.reshape(-1)
        cfg = self.config
        with np.errstate(invalid="ignore"):
            valid = (d >= cfg.min_range) & (d < cfg.max_range)
        if cfg.mixed_pixels:
            valid &= ~mixed_pixels(depth).reshape(-1)
        if viewpoint is None:
            src = frame.base_pose if frame.base_pose is not None else frame.pose
            viewpoint = (float(src[0, 3]), float(src[1, 3]))
        n_ok = int(np.count_nonzero(valid))
        if n_ok == 0:
            return 0
        inv, lim = 1.0 / cfg.resolution, OFFSET - 1
        safe = within_packing(frame.pose, ru, rv, cfg.max_range, inv, lim)
        if safe and n_ok >= DENSE_SHARE * d.size:  # nearly every pixel: no gathers
            self._integrate_dense(d, valid, ru, rv, frame, viewpoint)
            return n_ok
        idx = np.flatnonzero(valid)
        wx, wy, _, keys, rng = world_voxels(d, idx, ru, rv, frame.pose, inv,
                                            (SHIFT_X, SHIFT_Y, SHIFT_Z), OFFSET, self._scratch,
                                            need_range=not safe)
        if not (safe or all(-lim < v < lim for v in rng)):  # out of the packing, NaN
            raise beyond_packing(f"frame {frame.index} at {frame.time_ns / 1e9:.3f} s",
                                 frame.pose, cfg.resolution, lim)
        if frame.ids is not None:
            lab = self.labels_of(np.asarray(frame.ids).reshape(-1)[idx])
        else:
            lab = np.zeros(idx.size, dtype=np.int64)
        np.add(keys, lab, out=keys)
        return self._count(keys, wx, wy, lab, viewpoint, frame.index)

    def _integrate_dense(self, d: np.ndarray, valid: np.ndarray, ru: np.ndarray,
                         rv: np.ndarray, frame: Frame, viewpoint: tuple[float, float]) -> None:
        """:meth:`integrate` of a frame whose points are within the packing, computed for
        every pixel in place: the invalid ones get id 0 (label 0, whose sums are never
        read) and the key ``_DROPPED``, which the counting leaves out. The valid pixels get
        the same bits, labels and counts as through the gathers."""
        bad = np.flatnonzero(~valid)
        cfg = self.config
        with np.errstate(invalid="ignore", over="ignore"):  # NaN, inf of invalid pixels
            wx, wy, _, keys, _ = world_voxels(d, None, ru, rv, frame.pose, 1.0 / cfg.resolution,
                                              (SHIFT_X, SHIFT_Y, SHIFT_Z), OFFSET,
                                              self._scratch, need_range=False)
        if frame.ids is not None:
            ids = np.asarray(frame.ids).reshape(-1)
            if bad.size:
                ids = ids.copy()
                ids[bad] = 0
            lab = self.labels_of(ids)
            np.add(keys, lab, out=keys)
        else:
            lab = np.zeros(d.size, dtype=np.int64)
        keys[bad] = _DROPPED
        self._count(keys, wx, wy, lab, viewpoint, frame.index, drop=_DROPPED)

    def integrate_points(self, xyz: np.ndarray, labels: np.ndarray,
                         viewpoint: tuple[float, float], frame_index: int = -1) -> int:
        """Fuse world points (N, 3) float64 with label indices (from :meth:`labels_of`)."""
        xyz = np.asarray(xyz, dtype=np.float64)
        return self._fuse(np.ascontiguousarray(xyz[:, 0]), np.ascontiguousarray(xyz[:, 1]),
                          np.ascontiguousarray(xyz[:, 2]), np.asarray(labels, np.int64),
                          viewpoint, frame_index)

    def _fuse(self, wx: np.ndarray, wy: np.ndarray, wz: np.ndarray, labels: np.ndarray,
              viewpoint: tuple[float, float], frame_index: int) -> int:
        """Quantise, pack and count one frame's world points (module doc)."""
        inv = 1.0 / self.config.resolution
        vx = np.floor(wx * inv).astype(np.int64)
        vy = np.floor(wy * inv).astype(np.int64)
        vz = np.floor(wz * inv).astype(np.int64)
        lim = OFFSET - 1
        if vx.size and not all(-lim < int(a.min()) and int(a.max()) < lim
                               for a in (vx, vy, vz)):  # out of the packing, NaN
            raise beyond_packing(f"frame {frame_index}", None, self.config.resolution, lim)
        if vx.size == 0:
            return 0
        return self._count(pack(vx, vy, vz, labels), wx, wy, labels, viewpoint, frame_index)

    def _count(self, keys: np.ndarray, wx: np.ndarray, wy: np.ndarray, labels: np.ndarray,
               viewpoint: tuple[float, float], frame_index: int, drop: int | None = None
               ) -> int:
        """Count one frame's packed keys into the pending list and its statistics (keys
        equal to ``drop`` left out)."""
        uk, cnt = count_keys(keys, drop)
        self._pending.append((uk, cnt))
        self._pending_n += len(uk)
        # points per label from the distinct keys (far fewer than the points)
        lab_u = uk & LABEL_MASK
        pts = np.bincount(lab_u, weights=cnt).astype(np.int64)
        n_lab = max(len(self._label_ids), len(pts))

        def voxel_means() -> tuple[np.ndarray, np.ndarray]:
            """Mean voxel centre (x, y) per label index, weighted by points."""
            n = np.maximum(np.bincount(lab_u, weights=cnt, minlength=n_lab), 1.0)
            res = self.config.resolution

            def mean(sh: int) -> np.ndarray:
                return np.bincount(lab_u, weights=cnt * (((uk >> sh) & AXIS_MASK)
                                                         - (OFFSET - 0.5)),
                                   minlength=n_lab) * res / n

            return mean(SHIFT_X), mean(SHIFT_Y)

        update_frame(self._stats, pts, voxel_means, labels, wx, wy, n_lab, viewpoint,
                     frame_index, self.config.min_points, self.config.resolution)
        if self._pending_n >= self.config.flush_keys:
            self.flush()
        self.version += 1
        return int(keys.size)

    def flush(self) -> None:
        """Merge the pending frame keys into the sorted map."""
        if not self._pending:
            return
        if len(self._pending) == 1:
            uk, cnt = self._pending[0]
            frames = np.ones(len(uk), dtype=np.int64)
        else:
            keys = np.concatenate([p[0] for p in self._pending])
            counts = np.concatenate([p[1] for p in self._pending])
            order = np.argsort(keys, kind="stable")
            keys, counts = keys[order], counts[order]
            starts = np.flatnonzero(np.concatenate([[True], keys[1:] != keys[:-1]]))
            uk = keys[starts]
            cnt = np.add.reduceat(counts, starts)
            frames = np.diff(np.append(starts, len(keys)))  # a frame's keys are distinct
        self._pending.clear()
        self._pending_n = 0
        nk = self._store.add(uk, cnt)
        self._frames.add(uk, frames)
        if len(nk):
            self._voxel_stats(nk, +1)
            self._new_keys.append(nk)
            self._unwatched.append(nk)
            self._zhist += np.bincount((nk >> SHIFT_Z) & AXIS_MASK, minlength=1 << AXIS_BITS)

    def _voxel_stats(self, keys: np.ndarray, sign: int) -> None:
        ix, iy, iz, lab = unpack(keys)
        st = self._stats
        m = max(len(self._label_ids), int(lab.max()) + 1 if lab.size else 0)
        st.grow(m)
        st.vox_n[:m] += sign * np.bincount(lab, minlength=m)[:m]
        for a, col in ((ix, 0), (iy, 1), (iz, 2)):
            s = np.bincount(lab, weights=a.astype(np.float64), minlength=m)[:m]
            st.vox_sum[:m, col] += sign * np.rint(s).astype(np.int64)

    def forget_instance(self, instance_id: int) -> int:
        """Drop an instance (it moved or changed state): every vote of it, and every voxel
        it wins (most votes, ties to the lower label as :meth:`voxels`) with the votes of
        the other labels in it (module doc: a frame that missed or swapped its label must
        not leave its geometry behind). Returns the number of (voxel, label) entries
        removed. Its observation counts restart too, but for the frames it appeared in:
        that it exists is still known (:mod:`sgtool.scenegraph.object_evidence`)."""
        lab = self._label_of.get(int(instance_id))
        if lab is None or lab == 0 or lab == OVERFLOW_LABEL:
            return 0
        keys, counts = self.entries()
        mask = (keys & LABEL_MASK) == lab
        if mask.any():
            lo, hi = voxel_bounds(sorted_unique(keys[mask] >> VOXEL_SHIFT))
            idx = spans(np.searchsorted(keys, lo), np.searchsorted(keys, hi))
            win = idx[winning_entries(keys[idx], counts[idx])]
            won_vk = keys[win[(keys[win] & LABEL_MASK) == lab]] >> VOXEL_SHIFT
            mask[idx[np.isin(keys[idx] >> VOXEL_SHIFT, won_vk)]] = True
        n = int(mask.sum())
        if n:
            gone = keys[mask]
            others = gone[(gone & LABEL_MASK) != lab]
            if len(others):  # other labels' votes in the voxels it won
                self._voxel_stats(others, -1)
            self._remove(mask, gone)
        st = self._stats
        st.vox_n[lab] = 0
        st.vox_sum[lab] = 0
        st.points_max[lab] = 0
        st.points_total[lab] = 0
        st.view_dist[lab] = np.inf
        st.view_xy[lab] = np.nan
        return n

    def clear_unlabelled_around(self, points: np.ndarray, radius: float, zlo: int,
                                zhi: int) -> int:
        """Free-space evidence of the robot's body: drop the voxels at levels
        ``zlo..zhi`` whose column centre lies within ``radius`` m of one of the world
        ``points`` (k, 2) and that never got an instance's label (label 0 their only
        entry: a dropped detection, a door panel seen mid-swing). A voxel with an
        instance's vote stays (an instance's geometry goes with :meth:`forget_instance`;
        a drifted pose must not wipe a labelled wall). Entries are looked up in those
        columns only; returns the number removed."""
        pts = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        if not len(pts):
            return 0
        self.flush()
        res = self.config.resolution
        reach = int(math.ceil(radius / res)) + 1
        d = np.arange(-reach, reach + 1)
        cx = np.floor(pts[:, 0] / res).astype(np.int64)[:, None, None] + d[None, :, None]
        cy = np.floor(pts[:, 1] / res).astype(np.int64)[:, None, None] + d[None, None, :]
        near = (((cx + 0.5) * res - pts[:, 0, None, None]) ** 2
                + ((cy + 0.5) * res - pts[:, 1, None, None]) ** 2) <= radius * radius
        cx, cy = np.broadcast_arrays(cx, cy)
        cols = sorted_unique(((cx[near] + OFFSET) << AXIS_BITS) | (cy[near] + OFFSET))
        keys, _ = self._store.within(cols << COLUMN_SHIFT, (cols + 1) << COLUMN_SHIFT)
        if not len(keys):
            return 0
        vk = keys >> VOXEL_SHIFT
        alone = np.concatenate([[True], vk[1:] != vk[:-1]]) & \
            np.concatenate([vk[1:] != vk[:-1], [True]])  # the voxel's only entry
        iz = ((keys >> SHIFT_Z) & AXIS_MASK) - OFFSET
        gone = keys[alone & ((keys & LABEL_MASK) == 0) & (iz >= zlo) & (iz <= zhi)]
        if not len(gone):
            return 0
        all_keys, _ = self.entries()
        mask = np.zeros(len(all_keys), dtype=bool)
        mask[np.searchsorted(all_keys, gone)] = True
        self._voxel_stats(gone, -1)
        self._remove(mask, gone)
        return int(len(gone))

    def clear_seen_through(self, views: Sequence[View], zlo: int, zhi: int,
                           config: FreeSpaceConfig | None = None) -> int:
        """Projective free-space evidence (:mod:`sgtool.mapping.free_space`): every voxel
        at levels ``zlo..zhi`` with at most ``weak_votes`` votes counts the ``views`` that
        saw through it (misses, kept across calls); a voxel whose misses reach its votes
        is dropped with all its entries. A voxel with more votes is no longer watched (its
        votes only grow); a dropped one that a later frame sees again starts anew.
        Returns the number of (voxel, label) entries removed."""
        cfg = config or FreeSpaceConfig()
        self.flush()
        new = drain_keys(self._unwatched)
        if len(new):
            iz = ((new >> SHIFT_Z) & AXIS_MASK) - OFFSET
            nv = sorted_unique(new[(iz >= zlo) & (iz <= zhi)] >> VOXEL_SHIFT)
            at = np.searchsorted(self._weak, nv)
            known = np.zeros(len(nv), dtype=bool)
            inside = at < len(self._weak)
            known[inside] = self._weak[at[inside]] == nv[inside]
            fresh = nv[~known]
            if len(fresh):  # merged in order (both sorted, disjoint)
                where = np.searchsorted(self._weak, fresh)
                self._weak = np.insert(self._weak, where, fresh)
                self._misses = np.insert(self._misses, where, 0)
        if not len(self._weak):
            return 0
        keys, counts = self._store.within(*voxel_bounds(self._weak))
        vk = keys >> VOXEL_SHIFT
        votes = np.bincount(np.searchsorted(self._weak, vk), weights=counts,
                            minlength=len(self._weak)).astype(np.int64)
        iz = ((self._weak >> (SHIFT_Z - VOXEL_SHIFT)) & AXIS_MASK) - OFFSET
        keep = (votes > 0) & (votes <= cfg.weak_votes) & (iz >= zlo) & (iz <= zhi)
        self._weak, self._misses, votes = self._weak[keep], self._misses[keep], votes[keep]
        if not len(self._weak) or not views:
            return 0
        w = self._weak
        res = self.config.resolution
        centres = np.stack([(((w >> (SHIFT_X - VOXEL_SHIFT)) & AXIS_MASK) - OFFSET + 0.5) * res,
                            (((w >> (SHIFT_Y - VOXEL_SHIFT)) & AXIS_MASK) - OFFSET + 0.5) * res,
                            (iz[keep] + 0.5) * res], axis=1)
        for view in views:
            self._misses += seen_through(centres, view, cfg.margin, self.config.min_range,
                                         self.config.max_range, res)
        drop = self._misses >= votes
        if not drop.any():
            return 0
        gone_vk = w[drop]
        self._weak, self._misses = w[~drop], self._misses[~drop]
        all_keys, _ = self.entries()
        lo, hi = voxel_bounds(gone_vk)
        idx = spans(np.searchsorted(all_keys, lo), np.searchsorted(all_keys, hi))
        mask = np.zeros(len(all_keys), dtype=bool)
        mask[idx] = True
        gone = all_keys[idx]
        self._voxel_stats(gone, -1)
        self._remove(mask, gone)
        return int(len(gone))

    def _remove(self, mask: np.ndarray, gone: np.ndarray) -> None:
        """Drop the entries ``mask`` of :meth:`entries` (their keys ``gone``)."""
        keys, counts = self._store.arrays()
        self._zhist -= np.bincount((gone >> SHIFT_Z) & AXIS_MASK, minlength=1 << AXIS_BITS)
        self._store.replace(keys[~mask], counts[~mask])
        fkeys, frames = self._frames.arrays()  # the same keys in the same order
        self._frames.replace(fkeys[~mask], frames[~mask])
        self._removed_keys.append(gone)
        self.removals += 1
        self.version += 1

    # ----- queries ----------------------------------------------------------------------
    @property
    def resolution(self) -> float:
        return self.config.resolution

    def __len__(self) -> int:
        self.flush()
        return len(self._store)

    def entries(self) -> tuple[np.ndarray, np.ndarray]:
        """(sorted packed keys, vote counts) of every (voxel, label) pair."""
        self.flush()
        return self._store.arrays()

    def merged_keys(self) -> np.ndarray:
        """The sorted packed keys merged so far, without merging the pending frames (the
        map as of the last :meth:`flush`; reading it changes nothing)."""
        return self._store.arrays()[0]

    def drain_new_keys(self) -> np.ndarray:
        """(voxel, label) keys that entered the map since the last call (unsorted)."""
        self.flush()
        return drain_keys(self._new_keys)

    def drain_removed_keys(self) -> np.ndarray:
        """(voxel, label) keys removed since the last call (:meth:`forget_instance`)."""
        return drain_keys(self._removed_keys)

    def level_histogram(self) -> tuple[int, np.ndarray]:
        """(lowest level, entries per height level from it up): the map's z histogram,
        kept up to date by every merge and removal."""
        self.flush()
        nz = np.flatnonzero(self._zhist)
        if len(nz) == 0:
            return 0, np.zeros(0, dtype=np.int64)
        return int(nz[0]) - OFFSET, self._zhist[nz[0]:nz[-1] + 1].copy()

    def voxels(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Distinct voxels: (ijk (M, 3) int64, winning label index (M,), total votes (M,)).
        The winning label has the most votes (ties: the lower label index)."""
        keys, counts = self.entries()
        if len(keys) == 0:
            return np.zeros((0, 3), np.int64), np.zeros(0, np.int64), np.zeros(0, np.int64)
        vk = keys >> VOXEL_SHIFT
        starts = np.flatnonzero(np.concatenate([[True], vk[1:] != vk[:-1]]))
        total = np.add.reduceat(counts, starts)
        win = winning_entries(keys, counts)
        ix, iy, iz, lab = unpack(keys[win])
        return np.stack([ix, iy, iz], axis=1), lab, total

    def winning_labels(self, voxel_keys: np.ndarray) -> np.ndarray:
        """The winning label index (as :meth:`voxels`) of each of the sorted distinct voxel
        keys (``key >> VOXEL_SHIFT``) of voxels in the map, looked up in those voxels only."""
        self.flush()
        keys, counts = self._store.within(*voxel_bounds(voxel_keys))
        win = keys[winning_entries(keys, counts)]
        if len(win) != len(voxel_keys) or ((win >> VOXEL_SHIFT) != voxel_keys).any():
            raise ValueError("winning_labels: a voxel is not in the map")
        return win & LABEL_MASK

    def frame_counts(self, keys: np.ndarray) -> np.ndarray:
        """The number of frames that voted each of the distinct (voxel, label) ``keys`` of
        the map (any order); a key not in the map raises ValueError."""
        self.flush()
        order = np.argsort(keys, kind="stable")
        sk = keys[order]
        got, frames = self._frames.within(sk, sk + 1)
        if len(got) != len(sk) or (got != sk).any():
            raise ValueError("frame_counts: a key is not in the map")
        out = np.empty(len(keys), dtype=np.int64)
        out[order] = frames
        return out

    def instance_id(self, label: int) -> int:
        return self._label_ids[label] if 0 <= label < len(self._label_ids) else -1

    def label_ids(self) -> np.ndarray:
        """Instance id of every label index (index 0: 0, no instance)."""
        return np.asarray(self._label_ids, dtype=np.int64)

    def observation(self, instance_id: int) -> InstanceObservation | None:
        lab = self._label_of.get(int(instance_id))
        if lab is None or lab == 0 or lab == OVERFLOW_LABEL:
            return None
        self.flush()
        st = self._stats
        n = int(st.vox_n[lab])
        res = self.config.resolution
        centroid = None
        if n > 0:
            c = (st.vox_sum[lab].astype(np.float64) / n + 0.5) * res
            centroid = (float(c[0]), float(c[1]), float(c[2]))
        vd = float(st.view_dist[lab])
        vp = None if not np.isfinite(vd) else (float(st.view_xy[lab, 0]),
                                                float(st.view_xy[lab, 1]))
        return InstanceObservation(
            id=int(instance_id), max_points=int(st.points_max[lab]),
            total_points=int(st.points_total[lab]), frames=int(st.frames[lab]),
            last_index=int(st.last_index[lab]), viewpoint=vp, view_distance=vd, voxels=n,
            centroid=centroid,
        )

    def observed_instances(self) -> list[int]:
        """Instance ids (sorted) that appeared in at least one frame."""
        st = self._stats
        return sorted(i for lab, i in enumerate(self._label_ids)
                      if lab > 0 and st.points_total[lab] > 0)

    def voxels_of(self, instance_ids: list[int]) -> dict[int, np.ndarray]:
        """Instance id -> ijk (M, 3) of its voxels, for several instances in one pass."""
        keys, _ = self.entries()
        labs = {i: self._label_of[i] for i in sorted(instance_ids)
                if 0 < self._label_of.get(i, 0) < OVERFLOW_LABEL}
        out = {i: np.zeros((0, 3), np.int64) for i in sorted(instance_ids)}
        if not labs or len(keys) == 0:
            return out
        lab = keys & LABEL_MASK
        sel = np.isin(lab, np.asarray(sorted(labs.values()), dtype=np.int64))
        sk, sl = keys[sel], lab[sel]
        ix, iy, iz, _ = unpack(sk)
        ijk = np.stack([ix, iy, iz], axis=1)
        for i, lb in labs.items():
            out[i] = ijk[sl == lb]
        return out
