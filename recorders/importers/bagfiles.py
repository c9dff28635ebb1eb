"""Opening ROS bags with ``rosbags`` and describing what is in them.

:func:`open_bag` accepts what people pass around:
- a ROS 1 ``.bag`` file;
- a ROS 2 bag folder (``metadata.yaml`` plus ``.db3`` or ``.mcap`` storage files), or a
  storage file inside such a folder;
- a bare ROS 2 ``.mcap`` or ``.db3`` file without ``metadata.yaml`` (a copy of the storage
  file alone, or a recording made by ``mcap``/Foxglove tools): ``rosbags`` reads these
  from the file's own schemas and tables; one without a chunk index, or whose summary
  leaves out channels, schemas or message indexes (all valid MCAP, misread by
  ``rosbags``), through a temporary indexed copy (:func:`sgtool.log.recover.recover`'s);
- a storage file compressed whole (``*.mcap.zstd``) inside its bag folder.

Failures become :class:`SgtoolError` messages that name the file and what it is instead
(an sgtool log or another non-ROS MCAP file is named as such).
"""

from __future__ import annotations

import contextlib
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sgtool.errors import SgtoolError
from sgtool.files import quoted

ROS1_MAGIC = b"#ROSBAG V2.0\n"  # the first bytes of a ROS 1 bag
IMAGE_TYPES = ("sensor_msgs/msg/Image", "sensor_msgs/msg/CompressedImage")
INFO_TYPES = ("sensor_msgs/msg/CameraInfo",)
TF_TYPES = ("tf2_msgs/msg/TFMessage", "tf/msg/tfMessage")
POSE_TYPES = (
    "geometry_msgs/msg/PoseStamped",
    "geometry_msgs/msg/PoseWithCovarianceStamped",
    "geometry_msgs/msg/TransformStamped",
    "nav_msgs/msg/Odometry",
)


@dataclass(frozen=True)
class TopicInfo:
    topic: str
    msgtype: str
    count: int


def normalise_type(t: str) -> str:
    """ROS 1 names types ``pkg/Type``; rosbags reports ``pkg/msg/Type``: accept both."""
    parts = t.split("/")
    return f"{parts[0]}/msg/{parts[1]}" if len(parts) == 2 else t


def bag_kind(path: Path) -> str:
    """``ros1`` (a .bag file, or a file starting as one) or ``ros2`` (folder, or bare
    storage file)."""
    if path.is_dir():
        return "ros2"
    if path.suffix == ".bag" or _starts_with(path, ROS1_MAGIC):
        return "ros1"
    return "ros2"


def _check_mcap_profile(path: Path) -> bool:
    """A non-ROS MCAP file (an sgtool log, a protobuf recording) gets a message that says
    what it is, rather than the bag reader's "Profile is not ros2". Returns whether the
    bag reader needs an indexed copy of the file to read all of its messages: a valid MCAP
    file without a chunk index (read in file order, refused when not in log-time order)
    or whose summary leaves out what the reader relies on (:func:`_summary_gap`)."""
    from mcap.reader import make_reader

    from sgtool.log.mcap_records import MAGIC

    with open(path, "rb") as f:
        head = f.read(len(MAGIC))
        size = f.seek(0, 2)
        f.seek(max(size - len(MAGIC), 0))
        tail = f.read(len(MAGIC))
    if head != MAGIC:
        raise SgtoolError(f"{path}: not an MCAP file (it does not start with the MCAP magic "
                          "bytes)")
    if size < 2 * len(MAGIC) or tail != MAGIC:  # cut short, or bytes appended after it
        from sgtool.log.log_file import unended_problem

        raise SgtoolError(unended_problem(path, size))
    try:
        with open(path, "rb") as f:
            reader = make_reader(f)
            header = reader.get_header()
            summary = reader.get_summary()
    except Exception as e:  # the mcap library raises assorted errors on garbage
        raise SgtoolError(f"{path}: not a readable MCAP file ({type(e).__name__}: {e})") from e
    encodings = sorted({ch.message_encoding for ch in summary.channels.values()}) if summary \
        else []
    if header.profile != "ros2" or (encodings and encodings != ["cdr"]):
        # (no summary: the channels, and so the encodings, are not known without a scan)
        what = ", ".join(encodings) if encodings else "no" if summary else "unlisted"
        raise SgtoolError(
            f"{path} is an MCAP file with profile {header.profile!r} and "
            f"{what} messages, not a ROS 2 bag (profile 'ros2', cdr)"
            + ("; it already is an sgtool log" if header.profile == "sgtool" else "")
        )
    return summary is None or not summary.chunk_indexes or _summary_gap(summary) is not None


def _summary_gap(summary: Any) -> str | None:
    """What a ROS 2 MCAP file's summary leaves out that ``rosbags`` relies on (the MCAP
    specification makes each part optional), or None. ``rosbags`` scans the file for the
    channels and schemas only when the summary lists neither: channels listed without
    their schemas read as schemaless, schemas listed without the channels as no topic; and
    a chunk index without message indexes hides that chunk's messages."""
    stats, chunks = summary.statistics, summary.chunk_indexes
    unlisted = (stats.channel_count > len(summary.channels) if stats is not None
                else not summary.channels and bool(chunks))
    if unlisted and (summary.schemas or (stats is None and chunks)):
        return "does not list the channels"
    if any(ch.schema_id and ch.schema_id not in summary.schemas
           for ch in summary.channels.values()):
        return "lists the channels but not their schemas"
    if any(not ci.message_index_offsets and (ci.message_start_time or ci.message_end_time)
           for ci in chunks):
        return "indexes the chunks but not the messages in them"
    return None


def _renamed_bag(path: Path, stack: contextlib.ExitStack) -> Path:
    """What the bag reader opens for a file not named as a bag: the bag folder of a storage
    file compressed whole (rosbag2's compression mode 'file', said in the folder's
    metadata.yaml), or a ROS 1 bag under a name the reader goes by (removed on leaving
    ``stack``); anything else is one line."""
    if _starts_with(path, _ZSTD_MAGIC):
        if (path.parent / "metadata.yaml").is_file():
            return path.parent
        raise SgtoolError(
            f"{path}: a zstd-compressed file (rosbag2's compression mode 'file'): import its "
            f"bag folder, with its metadata.yaml, or decompress it first (`zstd -d "
            f"{quoted(path)}`)")
    if not _starts_with(path, ROS1_MAGIC):
        raise SgtoolError(
            f"{path}: not a ROS bag (expected a ROS 1 .bag file, a ROS 2 bag folder, "
            "or a ROS 2 .mcap/.db3 file)")
    target = Path(stack.enter_context(tempfile.TemporaryDirectory())) / "bag.bag"
    target.symlink_to(path.resolve())
    return target


def _indexed_copy(path: Path, stack: contextlib.ExitStack, into: Path | None = None) -> Path:
    """``path``'s messages in a temporary, fully indexed MCAP file (``sgtool doctor
    --recover``'s copy: the same schemas, channels and messages), removed on leaving
    ``stack`` (or in the folder ``into``). A damaged file is refused in one line, as the
    bag reader refuses one it reads directly: the copy would leave out what is lost without
    a word."""
    from sgtool.log.recover import recover

    folder = into or Path(stack.enter_context(tempfile.TemporaryDirectory()))
    copy = folder / path.name
    diag = recover(path, copy)
    if diag.status in ("corrupt", "truncated"):
        first = (diag.problems or [diag.status])[0][:200]
        raise SgtoolError(f"{path}: damaged or truncated bag ({first}); `sgtool doctor "
                          f"{quoted(path)}` says what is lost, `--recover OUT.mcap` copies "
                          "what is readable")
    return copy


def _indexed_folder(folder: Path, stack: contextlib.ExitStack) -> Path:
    """A ROS 2 bag folder whose MCAP storage files rosbags would misread (rosbag2's storage
    options write them without chunks or message indexes): a temporary folder of the same
    files, those through an indexed copy (:func:`_indexed_copy`), the others linked;
    ``folder`` itself when none needs it."""
    def needs_index(f: Path) -> bool:
        try:
            return _check_mcap_profile(f)
        except SgtoolError:  # (not a ROS 2 MCAP file: the bag reader says what it is)
            return False

    needs = [f for f in sorted(folder.glob("*.mcap")) if needs_index(f)]
    if not needs:
        return folder
    tmp = Path(stack.enter_context(tempfile.TemporaryDirectory())) / folder.name
    tmp.mkdir()
    for f in sorted(folder.iterdir()):
        if f in needs:
            _indexed_copy(f, stack, into=tmp)
        else:
            (tmp / f.name).symlink_to(f.resolve())
    return tmp


def _starts_with(path: Path, magic: bytes) -> bool:
    try:
        with open(path, "rb") as fh:
            return fh.read(len(magic)) == magic
    except OSError:
        return False


@contextlib.contextmanager
def open_bag(path: str | Path) -> Iterator[Any]:
    """An open ``rosbags`` AnyReader over the bag at ``path`` (see the module docstring)."""
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    path = Path(path)
    if not path.exists():
        raise SgtoolError(f"{path}: no such file or folder")
    with contextlib.ExitStack() as stack:
        target = path
        if path.is_file() and path.suffix in (".mcap", ".db3"):
            if (path.parent / "metadata.yaml").is_file():
                target = path.parent
            elif path.suffix == ".mcap" and _check_mcap_profile(path):
                target = _indexed_copy(path, stack)
        elif path.is_dir() and not (path / "metadata.yaml").is_file():
            raise SgtoolError(f"{path}: a folder without metadata.yaml is not a ROS 2 bag")

        elif path.is_file() and path.suffix != ".bag":
            target = _renamed_bag(path, stack)
        if target.is_dir() and (target / "metadata.yaml").is_file():
            target = _indexed_folder(target, stack)
        if target.is_dir() and target.suffix == ".bag":
            # a ROS 2 bag folder named *.bag (`ros2 bag record -o run.bag`), given or found
            # above its storage file: the reader takes the name for a ROS 1 file
            link = Path(stack.enter_context(tempfile.TemporaryDirectory())) / "bag"
            link.symlink_to(target.resolve(), target_is_directory=True)
            target = link
        try:
            reader = AnyReader([target], default_typestore=get_typestore(Stores.LATEST))
            stack.enter_context(reader)
        except Exception as e:  # the bag readers raise assorted errors on garbage
            first = (str(e).strip().splitlines() or [""])[0][:200]  # one line (YAML's are many)
            mcaps = [path] if path.suffix == ".mcap" else sorted(path.glob("*.mcap")) \
                if path.is_dir() else []
            hint = (f"; if it was cut short, `sgtool doctor {quoted(mcaps[0])} --recover "
                    "OUT.mcap` copies what is readable" if mcaps else "")
            raise SgtoolError(f"{path}: not a readable ROS bag ({type(e).__name__}: {first})"
                              f"{hint}") from e
        try:
            yield reader
        except Exception as e:
            if not damaged_bag(e):
                raise
            raise SgtoolError(f"{path}: damaged or truncated bag, a message cannot be read "
                              f"({type(e).__name__}: {e})") from e


_DAMAGE_MODULES = ("rosbags.", "backports.zstd", "zstandard", "compression.zstd", "lz4",
                   "mcap.")


def damaged_bag(exc: BaseException) -> bool:
    """Whether ``exc``, raised while reading a bag's messages, says the file is damaged
    (a bag reader's, a decompressor's or a record decoder's error), not a bug of ours."""
    import struct
    import zlib

    if isinstance(exc, (EOFError, struct.error, zlib.error)):
        return True
    return any(type(exc).__module__.startswith(m) or type(exc).__module__ == m.rstrip(".")
               for m in _DAMAGE_MODULES)


_ZSTD_MAGIC = b"\x28\xb5\x2f\xfd"


def deserialize(reader: Any, raw: bytes, connection: Any) -> Any:
    """A message of ``connection`` decoded by ``reader``. A ROS 2 MCAP file may name its
    schemas ``pkg/Type`` (as ROS 1 does; MCAP tools accept both), while the reader registers
    them as ``pkg/msg/Type``: the type is looked up under either name. A message compressed
    on its own (rosbag2's ``--compression-mode message``, said only in the bag folder's
    ``metadata.yaml``) is a user error naming the folder as what to import."""
    msgtype = connection.msgtype
    if msgtype not in reader.typestore.fielddefs:
        msgtype = normalise_type(msgtype)
    try:
        return reader.deserialize(raw, msgtype)
    except Exception as e:
        if bytes(raw[:4]) == _ZSTD_MAGIC and damaged_bag(e):
            raise SgtoolError(
                f"topic {connection.topic}: the messages are zstd-compressed one by one "
                "(rosbag2's compression mode 'message'), which only the bag folder's "
                "metadata.yaml says: import the bag folder, with its metadata.yaml") from None
        raise


def list_topics(reader: Any) -> list[TopicInfo]:
    out: dict[str, TopicInfo] = {}
    for c in reader.connections:
        prev = out.get(c.topic)
        n = int(c.msgcount) + (prev.count if prev else 0)
        out[c.topic] = TopicInfo(c.topic, normalise_type(c.msgtype), n)
    return [out[t] for t in sorted(out)]


def format_topics(topics: list[TopicInfo]) -> str:
    if not topics:
        return "  (no topics)"
    w = max(len(t.topic) for t in topics)
    wt = max(len(t.msgtype) for t in topics)
    return "\n".join(f"  {t.topic:<{w}}  {t.msgtype:<{wt}}  {t.count:>7}" for t in topics)


def connections_for(reader: Any, topic: str) -> list[Any]:
    return [c for c in reader.connections if c.topic == topic]
