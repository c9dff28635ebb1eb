"""What is in a log: the facts ``sgtool info`` prints, as plain data.

Works on any indexed MCAP file: on a foreign one (a ROS 2 recording) it lists topics,
schemas and counts; on an sgtool log it adds the log schema version, frame count,
camera, instances and the episode summary.

:func:`foreign_log_problem` says what a file that is not an sgtool log is (a ROS 1 bag, a
ROS 2 bag's sqlite3 or MCAP storage, another MCAP recording) and which ``sgtool import``
command turns it into one, for commands that need an sgtool log (``sgtool replay``).
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any

from sgtool.log import codec
from sgtool.log import schemas as S
from sgtool.log.frame_assembly import decoded
from sgtool.log.reader import LogReader

_SEED = re.compile(r"-?\d{1,30}")


def house_seed_of(text: str) -> int | None:
    """The house seed written as ``text`` in a log's metadata: an integer of at most 30
    decimal digits (any script), optionally negative; None for any other text."""
    return int(text) if _SEED.fullmatch(text) else None


def _fmt_time(t_ns: int) -> str:
    return f"{t_ns / 1e9:.3f} s"


def summarize(path: str | os.PathLike[str]) -> dict[str, Any]:
    """Facts about a log as a JSON-serialisable dict (stable key order)."""
    p = Path(path)
    with LogReader(p, check_version=False) as r:
        tr = r.time_range()
        out: dict[str, Any] = {
            "path": str(p),
            "size_bytes": p.stat().st_size,
            "profile": r._reader.get_header().profile,
            "library": r._reader.get_header().library,
            "sgtool_log": r.is_sgtool,
            "channels": [
                {
                    "topic": c.topic,
                    "schema": c.schema_name,
                    "schema_encoding": c.schema_encoding,
                    "message_encoding": c.message_encoding,
                    "messages": c.message_count,
                }
                for c in sorted(r.channels(), key=lambda c: c.topic)
            ],
            "messages": r.message_count(),
            "chunks": len(r.summary.chunk_indexes),
            "start_ns": tr[0] if tr else None,
            "end_ns": tr[1] if tr else None,
            "duration_s": round((tr[1] - tr[0]) / 1e9, 6) if tr else 0.0,
            "attachments": [
                {"name": a.name, "media_type": a.media_type, "size_bytes": int(a.data_size)}
                for a in sorted(r.summary.attachment_indexes, key=lambda a: a.name)
            ],
            "metadata": {k: dict(sorted(v.items())) for k, v in sorted(r.metadata.items())},
        }
        if not r.is_sgtool:
            return out
        v = r.schema_version
        out["log_schema_version"] = S.format_version(v) if v else None
        out["readable"] = v is None or v[0] <= S.LOG_SCHEMA_VERSION[0]
        out["seed"] = r.seed
        hs = r.metadata.get(S.METADATA_NAME, {}).get("house_seed", "")
        out["house_seed"] = house_seed_of(str(hs))
        if not out["readable"]:
            return out
        out["frames"] = r.frame_count()
        if out["frames"]:
            times = r.frame_times()
            if len(set(times)) < len(times):  # (only said when there are: replay refuses)
                out["repeated_frame_times"] = len(times) - len(set(times))
        if out["frames"] and r.has(S.CALIBRATION):
            for d in r.messages([S.CALIBRATION]):
                k = decoded(str(p), d.topic, d.log_time_ns, codec.decode_calibration,
                            d.message)
                out["camera"] = {"width": k.width, "height": k.height,
                                 "fx": round(k.fx, 3), "fy": round(k.fy, 3)}
                break
        out["has_rgb"] = r.has(S.RGB)
        out["has_instance_ids"] = r.has(S.IDS)
        inst = r.last_record("instances")
        out["instances"] = len(inst["instances"]) if inst else 0
        out["actions"] = r.message_count(S.RECORDS["action"].topic)
        out["scene_graphs"] = r.message_count(S.RECORDS["scene_graph"].topic)
        out["episode"] = r.last_record("episode")
        return out


ROS_IMAGE_SCHEMAS = ("sensor_msgs/msg/Image", "sensor_msgs/msg/CompressedImage",
                     "sensor_msgs/Image", "sensor_msgs/CompressedImage")
ROS_POSE_WORDS = ("tf2_msgs", "geometry_msgs", "nav_msgs/msg/Odometry", "nav_msgs/Odometry")


def _import_hint(path: Path, channels: list[tuple[str, str]]) -> str:
    """Which ``sgtool import bag`` command fits a ROS recording with these (topic, schema)
    channels."""
    images = [t for t, sch in channels if sch in ROS_IMAGE_SCHEMAS]
    poses = [t for t, sch in channels if any(w in sch for w in ROS_POSE_WORDS)]
    listing = f"`sgtool import bag {path} --list` shows its topics and suggests the flags"
    if images:
        depth = next((t for t in images if "depth" in t.lower()), "TOPIC")
        return (f"turn it into one with `sgtool import bag {path} -o OUT.mcap --depth {depth}` "
                f"({listing})")
    if poses:
        return (f"it has no image topic, only poses: `sgtool import bag {path} -o OUT.mcap "
                f"--tf-frames WORLD:FRAME` (or --pose TOPIC) imports the trajectory ({listing})")
    return f"it has no image or pose topic sgtool can import ({listing})"


def bag_problem(path: str | os.PathLike[str]) -> str | None:
    """:func:`foreign_log_problem` for a file that is no MCAP file (a ROS 1 bag, a ROS 2
    bag's SQLite storage), with the import command; None for anything else."""
    p = Path(path)
    if not p.is_file():  # (a pipe would block the open; the reader refuses it)
        return None
    try:
        with open(p, "rb") as f:
            if f.read(5) == b"\x89MCAP":
                return None
    except OSError:
        return None
    return foreign_log_problem(p)


def foreign_log_problem(path: str | os.PathLike[str]) -> str | None:
    """One line saying what ``path`` is when it is a recording but not an sgtool log, and the
    import command that turns it into one; None for an sgtool log, or for anything else (the
    log reader's own error says what is wrong)."""
    p = Path(path)
    if not p.is_file():
        return None
    with open(p, "rb") as f:
        head = f.read(16)
    if head.startswith(b"#ROSBAG V2.0"):
        return (f"{p} is a ROS 1 bag, not an sgtool log; turn it into one with `sgtool import "
                f"bag {p} -o OUT.mcap` (`sgtool import bag {p} --list` shows its topics and "
                "suggests the flags)")
    if head.startswith(b"SQLite format 3\0"):
        return (f"{p} is an SQLite file (a ROS 2 bag's storage?), not an sgtool log; turn a "
                f"ROS 2 bag into one with `sgtool import bag {p.parent} -o OUT.mcap` "
                f"(`--list` shows its topics and suggests the flags)")
    if not head.startswith(b"\x89MCAP"):
        return None
    try:
        with LogReader(p, check_version=False) as r:
            if r.is_sgtool:
                return None
            profile = r._reader.get_header().profile
            channels = [(c.topic, c.schema_name) for c in r.channels()]
            encodings = sorted({c.message_encoding for c in r.channels()})
    except Exception:  # noqa: BLE001 - damaged files: the reader's own error says it
        return None
    what = {"ros2": "a ROS 2 recording (MCAP, profile 'ros2')",
            "ros1": "a ROS 1 recording (MCAP, profile 'ros1')"}.get(
        profile, f"an MCAP file with profile {profile or ''!r}")
    enc = (f"{len({t for t, _ in channels})} topic(s) of messages encoded "
           f"{', '.join(map(repr, encodings))}"
           if encodings else "no message topics")
    if profile in ("ros1", "ros2") or encodings in (["cdr"], ["ros1"]):
        return f"{p} is {what} with {enc}, not an sgtool log; {_import_hint(p, channels)}"
    if profile == S.PROFILE:
        return (f"{p} has the MCAP profile 'sgtool' but no '{S.METADATA_NAME}' metadata "
                "record (version, schema version, seed): not an sgtool log as written, or "
                "one a tool rewrote without its metadata; copy the original's metadata "
                "record into it, or record or import it again")
    return (f"{p} is {what} with {enc}, not an sgtool log (profile 'sgtool'); sgtool imports "
            "ROS 1/2 bags (`sgtool import bag`) and RGB-D folders (`sgtool import rgbd`)")


def format_summary(s: dict[str, Any]) -> str:
    lines = [f"{s['path']}  ({s['size_bytes'] / 1e6:.2f} MB, {s['chunks']} chunks)"]
    if s["sgtool_log"]:
        lines.append(
            f"sgtool log, schema version {s.get('log_schema_version')}, "
            f"written by sgtool {s['metadata'].get('sgtool', {}).get('sgtool_version', '?')}"
            + (f", seed {s['seed']}" if s.get("seed") is not None else "")
            + (f", house seed {s['house_seed']}" if s.get("house_seed") is not None else "")
        )
        if not s.get("readable", True):
            lines.append(
                f"  this sgtool reads log schema {S.LOG_SCHEMA_VERSION[0]}.x only: upgrade sgtool"
            )
    else:
        lines.append(
            f"foreign MCAP file (profile {s['profile'] or '-'!r}, library {s['library'] or '-'!r})"
        )
    if s["start_ns"] is not None:
        lines.append(
            f"time {_fmt_time(s['start_ns'])} .. {_fmt_time(s['end_ns'])} "
            f"({s['duration_s']:.3f} s), {s['messages']} messages"
        )
    else:
        lines.append("no messages")
    if s["sgtool_log"] and s.get("readable", True):
        cam = s.get("camera")
        cam_txt = f", camera {cam['width']}x{cam['height']}" if cam else ""
        fps = ""
        if s["frames"] > 1 and s["duration_s"] > 0:
            fps = f" (~{(s['frames'] - 1) / s['duration_s']:.1f} fps)"
        lines.append(
            f"frames {s['frames']}{fps}{cam_txt}; rgb {'yes' if s['has_rgb'] else 'no'}, "
            f"instance ids {'yes' if s['has_instance_ids'] else 'no'}; "
            f"instances {s['instances']}, actions {s['actions']}, scene graphs {s['scene_graphs']}"
        )
        if s.get("repeated_frame_times"):
            lines.append(f"warning: {s['repeated_frame_times']} depth image(s) share a log time "
                         "with another: replay refuses such a log (one frame per time)")
        ep = s.get("episode")
        if ep:
            keys = ["kind", "status", "source", "house_id", "query", "planner", "steps",
                    "travelled_m", "frames"]
            parts = [f"{k}={ep[k]}" for k in keys if ep.get(k) is not None]
            lines.append("episode: " + ", ".join(parts))
        imported = s.get("metadata", {}).get(S.IMPORT_METADATA_NAME, {})
        lines += [f"import warning: {w}" for w in str(imported.get("warnings") or "")
                  .splitlines() if w.strip()]  # what `sgtool import` warned of, kept
    lines.append("")
    w_topic = max([len(c["topic"]) for c in s["channels"]] + [5])
    w_schema = max([len(c["schema"]) for c in s["channels"]] + [6])
    lines.append(f"{'topic':<{w_topic}}  {'schema':<{w_schema}}  {'encoding':<10}  messages")
    for c in s["channels"]:
        lines.append(
            f"{c['topic']:<{w_topic}}  {c['schema'] or '-':<{w_schema}}  "
            f"{c['message_encoding']:<10}  {c['messages']:>8}"
        )
    if s["attachments"]:
        lines.append("")
        lines.append("attachments: " + ", ".join(
            f"{a['name']} ({a['media_type']}, {a['size_bytes']} B)" for a in s["attachments"]
        ))
    return "\n".join(lines)
