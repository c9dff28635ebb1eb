"""Sanity checks of an import before the heavy work: pure functions over the numbers a source
gives, each returning a one-line problem that names the flag that fixes it (or None).

The importers turn a problem into an error when the value came from a default or a guess
(a silently wrong map is worse than no map) and into a warning when the user gave it with a
flag (they know their data better than these bands do):

- time stamps (:func:`timestamp_problem`): in the order the source lists its images they must
  increase, be distinct and give a frame rate an RGB-D camera has; per-frame intervals
  written where times belong give ~6000 "fps" and a sort that shuffles the frames;
- depth scale (:func:`depth_scale_problem`): the median depth of the valid pixels and the far
  end of the depth range (95th percentile) must be what indoor RGB-D gives; millimetres read
  with TUM's 5000 units per metre make the world 5x too small. The scales that would fit are
  named, or the byte order when the depth read with its bytes swapped is indoor depth and
  far smoother (:func:`swapped_fit`: a scale may "fit" swapped 16-bit depth, whose values
  spread over the whole range);
- floor (:func:`floor_problem`): the camera's median height above the estimated floor must be
  within a band (``--camera-height``, 0.5-2.2 m by default: hand-held, head- and robot-mounted
  cameras); a desk top taken for the floor puts a hand-held camera 0.4 m above it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

# frame rates (Hz) that RGB-D cameras and their recordings have: a key-frame subsample of a
# few seconds per frame up to a 90 Hz RealSense stream, with a margin
MIN_FPS = 0.05
MAX_FPS = 200.0
# indoor RGB-D: the median valid depth and the far end (95th percentile) of one frame's range
MEDIAN_DEPTH_M = (0.4, 6.0)
FAR_DEPTH_M = (0.9, 12.0)
# the depth scales (raw units per metre) datasets use: mm (ROS, RealSense, 7-Scenes, Redwood),
# 1/5000 m (TUM RGB-D), 0.1 mm (some Azure Kinect / ZED exports), 1/4000 m (ScanNet-style),
# 1/6553.5 m (Replica as NICE-SLAM renders it: 10 m over 16 bits)
KNOWN_SCALES = (1000.0, 5000.0, 10000.0, 4000.0, 6553.5)
DEFAULT_CAMERA_HEIGHT = (0.45, 2.2)  # m above the floor
SWAP_SMOOTHER = 4.0  # how much smoother depth read with its bytes swapped must be to say so


@dataclass(frozen=True)
class TimingStats:
    """What :func:`timestamp_problem` found in a list of time stamps (file order)."""

    frames: int
    backwards: int  # steps where the time goes back
    duplicates: int  # steps where it stays
    span_s: float
    fps: float  # from the median positive step (0 when there is none)


def timing_stats(times_ns: Sequence[int]) -> TimingStats:
    t = np.asarray(times_ns, dtype=np.int64)
    d = np.diff(t)
    pos = d[d > 0]
    fps = float(1e9 / np.median(pos)) if len(pos) else 0.0
    span = float((t.max() - t.min()) / 1e9) if len(t) else 0.0
    return TimingStats(len(t), int((d < 0).sum()), int((d == 0).sum()), span, fps)


FOLDER_TIME_FIX = ("import the frames in the listed order with --timestamps index --fps N "
                   "(N = the camera's frame rate)")
BAG_TIME_FIX = "import with --timestamps bag (the times the messages were recorded)"


def timestamp_problem(times_ns: Sequence[int], what: str,
                      fix: str = FOLDER_TIME_FIX) -> str | None:
    """The problem of the time stamps ``what`` lists (in its order), or None when they
    increase at a plausible rate; ``fix`` names the flag (``--timestamps index --fps N``
    for folders)."""
    if len(times_ns) < 2:
        return None
    s = timing_stats(times_ns)
    found = []
    if s.backwards:
        found.append(f"{s.backwards} of {s.frames - 1} steps go back in time")
    if s.duplicates:
        found.append(f"{s.duplicates} repeat a time stamp")
    if not found and not MIN_FPS <= s.fps <= MAX_FPS:
        found.append(f"{s.frames} frames span {s.span_s:.3g} s (~{s.fps:.4g} fps)")
    if not found:
        return None
    looks = ""
    if s.backwards and s.span_s * MAX_FPS < s.frames:  # small values up and down
        looks = f"; {s.frames} frames in {s.span_s:.3g} s: they look like per-frame intervals"
    elif not s.backwards and not s.duplicates and s.fps < MIN_FPS:
        for factor, unit in ((1e3, "milliseconds"), (1e6, "microseconds")):
            if 5.0 <= s.fps * factor <= 120.0:  # a camera's usual rates
                looks = (f"; read as {unit}, {s.fps * factor:.3g} fps: they look like "
                         f"{unit} where the format gives seconds (convert the lists and any "
                         "trajectory of the same clock to seconds to keep its poses)")
                break
    return f"{what}: the time stamps are not times of frames ({'; '.join(found)}{looks}); {fix}"


MAX_LOG_TIME_NS = 2**63 - 1  # a log's times are int64 nanoseconds >= 0 (up to year 2262)


def time_range_problem(times_ns: Sequence[int], what: str,
                       fix: str = FOLDER_TIME_FIX) -> str | None:
    """The problem of time stamps a log cannot hold: negative, or beyond year 2262 (seconds
    that are really milliseconds or microseconds); None when all are in range."""
    if not times_ns:
        return None
    lo, hi = min(times_ns), max(times_ns)
    if hi > MAX_LOG_TIME_NS:
        return (f"{what}: time stamps up to {hi / 1e9:.4g} s are beyond year 2262: they look "
                f"like milliseconds or microseconds, the format gives seconds; {fix}")
    if lo < 0:
        return (f"{what}: negative time stamps (from {lo / 1e9:.6g} s); a log's times start "
                f"at 0 or later; {fix}")
    return None


@dataclass(frozen=True)
class DepthStats:
    """Median and 95th percentile of the valid depth (metres at the scale checked)."""

    median_m: float
    far_m: float
    valid: int


def depth_stats(raw: Sequence[np.ndarray], scale: float) -> DepthStats:
    """Over the valid pixels (not 0, not 65535 for 16-bit) of a few raw depth images."""
    vals = []
    for a in raw:
        a = np.asarray(a)
        v = a[(a > 0) & np.isfinite(a)] if a.dtype.kind == "f" else a[(a > 0) & (a != 65535)]
        vals.append(v.astype(np.float64).ravel())
    v = np.concatenate(vals) if vals else np.zeros(0)
    if len(v) == 0:
        return DepthStats(0.0, 0.0, 0)
    return DepthStats(float(np.median(v)) / scale, float(np.percentile(v, 95)) / scale, len(v))


def no_depth_problem(raw: Sequence[np.ndarray], what: str) -> str | None:
    """The problem of depth images without one valid pixel (all 0 or 65535: no return):
    nothing to map, no floor to find; None when some pixel is valid."""
    if depth_stats(raw, 1.0).valid:
        return None
    return (f"{what}: none of the {len(raw)} sampled depth images has a valid pixel (all 0 or "
            "65535, no return): nothing to map")


def depth_plausible(s: DepthStats) -> bool:
    return (MEDIAN_DEPTH_M[0] <= s.median_m <= MEDIAN_DEPTH_M[1]
            and FAR_DEPTH_M[0] <= s.far_m <= FAR_DEPTH_M[1])


def fitting_scales(raw: Sequence[np.ndarray], scale: float) -> list[tuple[float, DepthStats]]:
    """The known scales (other than ``scale``) at which the depth looks indoor, nearest to a
    2 m median first."""
    out = []
    for k in KNOWN_SCALES:
        if k == scale:
            continue
        s = depth_stats(raw, k)
        if depth_plausible(s):
            out.append((k, s))
    return sorted(out, key=lambda ks: abs(np.log(ks[1].median_m / 2.0)))


def roughness(raw: Sequence[np.ndarray]) -> float:
    """How much valid depth changes from a pixel to its right-hand neighbour, relative to
    its size: the median of ``|a - b| / (a + b)`` over the pairs of valid pixels that
    differ (0 for a flat image; depth of real surfaces changes little from pixel to pixel,
    bytes read in the wrong order make it jump). Equal pairs are left out: they are equal
    in either byte order, and a Kinect's quantised depth has more of them than not (its
    median would be 0 both ways)."""
    parts = []
    for a in raw:
        a = np.asarray(a, dtype=np.float64)
        if a.ndim != 2 or a.shape[1] < 2:
            continue
        left, right = a[:, :-1], a[:, 1:]
        ok = (left > 0) & (right > 0) & np.isfinite(left) & np.isfinite(right) \
            & (left != 65535) & (right != 65535) & (left != right)
        parts.append((np.abs(left - right)[ok] / (left + right)[ok]).ravel())
    v = np.concatenate(parts) if parts else np.zeros(0)
    return float(np.median(v)) if len(v) else 0.0


def swapped_fit(raw: Sequence[np.ndarray], scale: float) -> tuple[float, DepthStats] | None:
    """(scale, stats) at which ``raw`` read with each value's bytes swapped is indoor depth
    (``scale`` first, then :data:`KNOWN_SCALES`), when swapped it is also far smoother
    (:data:`SWAP_SMOOTHER` times, :func:`roughness`): depth written in the other byte order
    than the image says (a ROS Image's ``is_bigendian``); None otherwise."""
    raw = [a for a in raw if a.dtype.itemsize > 1]
    if not raw:
        return None
    swapped = [a.byteswap() for a in raw]
    if roughness(swapped) * SWAP_SMOOTHER >= roughness(raw):
        return None
    for k in (scale, *(k for k in KNOWN_SCALES if k != scale)):
        s = depth_stats(swapped, k)
        if s.valid and depth_plausible(s):
            return k, s
    return None


def depth_scale_problem(raw: Sequence[np.ndarray], scale: float, origin: str) -> str | None:
    """The problem of reading ``raw`` depth (16-bit integers, or floats: 32FC1 is metres
    unless a scale was given) at ``scale`` units per metre (which came from ``origin``: a
    flag, a layout default, the encoding), naming the scales that fit; None when the depth
    looks indoor."""
    raw = [np.asarray(a) for a in raw if np.asarray(a).dtype.kind in "uif"]
    if not raw:
        return None
    s = depth_stats(raw, scale)
    if s.valid == 0 or depth_plausible(s):
        return None
    swap = swapped_fit(raw, scale)
    fits = fitting_scales(raw, scale)
    if swap is not None:
        k, fs = swap
        at = "" if k == scale else f" at --depth-scale {k:g}"
        fix = (f"with each value's bytes swapped it is smooth indoor depth (median "
               f"{fs.median_m:.2f} m{at}): the images are in the other byte order than they "
               "say (a ROS Image's is_bigendian flag, or files written with their bytes "
               "swapped); write them in the right order")
    elif fits:
        k, fs = fits[0]
        also = ", ".join(f"{a:g} (median {f.median_m:.2f} m)" for a, f in fits[1:])
        fix = (f"--depth-scale {k:g} fits (median {fs.median_m:.2f} m)" + (
            f", and so do {also}: the depth alone cannot tell them apart, and the sensor's "
            "datasheet or the dataset's readme says which is its" if also else "")
            + f"; give it, or --depth-scale {scale:g} to keep this one")
    else:
        fix = "no usual scale fits; give the sensor's units with --depth-scale"
    return (f"depth scale {scale:g} units/m ({origin}) looks wrong: median depth "
            f"{s.median_m:.2f} m, 95 % within {s.far_m:.2f} m, outside indoor RGB-D "
            f"({MEDIAN_DEPTH_M[0]:g}-{MEDIAN_DEPTH_M[1]:g} m median); {fix}")


def camera_heights(poses: Sequence[np.ndarray], alignment_matrix: np.ndarray) -> np.ndarray:
    """Height (z) of each camera in the aligned world."""
    return np.array([float((alignment_matrix @ np.asarray(T))[2, 3]) for T in poses])


def floor_problem(poses: Sequence[np.ndarray], alignment_matrix: np.ndarray, floor: float,
                  origin: str, band: tuple[float, float]) -> str | None:
    """The problem of a floor at source height ``floor`` (which came from ``origin``) that
    puts the camera's median height outside ``band``; None when it is within."""
    if not poses:
        return None
    h = float(np.median(camera_heights(poses, alignment_matrix)))
    if band[0] <= h <= band[1]:
        return None
    cam = h + floor  # the camera's median height in the source world along up
    example = cam - 1.3
    return (f"the camera is {h:.2f} m above the floor ({origin}; at {floor:.3f} m in the "
            f"source), outside --camera-height {band[0]:g}:{band[1]:g}"
            + (": a table or counter was taken for the floor (not in view), or the camera "
               f"is mounted that low (a robot's: then give --camera-height "
               f"{max(0.1, round(h - 0.1, 1)):g}:{band[1]:g})" if h < band[0] else "")
            + f"; give the floor's height with --floor (e.g. --floor {example:.2f} puts the "
            "camera at 1.3 m), or a wider --camera-height")


# how far (a fraction of the image size, per axis) a principal point may be from the image
# centre: real cameras stay within a few per cent; intrinsics of half or double the
# resolution put it a quarter of the image off
PRINCIPAL_POINT_OFF = 0.125


def _size(pixels: float) -> int:
    """An image size near ``pixels`` (twice a principal point): the nearest multiple of 8."""
    return max(8, 8 * round(pixels / 8))


def principal_point_problem(cx: float, cy: float, width: int, height: int,
                            origin: str) -> str | None:
    """The problem of a principal point more than :data:`PRINCIPAL_POINT_OFF` of the image
    from the centre of ``width`` x ``height`` images: intrinsics of another resolution (e.g.
    320x240 numbers for 640x480 images, whatever size the intrinsics claim) stretch the
    world; None when it is near the centre."""
    if (abs(cx - width / 2) <= PRINCIPAL_POINT_OFF * width
            and abs(cy - height / 2) <= PRINCIPAL_POINT_OFF * height):
        return None
    return (f"intrinsics ({origin}): the principal point ({cx:g}, {cy:g}) is far from the "
            f"centre ({width / 2:g}, {height / 2:g}) of the {width}x{height} depth images; they "
            f"look like intrinsics of {_size(2 * cx)}x{_size(2 * cy)} images: give the "
            f"intrinsics of {width}x{height} images with --intrinsics fx,fy,cx,cy")


MAX_DROPPED = 0.10  # share of the frames an import may drop without --allow-drop


def dropped_problem(dropped: int, total: int, why: str, fixes: str) -> str | None:
    """The problem of dropping ``dropped`` of ``total`` frames (``why``: "no pose from tf
    world -> cam") when that is more than :data:`MAX_DROPPED`: a map of the rest is not the
    recording; ``fixes`` names the flags (``--tf-tolerance``, ``--estimate-poses``,
    ``--allow-drop``). None at or under the share."""
    if total <= 0 or dropped <= MAX_DROPPED * total:
        return None
    return (f"{dropped} of {total} frames ({100 * dropped / total:.0f} %, more than "
            f"{100 * MAX_DROPPED:.0f} %) would be dropped: {why}; {fixes}")


MAX_CLOCK_OFFSET_S = 0.05  # image stamps this much later than their record time vs /tf's


def clock_offset_s(image_latency_ns: Sequence[int], tf_latency_ns: Sequence[int]
                   ) -> float | None:
    """How much earlier (s) than /tf the images were recorded relative to their stamps:
    median(record - stamp) of the images minus that of the /tf transforms. A camera's
    images arrive after their stamps (latency, > 0); images stamped later than /tf stamps
    the same instant arrive "before" their stamps (< 0). None without both."""
    if not image_latency_ns or not tf_latency_ns:
        return None
    return float(np.median(image_latency_ns) - np.median(tf_latency_ns)) / 1e9


def clock_problem(offset_s: float | None, what: str) -> str | None:
    """The problem of image stamps later than the bag recorded them, relative to /tf, by
    more than :data:`MAX_CLOCK_OFFSET_S` (the images are then paired with poses from the
    future), naming ``--time-offset`` with the shift that fits and ``--timestamps bag``;
    None otherwise (a camera's latency, offset > 0, is not a clock error)."""
    if offset_s is None or offset_s >= -MAX_CLOCK_OFFSET_S:
        return None
    return (f"{what}: the image stamps are {-offset_s:.3f} s later than the times the bag "
            "recorded them, relative to /tf (by the bag's record times): the images would "
            "take the poses of that much later; give --time-offset "
            f"{offset_s:.3f} to shift the image times, or --timestamps bag to use the record "
            "times")


def id_step_notes(ids: Sequence[int], fps: float) -> list[str]:
    """A note when the frame numbers that place frames (frame n at n / ``fps``) advance
    by a common step above 1 (every k-th frame of a recording kept): ``fps`` is then the
    rate of the numbering, and the note says what the frames span; else none."""
    steps = np.diff(np.asarray(sorted(ids), dtype=np.int64))
    step = int(np.gcd.reduce(steps)) if steps.size else 1
    if step <= 1:
        return []
    span = (max(ids) - min(ids)) / fps
    return [f"the frame numbers advance by {step} (every {step}th frame of a recording): "
            f"frame n is at n/{fps:g} s, so --fps is the rate of the numbering, not of these "
            f"{len(ids)} frames; they span {span:.3g} s ({len(ids) / span:.3g} frames a "
            "second)"]
