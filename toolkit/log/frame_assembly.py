"""Assembling frames from the frame-topic messages of a log, pushed in log order.

A *frame* is the depth message at one log time together with the RGB and instance-id
messages of the same log time, the camera calibration in force and the camera pose composed
from the ``/tf`` transforms (world -> ... -> camera) in force at that time (links that do not
move may come once on ``/tf_static``). The reader
(:meth:`sgtool.log.reader.LogReader.frames`) and replay
(:mod:`sgtool.replayers.derived_log`) both assemble frames with :class:`FrameAssembler`.

**Which time pairs /tf with frames** (``tf_time``): by default the *log time*, the time
each message was recorded (sgtool's writers stamp every message with its log time, so the
two agree exactly in sgtool's own logs). A log whose ``/tf`` header stamps disagree with
their log times is checked, since pairing by one time or the other builds another map:
an offset beyond :data:`TF_STAMP_WARN_S` is noted (:meth:`FrameAssembler.tf_stamp_note`,
naming the largest offset and ``--tf-time``), one beyond :data:`TF_STAMP_REFUSE_S` is
refused (:class:`LogFormatError`). With ``tf_time="stamp"`` transforms are keyed by their
header stamps and a frame's pose is looked up at its depth image's header stamp; the
offsets are then not checked. A stamp of 0 (unset) counts as the log time. Either way a
frame waits, for a while, for the transforms after its time (:class:`FrameAssembler`):
a pose is interpolated between the samples around it, as ``tf2`` does.
"""

from __future__ import annotations

import bisect
import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, TypeVar

import numpy as np

from sgtool.errors import LogFormatError
from sgtool.log import codec
from sgtool.log import schemas as S
from sgtool.log.frame import CameraIntrinsics, Frame
from sgtool.log.poses import interpolate

T = TypeVar("T")
_Snapshot = dict[str, tuple[np.ndarray, int]] | None


class TransformBuffer:
    """Transforms by (parent, child) over time. A link's value at time t is its sample at
    t, else interpolated between the samples around t (linear in translation, slerp in
    rotation, as ``tf2`` does) when they are no further apart than :func:`gap_limit`
    allows, else the latest before t; before a link's first sample, that sample when it is at most
    :data:`NEAR_NS` away. A ``static`` link (``/tf_static``) holds at every time, a link
    sent once on ``/tf`` (:meth:`_fixed`) from its time on."""

    def __init__(self) -> None:
        self._parent: dict[str, str] = {}
        self._times: dict[str, list[int]] = {}
        self._values: dict[str, list[np.ndarray]] = {}
        self._static: set[str] = set()
        self._latest = -(2**63)  # the latest sample time of any link

    def add(self, t_ns: int, parent: str, child: str, T: np.ndarray,  # noqa: N803
            static: bool = False) -> None:
        self._parent[child] = parent
        self._latest = max(self._latest, t_ns)
        if static:
            self._static.add(child)
        times = self._times.setdefault(child, [])
        vals = self._values.setdefault(child, [])
        if times and t_ns < times[-1]:
            i = bisect.bisect_right(times, t_ns)
            times.insert(i, t_ns)
            vals.insert(i, T)
        else:
            times.append(t_ns)
            vals.append(T)

    def _chain(self, target: str, root: str) -> list[str] | None:
        """The children of the links from ``target`` up to ``root``; None when unknown."""
        out: list[str] = []
        frame = target
        for _ in range(32):
            if frame == root:
                return out
            if frame not in self._parent:
                return None
            out.append(frame)
            frame = self._parent[frame]
        return None

    def _fixed(self, child: str) -> bool:
        """A link that does not move: from ``/tf_static``, or sent once on ``/tf`` (no
        second sample came within :data:`HOLD_NS` of later transforms)."""
        times = self._times[child]
        return child in self._static or (len(times) == 1 and
                                         self._latest - times[0] > HOLD_NS)

    def covers(self, t_ns: int, target: str, root: str = S.WORLD_FRAME) -> bool:
        """Every moving link from ``root`` to ``target`` has a sample at or after ``t_ns``
        (so no later transform can change the pose at ``t_ns``)."""
        chain = self._chain(target, root)
        return chain is not None and all(
            self._fixed(c) or self._times[c][-1] >= t_ns for c in chain)

    def _link(self, child: str, t_ns: int) -> tuple[np.ndarray, int] | None:
        """The link's value at ``t_ns`` (class doc) and how far its sample lies from
        ``t_ns`` when it was not interpolated (0 when it was, or the link is fixed)."""
        times, vals = self._times[child], self._values[child]
        i = bisect.bisect_right(times, t_ns) - 1
        if self._fixed(child) and (i >= 0 or child in self._static):
            return vals[max(i, 0)], 0
        if i >= 0 and times[i] == t_ns:
            return vals[i], 0
        if i < 0:
            return (vals[0], times[0] - t_ns) if times[0] - t_ns <= NEAR_NS else None
        if i + 1 < len(times) and times[i + 1] - times[i] <= gap_limit(times, i):
            a = (t_ns - times[i]) / (times[i + 1] - times[i])
            return interpolate(vals[i], vals[i + 1], a), 0
        return vals[i], t_ns - times[i]

    def snapshot(self, t_ns: int, target: str, root: str = S.WORLD_FRAME
                 ) -> dict[str, tuple[np.ndarray, int]] | None:
        """Each link's value at ``t_ns`` from the samples read so far (:meth:`resolve`
        falls back on it); None when the chain is not known."""
        chain = self._chain(target, root)
        if chain is None:
            return None
        out = {}
        for child in chain:
            link = self._link(child, t_ns)
            if link is not None:
                out[child] = link
        return out

    def resolve(self, t_ns: int, target: str, root: str = S.WORLD_FRAME,
                snapshot: dict[str, tuple[np.ndarray, int]] | None = None
                ) -> tuple[np.ndarray, int] | None:
        """root_T_target at ``t_ns`` and the largest distance in time of a sample taken as
        it is (not interpolated; 0 when every moving link was exact or interpolated), or
        None when the chain is not known. A moving link with no sample at or after
        ``t_ns`` takes its value from ``snapshot`` when it has one (what was read when
        the frame was assembled)."""
        chain = self._chain(target, root)
        if chain is None:
            return None
        T, age = None, 0  # noqa: N806 - the identity until the first link
        for child in chain:
            later = self._fixed(child) or self._times[child][-1] >= t_ns
            link = (snapshot.get(child) if snapshot is not None and not later else None) \
                or self._link(child, t_ns)
            if link is None:
                return None
            T = link[0].copy() if T is None else link[0] @ T  # noqa: N806
            age = max(age, link[1])
        return (np.eye(4) if T is None else T), age

    def lookup(self, t_ns: int, target: str, root: str = S.WORLD_FRAME) -> np.ndarray | None:
        """root_T_target at ``t_ns``, or None when the chain is not known yet."""
        found = self.resolve(t_ns, target, root)
        return None if found is None else found[0]


MAX_GAP_NS = 1_000_000_000  # /tf samples further apart: a dropout, before a rate is known
MIN_GAP_NS = 250_000_000  # /tf samples this near are interpolated whatever the rate
GAP_FACTOR = 2.5  # /tf samples more than this many usual intervals apart: a dropout
RATE_SAMPLES = 16  # the samples before a gap whose intervals give the usual one
NEAR_NS = 50_000_000  # a link's first sample counts this far before it
HOLD_NS = 1_000_000_000  # a frame waits this long (log time) for a later /tf
MAX_HELD = 64  # frames held at most (a /tf that stopped)
STALE_NS = 50_000_000  # a pose from /tf older than this is noted




def gap_limit(times: list[int], i: int) -> int:
    """The widest gap (ns) after sample ``i`` of a link's sample ``times`` that is still
    interpolated: :data:`GAP_FACTOR` times the median interval of the
    :data:`RATE_SAMPLES` samples up to ``i``, at least :data:`MIN_GAP_NS`, so a /tf that
    stops for a few of its samples is a dropout whatever its rate (a 0.75 s gap in a 4 Hz
    /tf was interpolated across a turn and split a room), and a slow /tf is not one;
    :data:`MAX_GAP_NS` with fewer than three samples."""
    if i < 2:
        return MAX_GAP_NS
    lo = max(0, i - RATE_SAMPLES)
    steps = sorted(b - a for a, b in zip(times[lo:i], times[lo + 1:i + 1], strict=True))
    return max(MIN_GAP_NS, int(GAP_FACTOR * steps[len(steps) // 2]))


FRAME_TOPICS = (S.RGB, S.DEPTH, S.IDS, S.CALIBRATION, S.TF, S.TF_STATIC)
TF_TIMES = ("log", "stamp")  # what pairs /tf with frames (module doc)
TF_STAMP_WARN_S = 0.05  # /tf stamps further than this from their log times: a note
TF_STAMP_REFUSE_S = 1.0  # ... further than this: refused (pairing by log time)
TF_TIME_OPTION = "--tf-time stamp"  # how a user of replay pairs by stamps instead


def stamp_ns(message: Any) -> int | None:
    """The header stamp of a decoded message in ns (its ``timestamp``), None when it has
    none or it is 0 (unset)."""
    ts = getattr(message, "timestamp", None)
    if ts is None:
        return None
    try:
        t = int(ts.seconds) * 1_000_000_000 + int(ts.nanos)
    except (AttributeError, TypeError, ValueError):
        return None
    return t or None


@dataclass
class TfStampOffsets:
    """How far ``/tf`` header stamps lie from their log times (stamp minus log time):
    ``checked`` messages with a stamp, ``beyond`` those past :data:`TF_STAMP_WARN_S`, and
    the ``worst`` offset (largest in size, signed, ns) with the log time it was met at."""

    checked: int = 0
    beyond: int = 0
    worst_ns: int = 0
    worst_at_ns: int = 0

    def add(self, log_ns: int, offset_ns: int) -> None:
        self.checked += 1
        if abs(offset_ns) > TF_STAMP_WARN_S * 1e9:
            self.beyond += 1
        if abs(offset_ns) > abs(self.worst_ns):
            self.worst_ns, self.worst_at_ns = offset_ns, log_ns


@dataclass
class StalePoses:
    """Frames posed from a ``/tf`` sample older than :data:`STALE_NS` (no later sample
    came while they were held): how many, the largest age (ns) and the log time of its
    frame."""

    count: int = 0
    worst_ns: int = 0
    worst_at_ns: int = 0
    left_out: bool = False  # the frames were left out (unposed), not posed stale

    def add(self, age_ns: int, t_ns: int) -> bool:
        """Count a frame whose pose is ``age_ns`` old; True when it is stale."""
        if age_ns <= STALE_NS:
            return False
        self.count += 1
        if age_ns > self.worst_ns:
            self.worst_ns, self.worst_at_ns = age_ns, t_ns
        return True

    def note(self, where: str = "") -> str | None:
        """One line when any frame was posed from a stale ``/tf`` (or left out for it),
        else None."""
        if not self.count:
            return None
        prefix = f"{where}: " if where else ""
        if self.left_out:
            return (f"{prefix}{self.count} frame(s) left out: their camera pose would come "
                    f"from a {S.TF} sample older than the image (up to "
                    f"{self.worst_ns / 1e9:.3f} s, at log time {self.worst_at_ns} ns; "
                    f"{S.TF} samples more than {GAP_FACTOR:g} times their usual interval "
                    f"apart, and at least {MIN_GAP_NS / 1e9:g} s, are a dropout, not "
                    "interpolated), which misplaces their points where the camera moved")
        return (f"{prefix}{self.count} frame(s) took a camera pose from a {S.TF} sample "
                f"older than the image (up to {self.worst_ns / 1e9:.3f} s, at log time "
                f"{self.worst_at_ns} ns; no later {S.TF} came within "
                f"{HOLD_NS / 1e9:g} s): where the camera moved, their points are misplaced")


_IMAGES = {S.DEPTH: "depth", S.RGB: "rgb", S.IDS: "ids"}


def decoded(where: str, topic: str, t_ns: int, fn: Callable[[Any], T], message: Any) -> T:
    """``fn(message)``, with a :class:`LogFormatError` of ``fn`` naming the source, the
    channel and the log time as well as the field."""
    try:
        return fn(message)
    except LogFormatError as e:
        prefix = f"{where}: " if where else ""
        raise LogFormatError(f"{prefix}{topic} message at {t_ns} ns: {e}") from None


def _ids_image(msg: Any) -> np.ndarray:
    """Instance ids as int32, copied once."""
    return codec.decode_image(msg, np.int32)


class FrameAssembler:
    """Groups decoded frame-topic messages, pushed in log order, into frames: the depth
    image of one log time with the RGB and id images of the same time, the calibration in
    force and the camera pose from the transforms in force (module doc).

    :meth:`push` returns the frames finished by a message: the previous log time's when a
    message of a new log time arrives; :meth:`flush` the frame being assembled (when it
    has its depth image), so a caller that meets another record of the same time can take
    the frame first; :meth:`finish`, at the end, every frame still held. A frame is held
    (in order) until every moving ``/tf`` link of its pose has a sample at or after its
    time, so that a transform stamped a moment after the image still poses it (interpolated,
    :class:`TransformBuffer`), for at most :data:`HOLD_NS` of log time or
    :data:`MAX_HELD` frames; then a link with no later sample keeps the value read when
    the frame was assembled, and :attr:`stale` counts the frames posed from a sample older
    than :data:`STALE_NS`.

    Inconsistent sensor data is refused with a :class:`LogFormatError` naming ``where``
    (the log), the channel, the log time and the field: a transform that is not finite or
    whose quaternion cannot be normalised, a calibration with a short K or a focal length
    that is not positive, a depth image with no calibration before it, images whose size
    differs from the calibration's or from each other, zero-size images, instance ids in
    a non-integer encoding, two images of one channel at one log time, and (pairing by log
    time) a ``/tf`` header stamp more than :data:`TF_STAMP_REFUSE_S` from its log time.

    ``tf_time`` (one of :data:`TF_TIMES`) is the time that pairs ``/tf`` with frames
    (module doc); :attr:`tf_offsets` sums up how far the stamps lie from the log times.
    ``drop_stale``: a frame whose pose would come from a stale ``/tf`` sample (older than
    :data:`STALE_NS`: a ``/tf`` dropout (:func:`gap_limit`), or a ``/tf`` that
    stopped) gets no pose (NaN, as a frame /tf does not pose), so a mapper leaves it out
    rather than putting its whole depth image where the camera was seconds before."""

    def __init__(self, index: int = 0, transforms: TransformBuffer | None = None,
                 calibration: CameraIntrinsics | None = None, where: str = "",
                 tf_time: str = "log", drop_stale: bool = False) -> None:
        if tf_time not in TF_TIMES:
            raise ValueError(f"tf_time must be one of {', '.join(TF_TIMES)}, not {tf_time!r}")
        self.index = index
        self.transforms = transforms or TransformBuffer()
        self.calibration = calibration
        self.where = where
        self.tf_time = tf_time
        self.tf_offsets = TfStampOffsets()
        self.depth_offsets = TfStampOffsets()  # the depth images' stamps, the same way
        self._pending: dict[str, Any] = {}
        self._t: int | None = None
        self._now: int | None = None  # the latest log time pushed or ticked
        # frames waiting for /tf: the frame, its pose's time, the camera's frame id and the
        # links of its camera and base chains as read when it was assembled
        self._held: list[tuple[Frame, int, str, tuple[_Snapshot, _Snapshot]]] = []
        self.stale = StalePoses(left_out=drop_stale)
        # colour and id images at a log time without a depth image: never part of a frame
        self.unpaired: dict[str, int] = {"rgb": 0, "ids": 0}
        self.stale_left_out: set[int] = set()  # indices of the frames drop_stale left out

    def tf_stamp_note(self) -> str | None:
        """One line when ``/tf`` stamps disagreed with their log times beyond
        :data:`TF_STAMP_WARN_S` while pairing by log time (naming the largest offset and
        the option that pairs by stamps), else None."""
        return self._offsets_note(self.tf_offsets, f"{S.TF} message(s)", (
            f"frames were paired with {S.TF} by log time ({TF_TIME_OPTION} pairs them by "
            "stamps)"))

    def depth_stamp_note(self) -> str | None:
        """One line when depth images' header stamps lie more than :data:`TF_STAMP_WARN_S`
        from their log times while frames are paired with ``/tf`` by log time (images
        logged late, say: their poses are those of the log time), else None."""
        return self._offsets_note(self.depth_offsets, f"{S.DEPTH} image(s)", (
            f"each was posed by {S.TF} at its log time ({TF_TIME_OPTION} poses it at its "
            "stamp)"))

    def _offsets_note(self, o: TfStampOffsets, what: str, then: str) -> str | None:
        """The line of :meth:`tf_stamp_note` and :meth:`depth_stamp_note`."""
        if self.tf_time != "log" or not o.beyond:
            return None
        prefix = f"{self.where}: " if self.where else ""
        return (f"{prefix}{o.beyond} of {o.checked} {what} have header stamps more than "
                f"{TF_STAMP_WARN_S:g} s from their log times (at most {o.worst_ns / 1e9:+.3f} "
                f"s, at log time {o.worst_at_ns} ns); {then}")

    @property
    def time(self) -> int | None:
        """The log time of the frame being assembled (None before the first message)."""
        return self._t

    def push(self, topic: str, t_ns: int, message: Any) -> list[Frame]:
        out: list[Frame] = []
        if self._t is not None and t_ns != self._t:
            out = self.flush()
            self._drop_unpaired()
        self._t = t_ns
        self._now = t_ns if self._now is None else max(self._now, t_ns)
        if topic in (S.TF, S.TF_STATIC):  # /tf_static: links written once
            T = decoded(self.where, topic, t_ns, codec.decode_transform, message)  # noqa: N806
            tf_t = self._tf_key(t_ns, message)
            self.transforms.add(tf_t, message.parent_frame_id, message.child_frame_id, T,
                                static=topic == S.TF_STATIC)
            out += self._release()
        elif topic == S.CALIBRATION:
            self.calibration = decoded(self.where, topic, t_ns, codec.decode_calibration,
                                       message)
        elif topic in _IMAGES:
            key = _IMAGES[topic]
            if key in self._pending:
                self._fail(topic, t_ns, "a second image of this channel at the same log "
                           "time (each frame needs its own log time)")
            self._pending[key] = message
        return out

    def unpaired_note(self) -> str | None:
        """One line when colour or instance-id images came at a log time without a depth
        image (a writer that logs them apart, even by a millisecond): they are in no frame,
        and the map has no colour or no objects from them; else None."""
        parts = [f"{n} {what} image(s)" for key, what in (("ids", "instance-id"),
                                                          ("rgb", "colour"))
                 if (n := self.unpaired.get(key, 0))]
        if not parts:
            return None
        prefix = f"{self.where}: " if self.where else ""
        return (f"{prefix}{' and '.join(parts)} at a log time without a depth image were "
                "not used: a frame is the depth, colour and id images of one log time (log "
                "them at the depth image's time)")

    def tick(self, t_ns: int) -> list[Frame]:
        """Log time ``t_ns`` has come (a message the caller does not push): the held frames
        that waited long enough."""
        self._now = t_ns if self._now is None else max(self._now, t_ns)
        return self._release()

    def finish(self) -> list[Frame]:
        """After the last message: the frame being assembled and every frame held."""
        out = self.flush()
        self._drop_unpaired()
        return out + self._release(final=True)

    def _drop_unpaired(self) -> None:
        """Its log time over: the images still pending had no depth image (counted)."""
        for key in self._pending:
            self.unpaired[key] = self.unpaired.get(key, 0) + 1
        self._pending = {}

    @property
    def holding(self) -> bool:
        """Frames are held for a later ``/tf`` (class doc)."""
        return bool(self._held)

    @property
    def first_held(self) -> int | None:
        """The index of the first frame held for a later ``/tf``; None when none is."""
        return self._held[0][0].index if self._held else None

    def _release(self, final: bool = False) -> list[Frame]:
        """The held frames, in order, whose pose no later ``/tf`` can change, or that waited
        long enough (class doc); every one when ``final``. A link of a frame that waited
        in vain keeps the value it had when the frame was assembled."""
        out: list[Frame] = []
        while self._held:
            fr, at, camera, snaps = self._held[0]
            if not (final or len(self._held) > MAX_HELD
                    or self.transforms.covers(at, camera)
                    or (self._now is not None and self._now - fr.time_ns > HOLD_NS)):
                break
            self._held.pop(0)
            found = self.transforms.resolve(at, camera, snapshot=snaps[0])
            if found is None:
                out.append(fr)  # (its pose is NaN: no chain at its time)
                continue
            if self.stale.add(found[1], fr.time_ns) and self.stale.left_out:
                self.stale_left_out.add(fr.index)
                out.append(fr)  # (its pose is NaN: left out, not posed from a stale /tf)
                continue
            base = self.transforms.resolve(at, S.BASE_FRAME, snapshot=snaps[1])
            out.append(dataclasses.replace(fr, pose=found[0],
                                           base_pose=None if base is None else base[0]))
        return out

    def _tf_key(self, t_ns: int, message: Any) -> int:
        """The time a transform is kept under: its stamp (``tf_time`` "stamp") or its log
        time, whose distance from the stamp is checked (module doc)."""
        stamp = stamp_ns(message)
        if stamp is None:
            return t_ns
        if self.tf_time == "stamp":
            return stamp
        offset = stamp - t_ns
        self.tf_offsets.add(t_ns, offset)
        if abs(offset) > TF_STAMP_REFUSE_S * 1e9:
            self._fail(S.TF, t_ns, f"its header stamp is {offset / 1e9:+.3f} s from its log "
                       f"time (more than {TF_STAMP_REFUSE_S:g} s): frames are paired with "
                       f"{S.TF} by log time, which would build another map than its stamps "
                       f"say; {TF_TIME_OPTION} pairs them by stamps")
        return t_ns

    def _fail(self, topic: str, t_ns: int, why: str) -> None:
        prefix = f"{self.where}: " if self.where else ""
        raise LogFormatError(f"{prefix}{topic} message at {t_ns} ns: {why}")

    def flush(self) -> list[Frame]:
        """The frame of the current log time, if its depth image has arrived (it is then
        handed out once, now or, held for a later ``/tf``, by a later call), after the
        frames held before it that can go."""
        pending, t = self._pending, self._t
        if "depth" not in pending or t is None:
            return self._release()
        self._pending = {}
        depth_msg = pending["depth"]
        if self.tf_time == "log" and (stamp := stamp_ns(depth_msg)) is not None:
            self.depth_offsets.add(t, stamp - t)
        k = self.calibration
        if k is None:
            self._fail(S.DEPTH, t, f"no camera calibration ({S.CALIBRATION}) before it")
        assert k is not None
        depth = decoded(self.where, S.DEPTH, t, codec.depth_from_image, depth_msg)
        if depth.shape != (k.height, k.width):
            self._fail(S.DEPTH, t, f"fields width/height: {depth.shape[1]}x{depth.shape[0]} "
                       f"pixels, the camera calibration says {k.width}x{k.height}")
        rgb = ids = None
        if "rgb" in pending:
            rgb = decoded(self.where, S.RGB, t, codec.decode_image, pending["rgb"])
        if "ids" in pending:
            if pending["ids"].encoding not in codec.INTEGER_ENCODINGS:
                self._fail(S.IDS, t, f"field encoding: instance ids must be integers, not "
                           f"{pending['ids'].encoding[:40]!r}")
            ids = decoded(self.where, S.IDS, t, _ids_image, pending["ids"])
        for topic, img in ((S.RGB, rgb), (S.IDS, ids)):
            if img is not None and img.shape[:2] != depth.shape:
                self._fail(topic, t, f"fields width/height: {img.shape[1]}x{img.shape[0]} "
                           f"pixels, the depth image is {depth.shape[1]}x{depth.shape[0]}")
        at = t
        if self.tf_time == "stamp":
            at = stamp_ns(depth_msg) or t
        fr = Frame(index=self.index, time_ns=t, rgb=rgb, depth=depth, ids=ids,
                   pose=np.full((4, 4), np.nan), intrinsics=k)
        self.index += 1
        camera = depth_msg.frame_id or S.CAMERA_FRAME
        self._held.append((fr, at, camera, (self.transforms.snapshot(at, camera),
                                            self.transforms.snapshot(at, S.BASE_FRAME))))
        return self._release()
