"""Making an imported world z-up with the floor at z = 0.

sgtool's mapping takes heights along world z (the floor plane is x/y), but real datasets
put their world frame anywhere: 7-Scenes and ICL-NUIM/Open3D trajectories start from the
first camera (y down), motion capture worlds (TUM) are tilted arbitrarily. An importer
therefore applies one fixed rigid transform ``A`` to every pose,
``world_T_camera' = A @ world_T_camera``, with ``A`` = rotate the source's up direction
onto +z, then shift along z so the floor is at 0.

Up direction:
- given (``--up -y``, or a vector ``0,-1,0``): used as is;
- automatic: start from the average "up" of the camera, ``-y`` of the optical frame in
  the world (hand-held and robot cameras are held roughly level, so their image "up" is
  close to the world's up on average), then refine it as the mean normal of the horizontal
  surfaces seen in a few depth frames (floor, table tops, ceiling share one normal). The
  refinement keeps normals within 30 degrees of the current estimate, then 15, then 8
  degrees, so walls never enter and pixels at wall/floor corners (normals in between)
  drop out of the last pass.

Floor height: the lowest large horizontal plane of the sampled frames, with a confidence
(:mod:`.floor`); without any upward-facing surface, the 1st percentile of all points
(``all-points``, confidence 0). ``--floor`` overrides.

The transform and how it was found are recorded in the log metadata (``sgtool.import``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from sgtool.errors import SgtoolError
from sgtool.log.frame import CameraIntrinsics

AXES = {
    "x": (1.0, 0.0, 0.0), "-x": (-1.0, 0.0, 0.0),
    "y": (0.0, 1.0, 0.0), "-y": (0.0, -1.0, 0.0),
    "z": (0.0, 0.0, 1.0), "-z": (0.0, 0.0, -1.0),
}


def parse_up(text: str) -> np.ndarray | None:
    """``auto`` -> None; an axis (``-y``) or three numbers -> unit vector."""
    s = text.strip().lower().replace("+", "")
    if s == "auto":
        return None
    if s in AXES:
        return np.array(AXES[s])
    try:
        v = np.array([float(x) for x in s.replace(",", " ").split()])
    except ValueError:
        v = np.zeros(0)
    if v.shape != (3,) or not np.all(np.isfinite(v)) or np.linalg.norm(v) < 1e-9:
        raise SgtoolError(
            f"--up {text!r}: give auto, an axis (x, -x, y, -y, z, -z) or a vector 'ux,uy,uz'"
        )
    return v / np.linalg.norm(v)


def rotation_to_z(u: np.ndarray) -> np.ndarray:
    """The smallest rotation taking unit vector ``u`` onto +z (Rodrigues); a half turn about
    x when ``u`` is -z."""
    u = np.asarray(u, dtype=np.float64)
    u = u / np.linalg.norm(u)
    z = np.array([0.0, 0.0, 1.0])
    c = float(u @ z)
    if c > 1.0 - 1e-12:
        return np.eye(3)
    if c < -1.0 + 1e-12:
        return np.diag([1.0, -1.0, -1.0])
    axis = np.cross(u, z)
    s = float(np.linalg.norm(axis))
    k = axis / s
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + s * kx + (1.0 - c) * (kx @ kx)


@dataclass(frozen=True)
class WorldAlignment:
    """``matrix`` maps source-world points to sgtool's z-up world."""

    rotation: np.ndarray  # 3x3
    floor: float  # source height of the floor along ``up`` (subtracted)
    up: tuple[float, float, float]  # the source world's up direction
    up_method: str  # "given", "camera-up", "horizontal-normals", "none"
    floor_method: str  # "given", "none", "no-depth", "horizontal-plane", "all-points"
    floor_confidence: float = 1.0  # of an estimated floor (:mod:`.floor`); 1 when given
    floor_detail: str = ""  # what the estimate is made of (:meth:`.FloorEstimate.describe`)
    surfaces_up: tuple[float, float, float] | None = None  # a given up: the surfaces' normal
    image_up: tuple[float, float, float] | None = None  # a given up: the cameras' image up
    image_right: tuple[float, float, float] | None = None  # and their image right (x)

    @classmethod
    def identity(cls) -> WorldAlignment:
        return cls(np.eye(3), 0.0, (0.0, 0.0, 1.0), "none", "none")

    @property
    def matrix(self) -> np.ndarray:
        A = np.eye(4)  # noqa: N806
        A[:3, :3] = self.rotation
        A[2, 3] = -self.floor
        return A

    def apply(self, pose: np.ndarray) -> np.ndarray:
        return self.matrix @ pose

    def metadata(self) -> dict[str, str]:
        return {
            "world_alignment": " ".join(f"{v:.9g}" for v in self.matrix.ravel()),
            "source_up": " ".join(f"{v:.6f}" for v in self.up),
            "up_method": self.up_method,
            "floor_height_in_source": f"{self.floor:.4f}",
            "floor_method": self.floor_method,
            **({"floor_estimate": self.floor_detail} if self.floor_detail else {}),
        }


@dataclass(frozen=True)
class DepthSample:
    """A depth image (metres) with its camera and source-world pose, for the estimates."""

    depth: np.ndarray
    intrinsics: CameraIntrinsics
    pose: np.ndarray


def backproject(depth: np.ndarray, k: CameraIntrinsics, stride: int) -> np.ndarray:
    """(h, w, 3) camera-frame points of every ``stride``-th pixel (z = 0 where no return)."""
    v, u = np.mgrid[0 : depth.shape[0] : stride, 0 : depth.shape[1] : stride]
    z = depth[::stride, ::stride].astype(np.float64)
    x = (u - k.cx) / k.fx * z
    y = (v - k.cy) / k.fy * z
    return np.stack([x, y, z], axis=-1)


def surface_points(sample: DepthSample, stride: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """World points and unit normals (oriented towards the camera) of one depth image, from
    central differences on the pixel grid; pixels at depth edges (second difference of the
    depth above 2 % + 2 cm) have no normal and are dropped."""
    P = backproject(sample.depth, sample.intrinsics, stride)  # noqa: N806
    z = P[..., 2]
    dx = P[1:-1, 2:] - P[1:-1, :-2]
    dy = P[2:, 1:-1] - P[:-2, 1:-1]
    zc = z[1:-1, 1:-1]
    ok = (zc > 0) & (z[1:-1, 2:] > 0) & (z[1:-1, :-2] > 0) & (z[2:, 1:-1] > 0) & (z[:-2, 1:-1] > 0)
    # a depth edge bends the depth profile sharply; a plane, even at a grazing angle, barely
    # (its depth is 1 / linear in the pixel coordinates): test the second differences
    lim = 0.02 * zc + 0.02
    ok &= np.abs(z[1:-1, 2:] - 2 * zc + z[1:-1, :-2]) < lim
    ok &= np.abs(z[2:, 1:-1] - 2 * zc + z[:-2, 1:-1]) < lim
    n = np.cross(dx, dy)
    norm = np.linalg.norm(n, axis=-1)
    ok &= norm > 1e-12
    p = P[1:-1, 1:-1][ok]
    n = n[ok] / norm[ok][:, None]
    flip = np.einsum("ij,ij->i", n, p) > 0  # towards the camera at the origin
    n[flip] *= -1
    R, t = sample.pose[:3, :3], sample.pose[:3, 3]  # noqa: N806
    return p @ R.T + t, n @ R.T


def camera_up(poses: Sequence[np.ndarray]) -> np.ndarray:
    """Mean image-up direction (-y of the optical frame) of the cameras, in the world."""
    ups = np.array([-np.asarray(T)[:3, 1] for T in poses])
    m = ups.mean(axis=0)
    n = float(np.linalg.norm(m))
    if n < 1e-6:
        raise SgtoolError(
            "cannot estimate the up direction: the cameras point every which way; "
            "give it with --up (e.g. --up -y)"
        )
    return m / n


ALIGNMENT_SAMPLES = 8  # depth frames whose surfaces the alignment looks at


def sample_indices(n: int, k: int = ALIGNMENT_SAMPLES) -> list[int]:
    """``k`` indices spread evenly over ``n`` frames (first and last included), sorted and
    distinct: the frames an importer hands to :func:`estimate_alignment`."""
    return np.unique(np.linspace(0, n - 1, min(k, n)).round().astype(int)).tolist()


def estimate_alignment(
    poses: Sequence[np.ndarray],
    samples: Sequence[DepthSample],
    *,
    up: np.ndarray | None = None,
    floor: float | None = None,
    floor_auto: bool = True,
) -> WorldAlignment:
    """The world alignment (see the module docstring). ``up`` None = estimate it;
    ``floor`` given = use it; else ``floor_auto`` estimates it, or leaves the height."""
    pts_list, nrm_list = [], []
    for s in samples:
        p, n = surface_points(s, stride=max(1, s.depth.shape[1] // 160))
        pts_list.append(p)
        nrm_list.append(n)
    pts = np.concatenate(pts_list) if pts_list else np.zeros((0, 3))
    nrm = np.concatenate(nrm_list) if nrm_list else np.zeros((0, 3))

    surfaces: tuple[float, float, float] | None = None
    image: tuple[float, float, float] | None = None
    right: tuple[float, float, float] | None = None
    if up is not None:
        u = np.asarray(up, dtype=np.float64) / np.linalg.norm(up)
        up_method = "given"
        seen = _horizontal_normal(nrm, u)
        if seen is not None:
            surfaces = (float(seen[0]), float(seen[1]), float(seen[2]))
        mean_up = np.mean([-np.asarray(T)[:3, 1] for T in poses], axis=0) if len(poses) else None
        if mean_up is not None and np.linalg.norm(mean_up) > 0.5:  # cameras held alike
            m = mean_up / np.linalg.norm(mean_up)
            image = (float(m[0]), float(m[1]), float(m[2]))
        mean_x = np.mean([np.asarray(T)[:3, 0] for T in poses], axis=0) if len(poses) else None
        if mean_x is not None and np.linalg.norm(mean_x) > 0.5:
            m = mean_x / np.linalg.norm(mean_x)
            right = (float(m[0]), float(m[1]), float(m[2]))
    else:
        u = camera_up(poses)
        up_method = "camera-up"
        seen = _horizontal_normal(nrm, u)
        if seen is not None:
            u, up_method = seen, "horizontal-normals"

    R = rotation_to_z(u)  # noqa: N806
    if floor is not None:
        fl, floor_method = float(floor), "given"
    elif not floor_auto or len(pts) == 0:
        # depth frames given but without one valid point: say so, not "none"
        fl, floor_method = 0.0, "none" if not floor_auto or not samples else "no-depth"
    else:
        from sgtool.recorders.importers.floor import estimate_floor

        est = estimate_floor(samples, u)
        assert est is not None  # there are points
        return WorldAlignment(R, est.height, (float(u[0]), float(u[1]), float(u[2])), up_method,
                              est.method, est.confidence, est.describe(), surfaces, image,
                              right)
    return WorldAlignment(R, fl, (float(u[0]), float(u[1]), float(u[2])), up_method, floor_method,
                          surfaces_up=surfaces, image_up=image, image_right=right)


def _horizontal_normal(nrm: np.ndarray, u: np.ndarray) -> np.ndarray | None:
    """The mean normal of the surfaces within 30, then 15, then 8 degrees of ``u``
    (module doc), oriented along ``u``; None when too few normals lie within 30."""
    found = None
    for cos_min in np.cos(np.radians([30.0, 15.0, 8.0])):
        d = nrm @ u
        sel = np.abs(d) > cos_min
        if sel.sum() < max(200, 0.02 * len(nrm)):
            break
        m = (nrm[sel] * np.sign(d[sel])[:, None]).mean(axis=0)
        u = found = m / np.linalg.norm(m)
    return found


UP_TOLERANCE_DEG = 10.0  # a given up this far from the horizontal surfaces is doubted


def _degrees(a: np.ndarray, b: np.ndarray) -> float:
    """The angle between unit vectors ``a`` and ``b``, in degrees."""
    return float(np.degrees(np.arccos(np.clip(float(a @ b), -1.0, 1.0))))


def given_up_problem(alignment: WorldAlignment) -> str | None:
    """A given ``--up`` against the cameras' image up (over 120 degrees from their mean:
    an upside-down world; over 75: another axis unless they look straight down) or image x
    axis (within 45 degrees of it: another axis; x stays level however the cameras
    pitch), or more than :data:`UP_TOLERANCE_DEG`
    from the normal of the horizontal surfaces (floor, table tops) seen near it, when
    those agree with the image up: heights would tilt across the map. None when the up
    was not given or nothing says otherwise."""
    if alignment.up_method != "given":
        return None
    given = np.asarray(alignment.up)
    image = None if alignment.image_up is None else np.asarray(alignment.image_up)
    if image is not None and float(given @ image) < -0.5:
        shown = ",".join(f"{-x + 0.0:.3f}" for x in given)  # (no -0.000)
        return (f"--up {','.join(f'{x:.3f}' for x in given)} points the way the cameras' "
                f"images point down: the world would be upside down (floor above, ceiling "
                f"below); give --up {shown} or --up auto")
    right = None if alignment.image_right is None else np.asarray(alignment.image_right)
    if right is not None and abs(float(given @ right)) > math.sin(math.radians(45.0)):
        # the cameras' x stays level however they pitch (no roll): an up along it is
        # another axis altogether
        off = min(_degrees(given, right), 180.0 - _degrees(given, right))
        return (f"--up {','.join(f'{x:.3f}' for x in given)} lies within {off:.0f} degrees "
                f"of the cameras' image x axis ({','.join(f'{x:.3f}' for x in right)}, level "
                "however they pitch): heights would run along the walls; give --up auto")
    if image is not None and _degrees(given, image) > 75.0:  # along the view: a camera
        # pitched this far down is a top-down scan, rare enough to be asked about
        return (f"--up {','.join(f'{x:.3f}' for x in given)} is "
                f"{_degrees(given, image):.0f} degrees from the cameras' image up "
                f"({','.join(f'{x:.3f}' for x in image)}): unless they look almost straight "
                "down, heights would run along the walls; give --up auto")
    if alignment.surfaces_up is None:
        return None
    seen = np.asarray(alignment.surfaces_up)
    if image is not None and _degrees(seen, image) > 45.0:
        return None  # the surfaces near the given up are walls: they say nothing of it
    off = _degrees(given, seen)
    if off <= UP_TOLERANCE_DEG:
        return None
    shown = ",".join(f"{x:.3f}" for x in seen)
    return (f"--up {','.join(f'{x:.3f}' for x in alignment.up)} is {off:.0f} degrees off the "
            f"horizontal surfaces seen (floor, table tops: up {shown}); heights tilt by "
            f"{np.tan(np.radians(off)):.2f} m per metre across the map; give --up {shown} "
            "or --up auto")
