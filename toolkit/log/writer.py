"""Writing sgtool logs (MCAP).

The writer is crash tolerant and atomic:
- it writes to a partial file with a unique name beside the output, ``OUT.XXXXXXXX.partial``
  (``XXXXXXXX``: eight random characters; the pattern is :data:`PARTIAL_GLOB`, listed by
  :func:`partial_files`), and renames it to ``OUT`` only when :meth:`LogWriter.close`
  succeeds. Two writers of one output never share a file: each renames its own complete
  log, and the last rename wins;
- an exception inside ``with LogWriter(...)`` removes the partial file, so a failed command
  never leaves a half-written output behind. A destination that cannot be written
  (read-only or missing folder, full disk) is a one-line
  :class:`~sgtool.files.OutputError` and leaves nothing behind;
- Ctrl-C (:class:`KeyboardInterrupt`) keeps the partial file when it holds messages, and
  re-raises as :class:`InterruptedWrite`, whose text names the file and the
  ``sgtool doctor`` line that recovers it; a writer of output that can be made again
  (``keep_partial=False``: a replay's derived log) removes it instead;
- it closes and flushes a chunk to the operating system at least every
  ``flush_interval_ns`` of log time (1 s by default) and whenever a chunk exceeds
  ``chunk_size``; a process killed with SIGKILL leaves ``OUT.XXXXXXXX.partial`` whose
  complete chunks ``sgtool doctor OUT.XXXXXXXX.partial --recover OUT`` turns into a valid
  log, losing at most that last interval.

Every chunk and the data section carry CRCs (``sgtool doctor`` checks them). Output is
deterministic: the same calls give the same bytes (no wall clock is written).
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping
from pathlib import Path
from types import TracebackType
from typing import IO, TYPE_CHECKING, Any, overload

import numpy as np
from mcap.summary import Summary
from mcap.writer import CompressionType, Writer
from mcap_protobuf.schema import build_file_descriptor_set

from sgtool.arg_checks import whole
from sgtool.errors import LogFormatError, SgtoolError, Terminated
from sgtool.files import (
    appeared_error,
    concerns,
    output_error,
    quoted,
    temp_beside,
    temp_prefix,
)
from sgtool.log import chunk_copy, codec
from sgtool.log import schemas as S
from sgtool.log.frame import CameraIntrinsics
from sgtool.log.records import RECORD_TYPES, Instances, LogRecord
from sgtool.publish import publish
from sgtool.version import __version__
from sgtool.vocabulary import RecordName

if TYPE_CHECKING:
    from google.protobuf.message import Message

PARTIAL_SUFFIX = ".partial"
PARTIAL_GLOB = "*.????????" + PARTIAL_SUFFIX  # OUT.XXXXXXXX.partial, see the module doc


def partial_files(path: str | os.PathLike[str]) -> list[Path]:
    """The partial files that writers of ``path`` left (killed or interrupted), newest
    first: ``OUT.XXXXXXXX.partial`` beside ``OUT``."""
    path = Path(path)
    if not path.parent.is_dir():
        return []
    head = temp_prefix(path.name, PARTIAL_SUFFIX, hidden=False)  # a long name is cut
    found = [p for p in path.parent.glob(f"{glob_escape(head)}????????{PARTIAL_SUFFIX}")
             if p.is_file()]
    return sorted(found, key=lambda p: (p.stat().st_mtime_ns, p.name), reverse=True)


def glob_escape(name: str) -> str:
    """``name`` with the glob special characters quoted."""
    return "".join(f"[{c}]" if c in "*?[" else c for c in name)


class InterruptedWrite(KeyboardInterrupt):
    """Ctrl-C while writing a log; ``str()`` says what was kept (the partial file and how
    to recover it) or that nothing was written."""

    def __init__(self, note: str, partial: Path | None) -> None:
        super().__init__(note)
        self.note = note
        self.partial = partial

    def __reduce__(self) -> tuple[Any, ...]:  # pickles (from a worker process) as built
        return type(self), (self.note, self.partial)


class TerminatedWrite(InterruptedWrite, Terminated):
    """:class:`InterruptedWrite` after a kill (SIGTERM): still a
    :class:`~sgtool.errors.Terminated`, so the command exits as killed."""


_COMPRESSION = {
    "zstd": CompressionType.ZSTD,
    "lz4": CompressionType.LZ4,
    "none": CompressionType.NONE,
}
COMPRESSIONS: tuple[str, ...] = tuple(_COMPRESSION)  # the names a log may be written with


def _check_frame(k: CameraIntrinsics, depth: np.ndarray, rgb: np.ndarray | None,
                 ids: np.ndarray | None) -> None:
    """``ValueError`` unless the frame's images would read back as written: depth of the
    intrinsics' size and not negative, rgb (H, W, 3) and ids (H, W) of the depth's (the intrinsics
    themselves are checked where their calibration message is made, when they change)."""
    if not isinstance(k, CameraIntrinsics):
        raise ValueError(f"intrinsics: a CameraIntrinsics, got {type(k).__name__}")
    size = (k.height, k.width)
    if np.shape(depth) != size:
        raise ValueError(f"depth of shape {np.shape(depth)}: the intrinsics say {k.width}x"
                         f"{k.height}, so ({k.height}, {k.width})")
    check_depth_sign(depth)
    if rgb is not None and np.shape(rgb) != (*size, 3):
        raise ValueError(f"rgb of shape {np.shape(rgb)}: give ({k.height}, {k.width}, 3), "
                         "the depth's size")
    if ids is not None and np.shape(ids) != size:
        raise ValueError(f"ids of shape {np.shape(ids)}: give ({k.height}, {k.width}), the "
                         "depth's size")


def check_depth_sign(depth: Any) -> None:
    """``ValueError`` naming the first pixel of ``depth`` with a finite negative value (it
    would read back as no return, which is 0, NaN or an infinity)."""
    d = np.asarray(depth)
    if d.ndim != 2 or not np.issubdtype(d.dtype, np.number):
        return
    neg = np.argwhere(np.isfinite(d) & (d < 0))
    if len(neg):
        r, c = (int(v) for v in neg[0])
        raise ValueError(f"depth {float(d[r, c]):g} m at pixel (row {r}, col {c}): "
                         "negative (no return is 0, NaN or inf)")


def log_time(t_ns: Any) -> int:
    """``t_ns`` as a log time: whole nanoseconds, at least 0; anything else (a float with a
    fraction, such as seconds given by mistake, which would truncate to the same time as
    its neighbours) is a ``ValueError`` naming it."""
    if isinstance(t_ns, bool) or not isinstance(t_ns, int | float | np.integer | np.floating):
        raise ValueError(f"log time {t_ns!r}: a time in whole nanoseconds (an int)")
    if isinstance(t_ns, float | np.floating) and not (
            math.isfinite(t_ns) and float(t_ns).is_integer()):
        raise ValueError(f"log time {t_ns!r}: times are whole nanoseconds (seconds? "
                         "int(round(t * 1e9)))")
    t = int(t_ns)
    if t < 0:
        raise ValueError(f"log time {t}: must be >= 0")
    return t


class LogWriter:
    """Writes one sgtool log. Use as a context manager::

        with LogWriter("run.mcap", seed=3) as log:
            log.attach_house(house_json)
            log.write_record(Instances.of([...]), 0)
            log.write_frame(t_ns, rgb=rgb, depth=depth_m, ids=ids, pose=world_T_cam,
                            intrinsics=k, base_pose=world_T_base)
    """

    def __init__(
        self,
        path: str | os.PathLike[str],
        *,
        seed: int | None = None,
        compression: str = "zstd",
        chunk_size: int = 8 * 1024 * 1024,
        flush_interval_ns: int = 1_000_000_000,
        metadata: dict[str, str] | None = None,
        overwrite: bool = True,
        keep_partial: bool = True,
    ) -> None:
        if compression not in _COMPRESSION:
            raise SgtoolError(f"unknown compression {compression!r} (zstd, lz4, none)")
        whole("seed", seed, optional=True)  # (a log's own seed is copied as it is)
        self.path = Path(path)
        if self.path.exists() and not overwrite:
            raise SgtoolError(f"{self.path} exists; not overwriting it (use --force, "
                              "overwrite=True)")
        if self.path.is_dir():
            raise SgtoolError(f"{self.path} is a folder, not a file name")
        if not self.path.parent.exists():
            raise SgtoolError(f"folder {self.path.parent} does not exist")
        try:
            fd, self.partial_path = temp_beside(self.path, PARTIAL_SUFFIX, hidden=False)
        except OSError as e:
            raise output_error(e, self.path) from None
        self._stream: IO[bytes] = os.fdopen(fd, "wb")
        self._compression = "" if compression == "none" else compression
        self._closed = False
        self._keep_on_interrupt = keep_partial
        self._checked_items: set[str] = set()  # instance-table items checked (JSON texts)
        self.message_count = 0
        try:
            self._mcap = Writer(
                self._stream, chunk_size=chunk_size, compression=_COMPRESSION[compression],
                enable_data_crcs=True)
            self._mcap.start(profile=S.PROFILE, library=f"sgtool {__version__}")
            meta = {
                "sgtool_version": __version__,
                "log_schema_version": S.format_version(S.LOG_SCHEMA_VERSION),
                "seed": "" if seed is None else str(int(seed)),
            }
            meta.update(metadata or {})
            self._mcap.add_metadata(S.METADATA_NAME, meta)
            self._mcap.flush()  # metadata first: even a log killed in its first second has it
        except BaseException as e:
            self.abort()
            if isinstance(e, OSError):
                raise output_error(e, self.path) from None
            raise
        self._flush_interval_ns = int(flush_interval_ns)
        self._last_flush_ns: int | None = None
        self._schemas: dict[str, int] = {}
        self._channels: dict[str, int] = {}
        self._sequence: dict[int, int] = {}
        self._last_calibration: CameraIntrinsics | None = None
        self._last_frame_t: int | None = None  # write_frame's last time

    # ----- channels ---------------------------------------------------------------------
    def _proto_channel(self, topic: str, message_class: Any) -> int:
        if topic in self._channels:
            return self._channels[topic]
        name = message_class.DESCRIPTOR.full_name
        if name not in self._schemas:
            fds = build_file_descriptor_set(message_class)
            self._schemas[name] = self._mcap.register_schema(
                name=name, encoding="protobuf", data=fds.SerializeToString(deterministic=True)
            )
        cid = self._mcap.register_channel(
            topic=topic, message_encoding="protobuf", schema_id=self._schemas[name]
        )
        self._channels[topic] = cid
        return cid

    def _json_channel(self, kind: S.RecordKind) -> int:
        if kind.topic in self._channels:
            return self._channels[kind.topic]
        if kind.schema_name not in self._schemas:
            self._schemas[kind.schema_name] = self._mcap.register_schema(
                name=kind.schema_name, encoding="jsonschema", data=kind.schema_bytes()
            )
        cid = self._mcap.register_channel(
            topic=kind.topic, message_encoding="json", schema_id=self._schemas[kind.schema_name],
            metadata={"version": kind.version},
        )
        self._channels[kind.topic] = cid
        return cid

    def _add(self, cid: int, t_ns: int, data: bytes, sequence: int | None = None,
             publish_ns: int | None = None) -> None:
        if self._closed:
            raise RuntimeError("log writer is closed")
        t_ns = log_time(t_ns)
        if self._last_flush_ns is None:
            self._last_flush_ns = t_ns
        elif t_ns - self._last_flush_ns >= self._flush_interval_ns:
            # close the chunk before the first message of the next interval, so chunks
            # hold whole frames and a crash loses at most one interval of log time
            self._mcap.flush()
            self._last_flush_ns = t_ns
        seq = self._sequence.get(cid, 0)
        self._sequence[cid] = seq + 1
        self._mcap.add_message(
            channel_id=cid, log_time=t_ns, publish_time=t_ns if publish_ns is None else publish_ns,
            data=data, sequence=seq if sequence is None else sequence)
        self.message_count += 1

    def copy_channel(self, topic: str, schema_name: str, schema_encoding: str,
                     schema_data: bytes, message_encoding: str,
                     metadata: dict[str, str] | None = None) -> int:
        """Register a channel copied from another log, with its schema as it is (a foreign
        schema keeps its bytes); returns the channel id for :meth:`write_raw`. A topic
        copied twice gets the same id."""
        if topic in self._channels:
            return self._channels[topic]
        key = f"copy\0{schema_name}\0{schema_encoding}\0" + schema_data.hex()
        sid = self._schemas.get(key)
        if sid is None:
            if schema_name or schema_encoding or schema_data:
                sid = self._mcap.register_schema(name=schema_name, encoding=schema_encoding,
                                                 data=schema_data)
            else:
                sid = 0  # a schemaless channel
            self._schemas[key] = sid
        cid = self._mcap.register_channel(topic=topic, message_encoding=message_encoding,
                                          schema_id=sid, metadata=dict(metadata or {}))
        self._channels[topic] = cid
        return cid

    def write_raw(self, channel_id: int, t_ns: int, data: bytes, sequence: int | None = None,
                  publish_ns: int | None = None) -> None:
        """Write already encoded message bytes on a channel of :meth:`copy_channel` (or
        :meth:`copy_channels`); sequence number and publish time default to this writer's
        count of the channel's messages and the log time."""
        self._add(channel_id, t_ns, data, sequence, publish_ns)

    def copy_channels(self, summary: Summary) -> bool:
        """Register every schema and channel of another log's ``summary`` under its own
        id, for :meth:`copy_chunk` and :meth:`write_raw`. False, and nothing registered,
        when this writer has channels already, two channels share a topic, or the ids are
        not 1..N (:func:`~sgtool.log.chunk_copy.ids_problem`), or the ``mcap`` writer
        cannot take copied chunks (:func:`~sgtool.log.chunk_copy.writer_supported`)."""
        topics = {ch.topic for ch in summary.channels.values()}
        if (self._schemas or self._channels or len(topics) != len(summary.channels)
                or chunk_copy.ids_problem(summary)
                or not chunk_copy.writer_supported(self._mcap)):
            return False
        with chunk_copy.outside_chunks(self._mcap):  # before any chunk copied after them
            for sid, schema in sorted(summary.schemas.items()):
                self._schemas[f"copied\0{sid}"] = self._mcap.register_schema(
                    name=schema.name, encoding=schema.encoding, data=bytes(schema.data))
            for _, ch in sorted(summary.channels.items()):
                self._channels[ch.topic] = self._mcap.register_channel(
                    topic=ch.topic, message_encoding=ch.message_encoding,
                    schema_id=ch.schema_id, metadata=dict(ch.metadata))
        return True

    def copy_chunk(self, chunk: chunk_copy.RawChunk) -> bool:
        """Write a chunk of another log as it is (:mod:`sgtool.log.chunk_copy`), after the
        messages written so far; its channels must come from :meth:`copy_channels`. False
        (nothing written) when it is not compressed as this log is."""
        if self._closed:
            raise RuntimeError("log writer is closed")
        if chunk.index.compression != self._compression:
            return False
        chunk_copy.append_chunk(self._mcap, self._stream, chunk)
        self.message_count += sum(chunk.counts.values())
        return True

    # ----- generic ----------------------------------------------------------------------
    def write_proto(self, topic: str, t_ns: int, msg: Message) -> None:
        """Write any protobuf message (e.g. a Foxglove SceneUpdate) on ``topic``."""
        cid = self._proto_channel(topic, type(msg))
        self._add(cid, t_ns, msg.SerializeToString(deterministic=True))

    @overload
    def write_record(self, record: LogRecord, t_ns: int) -> dict[str, Any]: ...

    @overload
    def write_record(self, record: RecordName, t_ns: int, data: Mapping[str, Any]
                     ) -> dict[str, Any]: ...

    def write_record(self, record: LogRecord | RecordName, t_ns: int,
                     data: Mapping[str, Any] | None = None) -> dict[str, Any]:
        """Write a typed sgtool JSON record (:mod:`sgtool.log.records`) on its channel,
        checked against its schema first (a :class:`~sgtool.errors.LogFormatError` names
        the field that is wrong); returns the JSON object written (what a reader of the
        log gets back).

        An instance table checks only the items this writer has not checked before in an
        earlier table (:meth:`~sgtool.log.records.Instances.check_since`: a table written
        again on every door that opens differs from the last in an item or two).

        ``write_record(kind, t_ns, dict)`` (the form before typed records) reads the dict
        as that kind's record and writes it the same way."""
        if isinstance(record, str):
            rtype = RECORD_TYPES.get(record)
            if rtype is None:
                raise ValueError(f"unknown record kind {record!r}; one of {sorted(RECORD_TYPES)}")
            record = rtype.from_json(dict(data or {}),
                                     where=rtype.describe(t_ns=int(t_ns)) + " to write")
        if not isinstance(record, LogRecord):
            raise TypeError(f"write_record takes an sgtool.log.records record, not "
                            f"{type(record).__name__}")
        where = record.describe(t_ns=int(t_ns)) + " to write"
        if isinstance(record, Instances):
            d = record.to_json()
            record.check_since(d, where, self._checked_items)
        else:
            d = record.checked_json(where)
        if (bad := refused_number(d)) is not None:
            raise LogFormatError(f"{where}: field {bad[0]!r} is {bad[1]!r}: "
                                 + ("a distance is never negative" if bad[1] < 0 else
                                    "NaN and infinity are no JSON numbers"))
        cid = self._json_channel(record.channel())
        self._add(cid, t_ns, json.dumps(d, sort_keys=True, separators=(",", ":")).encode())
        return d

    def attach(self, name: str, data: bytes, media_type: str, t_ns: int = 0,
               create_time_ns: int | None = None) -> None:
        """An attachment at log time ``t_ns``, created at ``create_time_ns`` (None: then
        too; a copied attachment keeps its own)."""
        self._mcap.add_attachment(
            create_time=t_ns if create_time_ns is None else create_time_ns, log_time=t_ns,
            name=name, media_type=media_type, data=data
        )

    def attach_house(self, house_json: str | bytes) -> None:
        data = house_json.encode() if isinstance(house_json, str) else house_json
        self.attach(S.HOUSE_ATTACHMENT, data, "application/json")

    def add_metadata(self, name: str, data: dict[str, str]) -> None:
        """Add an MCAP metadata record. MCAP strings are UTF-8: text that holds an OS file
        name's undecodable bytes (``surrogateescape``) keeps them as ``\\xNN`` escapes."""
        self._mcap.add_metadata(_utf8(name), {_utf8(k): _utf8(v) for k, v in data.items()})

    # ----- sensors ----------------------------------------------------------------------
    def write_rgb(self, t_ns: int, rgb: np.ndarray, frame_id: str = S.CAMERA_FRAME) -> None:
        self.write_proto(S.RGB, t_ns, codec.encode_image(t_ns, rgb, S.RGB_ENCODING, frame_id))

    def write_depth(self, t_ns: int, depth_m: np.ndarray, frame_id: str = S.CAMERA_FRAME) -> None:
        """Metric depth (float metres) or already uint16 millimetres; what would read back
        as no depth, or as other depth (a negative value), is a ``ValueError``
        (:func:`~sgtool.log.codec.encode_depth`, :func:`check_depth_sign`)."""
        check_depth_sign(depth_m)
        self.write_proto(S.DEPTH, t_ns, codec.encode_depth(t_ns, depth_m, frame_id))

    def write_ids(self, t_ns: int, ids: np.ndarray, frame_id: str = S.CAMERA_FRAME) -> None:
        """Instance ids as :func:`~sgtool.log.codec.encode_ids` writes them (16UC1 when they
        fit, else 32SC1)."""
        self.write_proto(S.IDS, t_ns, codec.encode_ids(t_ns, ids, frame_id))

    def write_calibration(
        self, t_ns: int, k: CameraIntrinsics, frame_id: str = S.CAMERA_FRAME
    ) -> None:
        self.write_proto(S.CALIBRATION, t_ns, codec.encode_calibration(t_ns, k, frame_id))
        self._last_calibration = k

    def write_transform(self, t_ns: int, parent: str, child: str, T: np.ndarray) -> None:  # noqa: N803
        """``T`` is parent_T_child: the pose of ``child`` in ``parent``."""
        self.write_proto(S.TF, t_ns, codec.encode_transform(t_ns, parent, child, T))

    def write_frame(
        self,
        t_ns: int,
        *,
        depth: np.ndarray,
        pose: np.ndarray,
        intrinsics: CameraIntrinsics,
        rgb: np.ndarray | None = None,
        ids: np.ndarray | None = None,
        base_pose: np.ndarray | None = None,
    ) -> None:
        """One time step. ``pose`` is world_T_camera; with ``base_pose`` (world_T_base) the
        transforms are written as the chain world -> base -> camera, else world -> camera.
        Calibration is written on the first frame and whenever it changes. Frame times
        must increase (a ``ValueError`` otherwise: a replay pairs messages by time), and so
        is anything that would read back as something else: images of another size than
        the intrinsics' (depth (H, W), rgb (H, W, 3), ids (H, W)), intrinsics a reader
        refuses, colours as float or beyond 0..255, ids as float."""
        t_ns = log_time(t_ns)
        if self._last_frame_t is not None and t_ns <= self._last_frame_t:
            raise ValueError(f"frame at t_ns={t_ns}: frame times must increase (the previous "
                             f"frame is at {self._last_frame_t})")
        # nested lists (as a pose may be given) are arrays here
        depth, pose = np.asarray(depth), np.asarray(pose, dtype=np.float64)
        rgb = None if rgb is None else np.asarray(rgb)
        ids = None if ids is None else np.asarray(ids)
        _check_frame(intrinsics, depth, rgb, ids)
        # every message encoded (and so checked) before the first is written: a refused
        # frame leaves nothing of itself in the log, and the same frame mended goes in
        out: list[tuple[str, Any]] = []
        if intrinsics != self._last_calibration:  # written, so checked, when it changes
            calibration = codec.encode_calibration(t_ns, intrinsics, S.CAMERA_FRAME)
            try:
                codec.decode_calibration(calibration)  # what a reader takes
            except LogFormatError as e:
                raise ValueError(f"intrinsics {intrinsics}: {e}") from None
            out.append((S.CALIBRATION, calibration))
        if base_pose is not None:
            base_T_cam = codec.relative(base_pose, pose)  # noqa: N806
            out += [(S.TF, codec.encode_transform(t_ns, S.WORLD_FRAME, S.BASE_FRAME,
                                                  base_pose)),
                    (S.TF, codec.encode_transform(t_ns, S.BASE_FRAME, S.CAMERA_FRAME,
                                                  base_T_cam))]
        else:
            out.append((S.TF, codec.encode_transform(t_ns, S.WORLD_FRAME, S.CAMERA_FRAME,
                                                     pose)))
        if rgb is not None:
            out.append((S.RGB, codec.encode_image(t_ns, rgb, S.RGB_ENCODING, S.CAMERA_FRAME)))
        out.append((S.DEPTH, codec.encode_depth(t_ns, depth, S.CAMERA_FRAME)))
        if ids is not None:
            out.append((S.IDS, codec.encode_ids(t_ns, ids, S.CAMERA_FRAME)))
        for topic, msg in out:
            self.write_proto(topic, t_ns, msg)
        self._last_calibration = intrinsics
        self._last_frame_t = int(t_ns)

    # ----- end --------------------------------------------------------------------------
    def flush(self) -> None:
        self._mcap.flush()

    def close(self) -> Path:
        """Finish the file (summary, index) and move it into place. Returns the path. A
        destination that fails now (full disk) is an :class:`~sgtool.files.OutputError`
        and the partial file is removed."""
        if self._closed:
            return self.path
        try:
            self._mcap.finish()
            self._stream.flush()
            os.fsync(self._stream.fileno())
            self._stream.close()
            self._closed = True
            publish(self.partial_path, self.path)
        except OSError as e:
            if isinstance(e, FileExistsError) and str(e.filename) == str(self.path):
                # (publish: another run wrote it) this run's finished log stays as it is
                raise appeared_error(self.path, kept=self.partial_path) from None
            self._closed = False
            self.abort()
            raise output_error(e, self.path) from None
        return self.path

    def abort(self) -> None:
        """Stop writing and remove the partial file."""
        self._closed = True
        try:
            self._stream.close()
        except OSError:
            pass  # a full disk refuses the buffered rest: the file goes anyway
        finally:
            self.partial_path.unlink(missing_ok=True)

    def _keep_partial(self, killed: bool = False) -> InterruptedWrite:
        """After Ctrl-C (or a kill: ``killed``): close the partial file with what it holds
        (complete chunks), or remove it when it holds no message; the exception to raise
        says which."""
        kind = TerminatedWrite if killed else InterruptedWrite
        self._closed = True
        kept = False
        try:
            if self.message_count:
                self._mcap.flush()
            self._stream.close()
            kept = self.message_count > 0
        except OSError:
            kept = False
        finally:
            if not kept:
                self.abort()
        if not kept:
            return kind(f"nothing written to {self.path}", None)
        p = self.partial_path
        force = " --force" if self.path.exists() else ""  # (an earlier log stays there)
        return kind(
            f"{self.path} not written; what was recorded is kept in {p} (recover it with: "
            f"sgtool doctor {quoted(p)} --recover {quoted(self.path)}{force})", p)

    def __enter__(self) -> LogWriter:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        if exc_type is None:
            self.close()
        elif issubclass(exc_type, KeyboardInterrupt) and not self._closed and \
                self._keep_on_interrupt:
            raise self._keep_partial(issubclass(exc_type, Terminated)) from None
        else:
            self.abort()
            if isinstance(exc, OSError) and concerns(exc, self.partial_path, self.path):
                raise output_error(exc, self.path) from None


def _utf8(text: str) -> str:
    """``text`` as valid UTF-8: lone surrogates (undecodable bytes of a file name) become
    ``\\xNN`` escapes; other text is returned unchanged."""
    try:
        text.encode("utf-8")
        return text
    except UnicodeEncodeError:
        return text.encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace")


DISTANCES = ("travelled_m", "shortest_m")  # record fields in metres: never negative


def refused_number(d: Any, path: str = "") -> tuple[str, float] | None:
    """The path and value of the first number of a record's JSON form that the log must
    not hold: NaN or infinite anywhere, negative in a top-level :data:`DISTANCES` field."""
    if isinstance(d, float) and not math.isfinite(d):
        return path, d
    if isinstance(d, Mapping):
        for k, v in d.items():
            if not path and k in DISTANCES and isinstance(v, int | float) and v < 0:
                return k, float(v)
            if (bad := refused_number(v, f"{path}.{k}" if path else str(k))) is not None:
                return bad
    elif isinstance(d, list | tuple):
        for i, v in enumerate(d):
            if (bad := refused_number(v, f"{path}[{i}]")) is not None:
                return bad
    return None
