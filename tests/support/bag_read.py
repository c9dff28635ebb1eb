"""Reading a ROS bag back in tests: every message by topic, deserialised."""

from __future__ import annotations

from pathlib import Path


def read_bag(path: Path, types: dict[str, str] | None = None
             ) -> dict[str, list[tuple[int, object]]]:
    """Every message of the bag by topic, deserialised; ``types`` gets topic -> type."""
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    out: dict[str, list[tuple[int, object]]] = {}
    with AnyReader([path], default_typestore=get_typestore(Stores.LATEST)) as r:
        for c, t, raw in r.messages():
            out.setdefault(c.topic, []).append((t, r.deserialize(raw, c.msgtype)))
            if types is not None:
                types[c.topic] = c.msgtype
    return out


def stamp_ns(msg: object) -> int:
    st = msg.header.stamp  # type: ignore[attr-defined]
    return int(st.sec) * 1_000_000_000 + int(st.nanosec)
