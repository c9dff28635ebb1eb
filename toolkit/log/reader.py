"""Reading sgtool logs: frames, records, attachments, random access by time.

:class:`LogReader` opens an indexed MCAP file (a complete one: a truncated file gives a
:class:`~sgtool.errors.LogFormatError` that points to ``sgtool doctor --recover``). It
checks the log schema version of sgtool logs (a newer major version is refused with a
message naming both versions) and still opens foreign MCAP files (ROS 2 recordings) for
listing; operations that need an sgtool channel name it when it is missing.

A *frame* is the depth message at one log time together with the RGB and instance-id
messages of the same log time, the camera calibration in force and the camera pose composed
from the ``/tf`` transforms (world -> ... -> camera) in force at that time.
"""

from __future__ import annotations

import bisect
import io
import json
import os
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar, overload

from mcap.data_stream import ReadDataStream
from mcap.exceptions import InvalidMagic, McapError
from mcap.reader import SeekingReader
from mcap.records import Attachment, Channel, Message, MessageIndex, Schema
from mcap.summary import Summary

from sgtool.arg_checks import of_type
from sgtool.errors import (
    LogFormatError,
    MissingChannelError,
    SchemaVersionError,
    SgtoolError,
    SpecError,
)
from sgtool.files import quoted
from sgtool.log import chunk_stream as cs
from sgtool.log import codec, message_check, walk_index
from sgtool.log import frame_assembly as assembly
from sgtool.log import schemas as S
from sgtool.log.chunk_copy import RawChunk, raw_chunk
from sgtool.log.frame import CameraIntrinsics, Frame
from sgtool.log.frame_assembly import FRAME_TOPICS, FrameAssembler, TransformBuffer, decoded
from sgtool.log.image_wire import parse_raw_image
from sgtool.log.log_file import magic_problem, require_regular_file
from sgtool.log.records import LogRecord, record_type
from sgtool.log.summary_check import BoundedReader, check_summary, read_attachment, read_footer
from sgtool.vocabulary import RecordName

if TYPE_CHECKING:
    from sgtool.house.spec import HouseSpec

R = TypeVar("R", bound=LogRecord)

_PROTO_CLASSES: dict[str, Any] = {}


def proto_class(schema_name: str) -> Any:
    """The Foxglove protobuf class for a schema name, or None for other schemas."""
    if schema_name in _PROTO_CLASSES:
        return _PROTO_CLASSES[schema_name]
    cls = None
    if schema_name.startswith("foxglove."):
        import importlib

        short = schema_name.split(".", 1)[1]
        try:
            mod = importlib.import_module(f"foxglove_schemas_protobuf.{short}_pb2")
            cls = getattr(mod, short)
        except (ImportError, AttributeError):
            cls = None
    _PROTO_CLASSES[schema_name] = cls
    return cls


@dataclass(frozen=True)
class ChannelInfo:
    id: int
    topic: str
    schema_name: str
    schema_encoding: str
    message_encoding: str
    message_count: int


@dataclass(frozen=True)
class Decoded:
    topic: str
    log_time_ns: int
    schema_name: str
    message: Any  # protobuf message, dict (JSON) or bytes (unknown encodings)


class LogReader:
    """An open log (module doc). Opening checks the MCAP magic bytes, footer, summary and
    the log schema version (a newer major version is refused); a missing, truncated or
    damaged file is a one-line :class:`~sgtool.errors.LogFormatError` that names the
    ``sgtool doctor`` line to run. :meth:`frames`, :meth:`records` (typed, checked) and
    :meth:`messages` read in log-time order. Use as a context manager or call
    :meth:`close`."""

    def __init__(self, path: str | os.PathLike[str], *, check_version: bool = True,
                 verify: bool = False) -> None:
        self.path = Path(of_type("path", path, (str, os.PathLike), "a log's path"))
        self.verify = verify
        if not os.fspath(path) or not self.path.exists():  # ("" would be the folder ".")
            raise LogFormatError(f"{os.fspath(path) or 'an empty path'}: no such file")
        if self.path.is_dir():
            raise LogFormatError(f"{self.path} is a folder; expected an MCAP file")
        require_regular_file(self.path)
        size, problem = magic_problem(self.path)
        if problem is not None:
            raise LogFormatError(problem)
        self.size = size
        # reads are clamped to the file: a damaged length cannot allocate gigabytes
        self._f = BoundedReader(io.FileIO(self.path, "rb"), size)
        try:
            # chunk CRCs are checked as chunks are read when asked (``verify``; `sgtool
            # doctor` checks them all): damaged bytes give a clear error either way
            self._reader = SeekingReader(self._f, validate_crcs=verify)
            self._reader.get_header()
            summary = self._reader.get_summary()
        except InvalidMagic as e:
            self._f.close()
            raise LogFormatError(
                f"{self.path}: not an MCAP file (it does not start with the MCAP magic bytes)"
            ) from e
        except (McapError, ValueError, EOFError, OSError) as e:
            self._f.close()
            raise LogFormatError(
                f"{self.path}: not a readable MCAP file ({type(e).__name__}: {e}); "
                f"`sgtool doctor {quoted(self.path)}` says what is wrong"
            ) from e
        except Exception as e:  # the mcap library raises struct.error etc. on garbage
            self._f.close()
            raise LogFormatError(
                f"{self.path}: not a readable MCAP file ({type(e).__name__}); "
                f"`sgtool doctor {quoted(self.path)}` says what is wrong"
            ) from e
        # the summary is optional in MCAP, and so is each of its parts: when it does not say
        # everything (no statistics, schemas it lacks, messages outside chunks ...), the
        # file is read once and indexed from its records (:mod:`sgtool.log.walk_index`)
        self._walked: list[walk_index.Entry] | None = None
        try:
            walk = walk_index.needs_walk(summary)
            if summary is not None:  # the footer read once for both checks
                footer = read_footer(self._f, size)
                check_summary(self._f, size, summary, footer)
                walk = walk or walk_index.loose_messages(self._f, size, summary, footer)
            if walk:
                walked = walk_index.walk_log(self.path, size)
                summary, self._walked = walked.summary, walked.messages
                self.metadata: dict[str, dict[str, str]] = walked.metadata
            else:
                self.metadata = {m.name: dict(m.metadata) for m in self._reader.iter_metadata()}
        except LogFormatError as e:
            self._f.close()
            if str(e).startswith(str(self.path)):
                raise
            raise LogFormatError(f"{self.path}: {e}; `sgtool doctor {quoted(self.path)}` says what "
                                 "is readable and --recover copies it") from None
        except Exception as e:  # noqa: BLE001 - the mcap library on damaged records
            self._f.close()
            raise LogFormatError(
                f"{self.path}: damaged metadata ({type(e).__name__}); `sgtool doctor "
                f"{self.path}` says what is readable") from None
        assert summary is not None
        self.summary: Summary = summary
        self._decoders: dict[int, Any] = {}
        self._channel_problems: dict[int, str | None] = {}  # "" not known yet
        self._frame_times: list[int] | None = None
        self._buffers = cs.ChunkBuffers()  # chunks decompressed for views, reused
        if check_version:
            self.check_version()

    # ----- identity -------------------------------------------------------------------
    @property
    def is_sgtool(self) -> bool:
        return S.METADATA_NAME in self.metadata

    @property
    def schema_version(self) -> tuple[int, int] | None:
        meta = self.metadata.get(S.METADATA_NAME)
        if not meta or "log_schema_version" not in meta:
            return None
        try:
            return S.parse_version(meta["log_schema_version"])
        except ValueError as e:
            raise LogFormatError(
                f"{self.path}: bad log_schema_version {meta['log_schema_version']!r}"
            ) from e

    @property
    def seed(self) -> int | None:
        """The seed the log was recorded (or run) with (its metadata's ``seed``: the
        recorder's or planner's, not the house's: :meth:`house_spec` ``.seed``); None when
        not recorded."""
        s = self.metadata.get(S.METADATA_NAME, {}).get("seed", "")
        try:
            return int(s) if s else None
        except ValueError:
            raise LogFormatError(f"{self.path}: metadata {S.METADATA_NAME} field seed is "
                                 f"{s[:40]!r}, not an integer") from None

    def check_version(self) -> None:
        v = self.schema_version
        if v is not None and v[0] > S.LOG_SCHEMA_VERSION[0]:
            raise SchemaVersionError(
                f"{self.path} was written with log schema version {S.format_version(v)}; "
                f"this sgtool reads version {S.LOG_SCHEMA_VERSION[0]}.x "
                f"(log schema {S.format_version(S.LOG_SCHEMA_VERSION)}): upgrade sgtool"
            )

    # ----- summary ----------------------------------------------------------------------
    def channels(self) -> list[ChannelInfo]:
        counts = self.summary.statistics.channel_message_counts if self.summary.statistics else {}
        out = []
        for cid, ch in sorted(self.summary.channels.items()):
            sch = self.summary.schemas.get(ch.schema_id)
            out.append(
                ChannelInfo(
                    cid, ch.topic, sch.name if sch else "", sch.encoding if sch else "",
                    ch.message_encoding, int(counts.get(cid, 0)),
                )
            )
        return out

    def topics(self) -> set[str]:
        return {ch.topic for ch in self.summary.channels.values()}

    def has(self, topic: str) -> bool:
        return topic in self.topics()

    def require(self, *topics: str, why: str = "") -> None:
        for t in topics:
            if not self.has(t):
                extra = f" ({why})" if why else ""
                raise MissingChannelError(f"{self.path} has no channel {t}{extra}")

    def time_range(self) -> tuple[int, int] | None:
        st = self.summary.statistics
        if st is None or st.message_count == 0:
            return None
        return int(st.message_start_time), int(st.message_end_time)

    def message_count(self, topic: str | None = None) -> int:
        return sum(c.message_count for c in self.channels() if topic is None or c.topic == topic)

    def frame_count(self) -> int:
        return self.message_count(S.DEPTH)

    # ----- attachments ----------------------------------------------------------------
    def iter_attachments(self) -> Iterator[Attachment]:
        """The attachments, each checked against its CRC."""
        for ai in self.summary.attachment_indexes:
            yield read_attachment(self._f, ai, where=str(self.path))

    def attachments(self) -> dict[str, bytes]:
        return {a.name: a.data for a in self.iter_attachments()}

    def attachment(self, name: str) -> bytes | None:
        for a in self.iter_attachments():
            if a.name == name:
                return a.data
        return None

    def house_json(self) -> str | None:
        data = self.attachment(S.HOUSE_ATTACHMENT)
        if data is None:
            return None
        try:
            return data.decode()
        except UnicodeDecodeError:
            raise LogFormatError(f"{self.path}: attachment {S.HOUSE_ATTACHMENT} is not "
                                 "UTF-8 text") from None

    def house_spec(self) -> HouseSpec | None:
        """The house attachment validated as a house file given on the command line is
        (:func:`sgtool.house.io.load_house_text`); None when the log has none. A
        :class:`~sgtool.errors.SpecError` naming the log and the attachment when it is not
        UTF-8, not JSON (or nested too deeply to read) or not a valid house spec."""
        from sgtool.house.io import load_house_text

        where = f"{self.path}: attachment {S.HOUSE_ATTACHMENT}"
        try:
            text = self.house_json()
        except LogFormatError as e:
            raise SpecError(str(e)) from None
        if text is None:
            return None
        try:
            return load_house_text(text)
        except SpecError as e:
            raise SpecError(f"{where}: {e}") from None

    # ----- messages ---------------------------------------------------------------------
    def _contract(self, schema: Schema | None, channel: Channel) -> None:
        """Refuse, in one line, a channel of an sgtool log whose topic sgtool reads with
        another schema or encoding than it has
        (:func:`~sgtool.log.message_check.channel_problem`): its messages would reach the
        frame assembly or the record checks as something else."""
        problem = self._channel_problems.get(channel.id, "")
        if problem == "":
            problem = (message_check.channel_problem(schema, channel)
                       if self.is_sgtool else None)
            self._channel_problems[channel.id] = problem
        if problem is not None:
            raise LogFormatError(f"{self.path}: {problem}")

    def _decode(self, schema: Schema | None, channel: Channel, message: Message) -> Any:
        self._contract(schema, channel)
        if channel.message_encoding == "json":
            try:
                return json.loads(bytes(message.data))  # bytes, or a view of its chunk
            except (ValueError, RecursionError) as e:
                raise LogFormatError(
                    f"{self.path}: {channel.topic} message at {message.log_time} ns is not "
                    f"JSON ({str(e)[:100]})") from None
        if channel.message_encoding == "protobuf" and schema is not None:
            try:
                return self._decode_protobuf(schema, channel, message)
            except Exception as e:  # noqa: BLE001 - protobuf's DecodeError and kin
                raise LogFormatError(
                    f"{self.path}: {channel.topic} message at {message.log_time} ns is not a "
                    f"valid {schema.name} ({type(e).__name__}: {str(e)[:80]})") from None
        return bytes(message.data)  # a copy when it is a view of its chunk

    def _decode_protobuf(self, schema: Schema, channel: Channel, message: Message) -> Any:
        if isinstance(message.data, memoryview) and schema.name == "foxglove.RawImage":
            view = parse_raw_image(message.data)  # pixels left in the chunk (frames only)
            if view is not None:
                return view
        cls = proto_class(schema.name)
        if cls is not None:
            msg = cls()
            msg.ParseFromString(message.data)
            return msg
        dec = self._decoders.get(channel.id)
        if dec is None:
            from mcap_protobuf.decoder import DecoderFactory

            dec = DecoderFactory().decoder_for("protobuf", schema)
            self._decoders[channel.id] = dec
        return dec(bytes(message.data)) if dec else bytes(message.data)

    def messages(
        self,
        topics: Iterable[str] | None = None,
        *,
        start_ns: int | None = None,
        end_ns: int | None = None,
        reverse: bool = False,
    ) -> Iterator[Decoded]:
        """Decoded messages in log-time order, ``start_ns <= t < end_ns``."""
        return self._messages(topics, start_ns=start_ns, end_ns=end_ns, reverse=reverse)

    def _messages(self, topics: Iterable[str] | None, *, start_ns: int | None = None,
                  end_ns: int | None = None, reverse: bool = False, views: bool = False
                  ) -> Iterator[Decoded]:
        """:meth:`messages`; with ``views`` the payloads are parsed from views into their
        chunk (no copy; :func:`~sgtool.log.chunk_stream.ordered_messages`)."""
        topics = list(topics) if topics is not None else None
        for schema, channel, message in self._checked(self._iter(
                topics, start_ns=start_ns, end_ns=end_ns, reverse=reverse, views=views)):
            yield Decoded(
                channel.topic, int(message.log_time), schema.name if schema else "",
                self._decode(schema, channel, message),
            )

    @overload
    def records(self, kind: type[R], *, start_ns: int | None = None, end_ns: int | None = None,
                reverse: bool = False) -> Iterator[tuple[int, R]]: ...

    @overload
    def records(self, kind: RecordName, *, start_ns: int | None = None,
                end_ns: int | None = None, reverse: bool = False
                ) -> Iterator[tuple[int, dict[str, Any]]]: ...

    def records(self, kind: type[LogRecord] | RecordName, *, start_ns: int | None = None,
                end_ns: int | None = None, reverse: bool = False
                ) -> Iterator[tuple[int, LogRecord | dict[str, Any]]]:
        """(log time, record) of one sgtool JSON channel, in time order, each checked
        against its schema (:mod:`sgtool.log.records`: a missing or mistyped field is a
        :class:`LogFormatError` naming the channel, the record and the field). ``kind`` a
        record type (``Episode``) gives typed records; a kind name (``"episode"``) gives
        the checked JSON dicts. ``start_ns``, ``end_ns``, ``reverse``: as in
        :meth:`messages`."""
        rtype = record_type(kind)
        if not self.has(rtype.channel().topic):
            return
        for i, d in enumerate(self.messages([rtype.channel().topic], start_ns=start_ns,
                                            end_ns=end_ns, reverse=reverse)):
            index = None if reverse else i
            rec = rtype.from_json(
                d.message, where=f"{self.path}: {rtype.describe(index, d.log_time_ns)}")
            yield d.log_time_ns, (d.message if isinstance(kind, str) else rec)

    @overload
    def last_record(self, kind: type[R], at_ns: int | None = None) -> R | None: ...

    @overload
    def last_record(self, kind: RecordName, at_ns: int | None = None) -> dict[str, Any] | None: ...

    def last_record(self, kind: type[LogRecord] | RecordName, at_ns: int | None = None
                    ) -> LogRecord | dict[str, Any] | None:
        """The last record of a channel (at or before ``at_ns``), checked as
        :meth:`records`; None when there is none."""
        end = None if at_ns is None else at_ns + 1
        for _, rec in self.records(kind, end_ns=end, reverse=True):
            return rec
        return None

    # ----- frames -----------------------------------------------------------------------
    def frames(
        self, *, start_ns: int | None = None, end_ns: int | None = None, tf_time: str = "log"
    ) -> Iterator[Frame]:
        """Frames in log-time order (see the module docstring); ``tf_time`` pairs ``/tf``
        with frames (:class:`~sgtool.log.frame_assembly.FrameAssembler`); a frame near
        ``end_ns`` is posed from the transforms before ``end_ns``."""
        self.require(S.DEPTH, why="frames need depth images")
        for _, ch in sorted(self.summary.channels.items()):
            if ch.topic in FRAME_TOPICS:
                problem = message_check.channel_problem(
                    self.summary.schemas.get(ch.schema_id), ch)
                if problem is not None:
                    raise LogFormatError(f"{self.path}: {problem}")
        tf, calib = (self._state_before(start_ns) if start_ns is not None
                     else (TransformBuffer(), None))
        index = self._frame_index_before(start_ns) if start_ns is not None else 0
        asm = FrameAssembler(index=index, transforms=tf, calibration=calib,
                             where=str(self.path), tf_time=tf_time)
        for d in self._messages(FRAME_TOPICS, start_ns=start_ns, end_ns=end_ns, views=True):
            yield from asm.push(d.topic, d.log_time_ns, d.message)
        yield from asm.finish()

    def raw_messages(self, topics: Iterable[str] | None = None
                     ) -> Iterator[tuple[Schema | None, Channel, Message]]:
        """Undecoded (schema, channel, message) records in log-time order (ties in file
        order); :meth:`decode` decodes one."""
        yield from self._checked(self._iter(list(topics) if topics is not None else None))

    def chunks(self, *, views: bool = False) -> Iterator[tuple[RawChunk | None, list[cs.Item]]]:
        """Each chunk in file order, as it is (:func:`~sgtool.log.chunk_copy.raw_chunk`: None
        when its indexes do not allow a copy; its CRC always checked: a copy keeps it) with
        its messages in log-time order (that of :meth:`raw_messages` when in sequence). A
        file indexed by a walk (its summary says too little; messages may lie outside
        chunks) is one group of every message, with no chunk to copy."""
        walked = self._walked
        if walked is not None:
            return iter([(None, list(walked))])

        def each() -> Iterator[tuple[RawChunk | None, list[cs.Item]]]:
            for ci in sorted(self.summary.chunk_indexes, key=lambda c: c.chunk_start_offset):
                record = cs.read_chunk(self._f, ci)
                data = cs.chunk_data(record, ci, True, self._buffers if views else None)
                items = cs.chunk_messages(data, ci, self.summary, views)
                yield raw_chunk(self._f, ci, record), items
        return self._checked(each())

    def _iter(self, topics: list[str] | None, *, start_ns: int | None = None,
              end_ns: int | None = None, reverse: bool = False, views: bool = False
              ) -> Iterator[tuple[Schema | None, Channel, Message]]:
        """Messages in log-time order (ties in file order), or its reverse: chunk by chunk
        (:mod:`sgtool.log.chunk_stream`) when the file is chunked, else through the
        ``mcap`` reader."""
        if self._walked is not None:
            return self._from_walk(topics, start_ns, end_ns, reverse)
        if self.summary.chunk_indexes and reverse:
            return cs.reversed_messages(self._f, self.summary, topics, start_ns=start_ns,
                                        end_ns=end_ns, verify=self.verify)
        if self.summary.chunk_indexes:
            return cs.ordered_messages(self._f, self.summary, topics, start_ns=start_ns,
                                    end_ns=end_ns, verify=self.verify, views=views,
                                    buffers=self._buffers)
        return self._reader.iter_messages(topics=topics, starting_at=start_ns,
                                          ending_before=end_ns, log_time_order=True,
                                          reverse=reverse)

    def _from_walk(self, topics: list[str] | None, start_ns: int | None, end_ns: int | None,
                   reverse: bool) -> Iterator[tuple[Schema | None, Channel, Message]]:
        """The messages of a file indexed by a walk, as :meth:`_iter` gives them."""
        assert self._walked is not None
        entries = reversed(self._walked) if reverse else iter(self._walked)
        for e in entries:
            t = int(e[2].log_time)
            if ((topics is None or e[1].topic in topics)
                    and (start_ns is None or t >= start_ns) and (end_ns is None or t < end_ns)):
                yield e

    def _checked(self, it: Iterator[Any]) -> Iterator[Any]:
        """``it``, with damaged chunks (bad CRC, bad compression, bad records) turned into a
        :class:`LogFormatError` that points to ``sgtool doctor``."""
        try:
            for item in it:
                self._f.check_open()  # an iterator made in the `with` block, read after it
                yield item
        except SgtoolError:
            raise
        except Exception as e:  # noqa: BLE001 - McapError, CRC, zstd, lz4, struct, MemoryError
            raise LogFormatError(
                f"{self.path}: damaged data ({type(e).__name__}: {str(e)[:120]}); "
                f"`sgtool doctor {quoted(self.path)}` says what is readable and --recover copies it"
            ) from e

    def decode(self, schema: Schema | None, channel: Channel, message: Message) -> Any:
        """A raw message decoded as :meth:`messages` decodes it."""
        return self._decode(schema, channel, message)

    def frame_times(self) -> list[int]:
        """Log times of all frames, sorted. Read from the MCAP message indexes: no chunk is
        decompressed and no image decoded."""
        self.require(S.DEPTH, why="frames need depth images")
        if self._frame_times is None:
            self._frame_times = self._index_times(S.DEPTH)
        return self._frame_times

    def _index_times(self, topic: str) -> list[int]:
        if self._walked is not None:
            return [int(m.log_time) for _, ch, m in self._walked if ch.topic == topic]
        cids = {cid for cid, ch in self.summary.channels.items() if ch.topic == topic}
        times: list[int] = []
        for ci in self.summary.chunk_indexes:
            for cid, offset in ci.message_index_offsets.items():
                if cid not in cids:
                    continue
                self._f.seek(offset + 1 + 8, io.SEEK_SET)  # opcode, record length
                try:
                    idx = MessageIndex.read(ReadDataStream(self._f))
                except Exception:  # noqa: BLE001 - garbage where the index points
                    idx = None
                found = [int(t) for t, _ in idx.records] if idx is not None else []
                if idx is None or idx.channel_id != cid or any(
                        not ci.message_start_time <= t <= ci.message_end_time for t in found):
                    raise LogFormatError(
                        f"{self.path}: the message index of {topic} at byte {offset} is "
                        f"damaged; `sgtool doctor {quoted(self.path)}` says what is readable")
                times.extend(found)
        times.sort()
        return times

    def frame_at(self, t_ns: int) -> Frame | None:
        """The frame at or before ``t_ns`` (None before the first frame), found through the
        MCAP chunk index without reading the log from the start (posed as replay poses it:
        a ``/tf`` up to :data:`~sgtool.log.frame_assembly.HOLD_NS` later counts)."""
        self.require(S.DEPTH, why="frames need depth images")
        times = self.frame_times()
        i = bisect.bisect_right(times, int(t_ns)) - 1
        t_frame = times[i] if i >= 0 else None
        if t_frame is None:
            return None
        for fr in self.frames(start_ns=t_frame, end_ns=t_frame + assembly.HOLD_NS + 1):
            return fr
        return None

    def _state_before(self, t_ns: int) -> tuple[TransformBuffer, CameraIntrinsics | None]:
        tf = TransformBuffer()
        calib = None
        for d in self.messages([S.CALIBRATION], end_ns=t_ns, reverse=True):
            calib = decoded(str(self.path), d.topic, d.log_time_ns, codec.decode_calibration,
                            d.message)
            break
        # the links written once (/tf_static), then the latest transform of each link
        # before t, newest first, until the camera chain is complete
        if self.has(S.TF_STATIC):
            for d in self.messages([S.TF_STATIC], end_ns=t_ns):
                tf.add(d.log_time_ns, d.message.parent_frame_id, d.message.child_frame_id,
                       decoded(str(self.path), d.topic, d.log_time_ns,
                               codec.decode_transform, d.message), static=True)
        seen: set[str] = set()
        for d in self.messages([S.TF], end_ns=t_ns, reverse=True):
            child = d.message.child_frame_id
            if child not in seen:
                seen.add(child)
                tf.add(d.log_time_ns, d.message.parent_frame_id, child,
                       decoded(str(self.path), d.topic, d.log_time_ns,
                               codec.decode_transform, d.message))
            if tf.lookup(t_ns, S.CAMERA_FRAME) is not None:
                break
        return tf, calib

    def _frame_index_before(self, t_ns: int) -> int:
        return bisect.bisect_left(self.frame_times(), t_ns)

    # ----- end --------------------------------------------------------------------------
    def close(self) -> None:
        self._f.close()

    def __enter__(self) -> LogReader:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
