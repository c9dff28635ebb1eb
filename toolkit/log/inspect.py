"""What is in a log: the facts ``sgtool info`` prints, as plain data.

Works on any indexed MCAP file: on a foreign one (a ROS 2 recording) it lists topics,
schemas and counts; on an sgtool log it adds the log schema version, frame count,
camera, instances and the episode summary.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from sgtool.log import codec
from sgtool.log import schemas as S
from sgtool.log.assembly import decoded
from sgtool.log.reader import LogReader


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
        out["house_seed"] = int(hs) if hs.lstrip("-").isdigit() else None
        if not out["readable"]:
            return out
        out["frames"] = r.frame_count()
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


def format_summary(s: dict[str, Any]) -> str:
    lines = [f"{s['path']}  ({s['size_bytes'] / 1e6:.2f} MB, {s['chunks']} chunks)"]
    if s["sgtool_log"]:
        lines.append(
            f"sgtool log, schema version {s.get('log_schema_version')}, "
            f"written by sgtool {s['metadata'].get('sgtool', {}).get('sgtool_version', '?')}, "
            f"seed {s.get('seed')}"
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
        ep = s.get("episode")
        if ep:
            keys = ["kind", "status", "source", "house_id", "query", "planner", "steps",
                    "travelled_m", "frames"]
            parts = [f"{k}={ep[k]}" for k in keys if ep.get(k) is not None]
            lines.append("episode: " + ", ".join(parts))
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
