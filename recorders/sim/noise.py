"""Seeded sensor faults for robustness studies: depth noise and holes, instance label swaps
and dropouts, odometry pose drift.

Faults apply to what is *logged* (the frames a mapper sees), never to the simulated world:
the robot still drives where it drives and the instances table stays the truth.

- depth noise: ``z + N(0, (sigma * z^2)^2)``, the quadratic growth of structured-light
  and stereo depth error with distance (Khoshelham & Elberink 2012 for the Kinect);
- depth holes: each pixel independently reads 0 (no return) with probability ``holes``;
- mixed ("flying") pixels: a pixel on a depth edge (a 4-neighbour farther or nearer by
  more than ``EDGE_REL`` of the nearer depth and ``EDGE_ABS``) reads, with probability
  ``flying``, a depth drawn uniformly between its own and that of the neighbour across
  the largest jump: the mixed returns of time-of-flight cameras and the edge smear of
  stereo ones, points floating in free space between a foreground edge and what lies
  behind it. Applied before the depth noise; the pixel keeps its label;
- label swaps: per frame, each visible non-structure instance is, with probability
  ``label_swap``, paired with another visible one and their ids exchanged in that frame
  (the confusions of a per-frame instance segmenter);
- label dropouts: per frame, each visible non-structure instance reads 0 with
  probability ``label_dropout`` (a missed detection);
- pose drift: the logged base pose integrates the true per-frame motion (dx, dy, dyaw in
  the base frame) with zero-mean errors of std ``drift_xy * sqrt(|d|)`` on each
  translation component and ``drift_yaw * sqrt(|d| + |dyaw|)`` on the heading (|d| in
  metres, |dyaw| in radians), like wheel odometry: a random walk whose variance grows with
  the distance driven and the angle turned, so ``drift_xy`` is the std (m) of the error
  after 1 m and the same whatever the frame rate (errors of std ``drift * |d|`` a frame
  added up to less the more frames a metre took: a third as much at 40 frames a metre
  as at 4). The logged camera pose rides on it.

Floor and walls (``structure``) are exempt from label faults, so rooms stay mappable; use
them to study object-level robustness. Each fault draws from its own generator spawned
from the seed, so turning one fault on or off does not change the others' draws.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable
from dataclasses import asdict, dataclass, fields, replace
from pathlib import Path
from typing import Any

import numpy as np

from sgtool.arg_checks import of_type
from sgtool.errors import SgtoolError
from sgtool.house.parse import JsonObject, json_object_pairs
from sgtool.log.codec import compose, relative
from sgtool.log.frame import Frame
from sgtool.recorders.sim.camera import LINK_TOL, se2_matrix

# the largest strengths taken: 1 m of depth std at 1 m, 1 m of drift std after 1 m driven,
# 1 rad of yaw drift std after 1 m (the strong profile is 0.006, 0.007, 0.011)
LIMITS = {"depth_sigma": 1.0, "drift_xy": 1.0, "drift_yaw": 1.0}
EDGE_REL = 0.1  # a depth edge: neighbouring depths differ by this share of the nearer one
EDGE_ABS = 0.1  # m; and by at least this much
# how pose drift accrues, logged with a drifted episode: 1 (sgtool before 992f26a) an error
# of std drift * |d| a frame, 2 a random walk in the distance (drift * sqrt(|d|) a frame)
DRIFT_MODEL = 2


@dataclass(frozen=True)
class NoiseProfile:
    """Fault strengths (all 0 = a perfect sensor). ``name`` labels and pools the
    profile's runs; a built-in profile's name (:data:`PROFILES`) is taken only with that
    profile's faults."""

    name: str = "none"
    depth_sigma: float = 0.0  # m of std at 1 m; grows with z^2
    holes: float = 0.0  # probability a depth pixel reads 0
    label_swap: float = 0.0  # per visible instance and frame
    label_dropout: float = 0.0  # per visible instance and frame
    drift_xy: float = 0.0  # std (m) per axis after 1 m driven (grows with its square root)
    drift_yaw: float = 0.0  # std (rad) after 1 m driven or 1 rad turned (likewise)
    flying: float = 0.0  # probability a depth-edge pixel reads between the two surfaces

    def __post_init__(self) -> None:
        for f in fields(self):
            if f.name == "name":
                continue
            v = getattr(self, f.name)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                raise SgtoolError(f"--noise {f.name}={v!r}: expected a number")
            if v < 0:
                raise SgtoolError(f"--noise {f.name}={v:g}: must be >= 0")
        for p in ("holes", "label_swap", "label_dropout", "flying"):
            if getattr(self, p) > 1:
                raise SgtoolError(f"--noise {p}={getattr(self, p):g}: a probability, at most 1")
        for p, most in LIMITS.items():  # beyond these, no sensor: overflow, not noise
            if getattr(self, p) > most:
                raise SgtoolError(f"--noise {p}={getattr(self, p):g}: at most {most:g}")
        of_type("NoiseProfile name", self.name, str, "a text")
        same = globals().get("PROFILES", {}).get(self.name.strip())
        if same is not None and any(getattr(self, f.name) != getattr(same, f.name)
                                    for f in fields(self) if f.name != "name"):
            raise SgtoolError(f"NoiseProfile({self.name!r}, ...): a built-in profile's name "
                              "with other faults; give it a name of its own")

    @property
    def is_clean(self) -> bool:
        return all(getattr(self, f.name) == 0 for f in fields(self) if f.name != "name")

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)

    @property
    def drift_model(self) -> int | None:
        """:data:`DRIFT_MODEL` when this profile drifts, else None."""
        return DRIFT_MODEL if self.drift_xy > 0 or self.drift_yaw > 0 else None


PROFILES: dict[str, NoiseProfile] = {
    "none": NoiseProfile("none"),
    # a good RGB-D camera and a fair segmenter
    # (drift: what the per-frame model's 0.005 and 0.02 added up to on the study's tours at
    # 4 frames a second: position after 1 m driven, heading over a whole tour, not per
    # motion; docs/experiments/houses-nobody-designed.md)
    "mild": NoiseProfile("mild", depth_sigma=0.0015, holes=0.01, label_swap=0.01,
                         label_dropout=0.02, drift_xy=0.0018, drift_yaw=0.0027),
    # a poor one: strong far-range noise, many holes, frequent label errors, fast drift
    "strong": NoiseProfile("strong", depth_sigma=0.006, holes=0.08, label_swap=0.05,
                           label_dropout=0.1, drift_xy=0.007, drift_yaw=0.011),
}


def parse_noise(text: str | None) -> NoiseProfile:
    """A profile from ``none``/``mild``/``strong``, optionally followed by overrides
    (``mild,holes=0.05,drift_xy=0``), only overrides (``holes=0.05``, starting from none),
    or a JSON file holding an object of fields."""
    if text is None:
        return PROFILES["none"]
    of_type("--noise", text, str, "a profile's text (none, mild, strong, overrides) or a "
            "JSON file's path")
    t = text.strip()
    if not t:
        raise SgtoolError("--noise: empty; give a profile (none, mild, strong), overrides "
                          "(holes=0.05) or a .json file")
    if names_file(t):
        p = Path(t)
        try:
            d = json.loads(p.read_text(encoding="utf-8-sig"),
                           object_pairs_hook=json_object_pairs)
        except (OSError, UnicodeDecodeError) as e:
            raise SgtoolError(f"--noise {t}: cannot read: {e}") from None
        except json.JSONDecodeError as e:
            raise SgtoolError(f"--noise {t}: not valid JSON ({e.msg})") from None
        if not isinstance(d, dict):
            raise SgtoolError(f"--noise {t}: expected a JSON object of noise fields")
        if isinstance(d, JsonObject) and d.duplicates:  # (json keeps the last silently)
            raise SgtoolError(f"--noise {t}: {', '.join(d.duplicates)} is given twice")
        prof = d.pop("profile", "none")
        if not isinstance(prof, str) or prof not in PROFILES:
            raise SgtoolError(f"--noise {t}: unknown profile {prof!r} (one of "
                              f"{', '.join(PROFILES)})")
        return _override(PROFILES[prof], d.items(), t, default_name=p.stem)
    parts = [s.strip() for s in t.split(",") if s.strip()]
    base = PROFILES["none"]
    if parts and "=" not in parts[0]:
        if parts[0] not in PROFILES:
            raise SgtoolError(f"--noise {t}: unknown profile {parts[0]!r} (one of "
                              f"{', '.join(PROFILES)}, or NAME=VALUE overrides, or a .json file)")
        base = PROFILES[parts.pop(0)]
    items: list[tuple[str, Any]] = []
    for s in parts:
        k, eq, v = s.partition("=")
        if not eq:
            raise SgtoolError(f"--noise {t}: {s!r} is not NAME=VALUE")
        if k.strip() == "name":  # the profile's name, as a file's "name" gives it
            items.append(("name", v.strip()))
            continue
        try:
            items.append((k.strip(), float(v)))
        except ValueError:
            raise SgtoolError(f"--noise {t}: {k.strip()}={v!r} is not a number") from None
    return _override(base, items, t,
                     default_name=_spelled(base.name, [(k, v) for k, v in items if k != "name"]))


def _spelled(base: str, items: Iterable[tuple[str, float]]) -> str:
    """One spelling of a profile given with overrides, its name and log folder: the
    base profile named unless it is ``none``, the overrides in the order of
    :class:`NoiseProfile`'s fields with numbers in Python's shortest form (``none,
    label_swap=0.1, holes=0.050`` and ``holes=5e-2,label_swap=0.1`` are
    ``holes=0.05,label_swap=0.1``; ``drift_xy=1.0`` is ``drift_xy=1``)."""
    def number(v: float) -> str:
        r = repr(float(v))
        return r[:-2] if r.endswith(".0") else r
    order = [f.name for f in fields(NoiseProfile)]
    given = sorted(items, key=lambda kv: order.index(kv[0]) if kv[0] in order else len(order))
    return ",".join(([base] if base != "none" else []) + [f"{k}={number(v)}" for k, v in given])


def names_file(text: str) -> bool:
    """Whether the ``--noise`` text names a JSON file (:func:`parse_noise`), not a
    profile with overrides: a profile's name is always the profile (a file of that name
    is ``./NAME``)."""
    t = text.strip()
    return t.endswith(".json") or (t not in PROFILES and Path(t).is_file())


def _override(base: NoiseProfile, items: Iterable[tuple[str, Any]], where: str,
              default_name: str) -> NoiseProfile:
    names = {f.name for f in fields(NoiseProfile)} - {"name"}
    kw: dict[str, Any] = {}
    for k, v in items:
        if k == "name":
            kw["name"] = str(v)
            continue
        if k not in names:
            raise SgtoolError(f"--noise {where}: unknown field {k!r} (fields: "
                              f"{', '.join(sorted(names))})")
        if k in kw:
            raise SgtoolError(f"--noise {where}: {k} is given twice")
        kw[k] = v
    if not kw:
        return base
    how = "its \"name\"" if "name" in kw else "the file's name"
    name = str(kw.pop("name", default_name))
    if not name.strip() or name.strip() in (".", "..") or any(c in name for c in "/\\\0"):
        raise SgtoolError(f"--noise {where}: name {name!r}: a profile's name names its log "
                          "folder (run-bench's logs/NAME/): give a name without / or \\")
    out = replace(base, **kw, name="")
    same = PROFILES.get(name.strip())
    if same is not None and replace(out, name="") != replace(same, name=""):  # pooled as it
        raise SgtoolError(f"--noise {where}: named {name.strip()!r} ({how}), a built-in "
                          "profile, with other faults; give it a name of its own")
    return replace(out, name=name)


class SensorFaults:
    """Applies a :class:`NoiseProfile` to a sequence of frames, seeded and in order
    (frame k's faults depend on the seed and frames 0..k only). ``base_T_camera``: the
    camera's mounting on the base, used as given where a frame's base -> camera link
    equals it (a tilted head gives other links, taken from the frame)."""

    def __init__(self, profile: NoiseProfile, seed: int, structure_ids: Iterable[int] = (),
                 base_T_camera: np.ndarray | None = None) -> None:
        self.profile = profile
        ss = np.random.SeedSequence([int(seed), 0x5EED])  # (children keep their draws
        # whatever the number spawned: a fault added later leaves the others' unchanged)
        self._depth_rng, self._label_rng, self._pose_rng, self._edge_rng = (
            np.random.default_rng(s) for s in ss.spawn(4))
        self._structure = frozenset(int(i) for i in structure_ids)
        self._base_T_cam = base_T_camera
        self._true_prev: tuple[float, float, float] | None = None
        self._est: tuple[float, float, float] | None = None

    def apply(self, frame: Frame) -> Frame:
        p = self.profile
        if p.is_clean:
            return frame
        depth, ids = frame.depth, frame.ids
        if p.flying > 0:
            depth = mixed_edges(depth, p.flying, self._edge_rng)
        if p.depth_sigma > 0 or p.holes > 0:
            depth = self._depth(depth)
        if ids is not None and (p.label_swap > 0 or p.label_dropout > 0):
            ids = self._labels(ids)
        pose, base = frame.pose, frame.base_pose
        if base is not None and (p.drift_xy > 0 or p.drift_yaw > 0):
            pose, base = self._drift(pose, base)
        return replace(frame, depth=depth, ids=ids, pose=pose, base_pose=base)

    # ----- depth ------------------------------------------------------------------------
    def _depth(self, depth: np.ndarray) -> np.ndarray:
        p, rng = self.profile, self._depth_rng
        d = depth.astype(np.float32, copy=True)
        valid = d > 0
        if p.depth_sigma > 0:
            n = rng.standard_normal(d.shape, dtype=np.float32)
            d += np.float32(p.depth_sigma) * d * d * n
            d[~valid] = 0.0
            np.maximum(d, 0.0, out=d)
        if p.holes > 0:
            d[rng.random(d.shape, dtype=np.float32) < np.float32(p.holes)] = 0.0
        return d

    # ----- labels -----------------------------------------------------------------------
    def _labels(self, ids: np.ndarray) -> np.ndarray:
        p, rng = self.profile, self._label_rng
        uniq, inverse = np.unique(ids, return_inverse=True)
        objs = [int(u) for u in uniq if u != 0 and u not in self._structure]
        mapping = {int(u): int(u) for u in uniq}
        if p.label_swap > 0 and len(objs) >= 2:
            free = list(objs)
            for u in objs:
                if u not in free:
                    continue
                hit = rng.random() < p.label_swap
                if not hit:
                    continue
                others = [v for v in free if v != u]
                if not others:
                    break
                v = others[int(rng.integers(len(others)))]
                mapping[u], mapping[v] = v, u
                free.remove(u)
                free.remove(v)
        if p.label_dropout > 0:
            for u in objs:
                if rng.random() < p.label_dropout:
                    mapping[u] = 0
        if all(mapping[int(u)] == int(u) for u in uniq):
            return ids
        lut = np.array([mapping[int(u)] for u in uniq], dtype=np.int32)
        return lut[inverse.reshape(ids.shape)]

    # ----- pose -------------------------------------------------------------------------
    def _drift(self, pose: np.ndarray, base: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        p, rng = self.profile, self._pose_rng
        true = (float(base[0, 3]), float(base[1, 3]), math.atan2(base[1, 0], base[0, 0]))
        if self._true_prev is None or self._est is None:
            self._true_prev, self._est = true, true
        else:
            x0, y0, a0 = self._true_prev
            c, s = math.cos(a0), math.sin(a0)
            dxw, dyw = true[0] - x0, true[1] - y0
            dx, dy = c * dxw + s * dyw, -s * dxw + c * dyw  # in the previous base frame
            da = math.atan2(math.sin(true[2] - a0), math.cos(true[2] - a0))
            dist = math.hypot(dx, dy)
            e = rng.standard_normal(3)
            dx += e[0] * p.drift_xy * math.sqrt(dist)
            dy += e[1] * p.drift_xy * math.sqrt(dist)
            da += e[2] * p.drift_yaw * math.sqrt(dist + abs(da))
            ex, ey, ea = self._est
            ce, se = math.cos(ea), math.sin(ea)
            self._est = (ex + ce * dx - se * dy, ey + se * dx + ce * dy,
                         math.atan2(math.sin(ea + da), math.cos(ea + da)))
            self._true_prev = true
        est_base = se2_matrix(*self._est)
        est_base[2, 3] = base[2, 3]
        base_T_cam = relative(base, pose)  # noqa: N806
        if self._base_T_cam is not None and np.allclose(base_T_cam, self._base_T_cam,
                                                        rtol=0.0, atol=LINK_TOL):
            base_T_cam = self._base_T_cam  # the mounting as given (not rounded again)
        return compose(est_base, base_T_cam), est_base


def mixed_edges(depth: np.ndarray, share: float, rng: np.random.Generator) -> np.ndarray:
    """A copy of ``depth`` (m, 0 = no return) whose depth-edge pixels (module doc) each
    read, with probability ``share``, a depth uniform between their own and that of the
    4-neighbour across their largest jump."""
    d = np.asarray(depth, dtype=np.float32)
    h, w = d.shape
    best = np.zeros((h, w), dtype=np.float32)  # the largest jump to a valid neighbour
    other = d.copy()  # that neighbour's depth
    pad = np.pad(d, 1)
    for dy, dx in ((-1, 0), (1, 0), (0, -1), (0, 1)):
        n = pad[1 + dy:1 + dy + h, 1 + dx:1 + dx + w]
        jump = np.abs(n - d)
        edge = ((d > 0) & (n > 0) & (jump > EDGE_ABS)
                & (jump > np.float32(EDGE_REL) * np.minimum(d, n)) & (jump > best))
        best[edge] = jump[edge]
        other[edge] = n[edge]
    u = rng.random((h, w), dtype=np.float32)
    t = rng.random((h, w), dtype=np.float32)
    hit = (best > 0) & (u < np.float32(share))
    out = d.copy()
    out[hit] = d[hit] + t[hit] * (other[hit] - d[hit])
    return out
