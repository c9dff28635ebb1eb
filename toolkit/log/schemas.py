"""The log contract: topics, schema names, JSON schemas and the log schema version.

Sensor and map data use Foxglove's well-known protobuf schemas (so a log opens in
Foxglove/Lichtblick and Rerun without plug-ins); sgtool's own records use JSON channels
with named JSON schemas. Every sgtool log carries a metadata record named ``sgtool`` with
the sgtool version, the log schema version (``major.minor``) and the seed.

Versioning rule: a reader reads every log whose major version equals its own and whose
minor version is any (new minor versions only add optional fields or channels); a newer
major version is refused with a message naming both versions.

Each JSON record kind has a typed record in :mod:`sgtool.log.records`, checked against the
JSON schema registered here whenever it is written or read.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from sgtool.vocabulary import (
    EPISODE_KINDS,
    EPISODE_STATUSES,
    INSTANCE_KINDS,
    OPEN_STATES,
    OUTCOMES,
    RELATIONS,
    RecordName,
)

# 1.1: sgtool.Action 1.1 adds the optional ``graph_time_ns``
# 1.2: instance ids may be 16UC1 (what Foxglove's Image panel shows); fixed transforms
#      (base -> camera) once on ``/tf_static``; derived logs add the ``/map/graph``
#      SceneUpdate (objects, doors, frontiers, edges with metadata)
LOG_SCHEMA_VERSION: tuple[int, int] = (1, 2)
PROFILE = "sgtool"
METADATA_NAME = "sgtool"
IMPORT_METADATA_NAME = "sgtool.import"  # where an import came from (sgtool import ...)
HOUSE_ATTACHMENT = "house.json"

WORLD_FRAME = "world"
BASE_FRAME = "base"
CAMERA_FRAME = "camera"
# the robot's true pose (world -> base_truth on /tf), written beside a base whose logged
# pose drifts (a simulated recording with pose drift): what scoring aligns the map by
TRUE_BASE_FRAME = "base_truth"

# protobuf (Foxglove well-known) topics
RGB = "/camera/rgb"
DEPTH = "/camera/depth"
IDS = "/camera/instances"
CALIBRATION = "/camera/calibration"
TF = "/tf"
TF_STATIC = "/tf_static"  # transforms that do not change, written once (FrameTransform)
OCCUPANCY = "/map/occupancy"
VORONOI = "/map/voronoi"
ROOMS = "/map/rooms"
GRAPH_SCENE = "/map/graph"  # the scene graph's objects, doors, frontiers and edges

# encodings of the RawImage channels
RGB_ENCODING = "rgb8"
DEPTH_ENCODING = "16UC1"  # millimetres, little endian, 0 = no return
IDS_ENCODING = "32SC1"  # instance ids, little endian int32, 0 = none
IDS_ENCODING_16 = "16UC1"  # instance ids that fit 0..IDS_MAX_16 (Foxglove shows it)
IDS_MAX_16 = 65535
DEPTH_SCALE = 1000.0  # depth units per metre
DEPTH_MAX_M = 65535 / DEPTH_SCALE  # m; the farthest depth uint16 millimetres hold


@dataclass(frozen=True)
class RecordKind:
    """A JSON record type: its schema name, version, topic and JSON schema."""

    key: RecordName
    schema_name: str
    version: str
    topic: str
    schema: dict[str, Any]

    def schema_bytes(self) -> bytes:
        import json

        doc = {
            "$schema": "https://json-schema.org/draft/2020-12/schema",
            "$id": f"sgtool/{self.schema_name}/{self.version}",
            "title": self.schema_name,
            "version": self.version,
            **_viewable(self.schema),
        }
        return json.dumps(doc, sort_keys=True, separators=(",", ":")).encode()


def _viewable(node: Any) -> Any:
    """``node`` in the JSON Schema subset Foxglove and Lichtblick parse (one ``type``
    string per property, ``properties`` on every object, ``items`` on every array): a
    nullable type is its non-null type, an ``enum`` gets the type of its values, an open
    object gets no properties, an untyped array holds open objects. Records are checked
    against :attr:`RecordKind.schema`, not against this."""
    if not isinstance(node, dict):
        return node
    out = {k: _viewable(v) if k in ("items",) else v for k, v in node.items()}
    if "properties" in node:
        out["properties"] = {k: _viewable(v) for k, v in node["properties"].items()}
    t = node.get("type")
    if isinstance(t, list):
        t = next((x for x in t if x != "null"), "null")
    if t is None and "enum" in node:
        kinds = {type(v) for v in node["enum"] if v is not None}
        t = "string" if kinds <= {str} else "boolean" if kinds <= {bool} else "number"
    if t is not None:
        out["type"] = t
    if t == "object":
        out.setdefault("properties", {})
    if t == "array":
        out.setdefault("items", {"type": "object", "properties": {}})
        if out["items"].get("type") not in ("boolean", "string", "number", "integer",
                                            "object"):  # Foxglove throws on arrays of arrays
            out["items"] = {"type": "object", "properties": {}}
    return out


def _obj(props: dict[str, Any], required: list[str]) -> dict[str, Any]:
    return {"type": "object", "properties": props, "required": required}


_STR = {"type": "string"}
_NUM = {"type": "number"}
_INT = {"type": "integer"}
_BOOL = {"type": "boolean"}
_NSTR = {"type": ["string", "null"]}

RECORDS: dict[RecordName, RecordKind] = {
    "episode": RecordKind(
        "episode",
        "sgtool.Episode",
        "1.0",
        "/sgtool/episode",
        _obj(
            {
                "kind": {"enum": [*EPISODE_KINDS]},
                "source": _STR,
                "house_id": _NSTR,
                "query": _NSTR,
                "planner": _NSTR,
                "status": {"enum": [*EPISODE_STATUSES]},
                "steps": _INT,
                "travelled_m": _NUM,
                "shortest_m": {"type": ["number", "null"]},
                "frames": _INT,
                "extra": {"type": "object"},
            },
            ["kind", "status"],
        ),
    ),
    "instances": RecordKind(
        "instances",
        "sgtool.Instances",
        "1.0",
        "/sgtool/instances",
        _obj(
            {
                "instances": {
                    "type": "array",
                    "items": _obj(
                        {
                            "id": _INT,
                            "category": _STR,
                            "synset": _NSTR,
                            "kind": {"enum": [*INSTANCE_KINDS]},
                            "state": {"enum": [*OPEN_STATES, None]},
                            "affordances": {"type": "array", "items": _STR},
                            "parent": {"type": ["integer", "null"]},
                            "relation": {"enum": [*RELATIONS, None]},
                            "spec_id": _NSTR,
                        },
                        ["id", "category", "kind"],
                    ),
                }
            },
            ["instances"],
        ),
    ),
    # 1.1: optional graph_time_ns, the log time of the sgtool.SceneGraph the action was
    # decided on (null: decided on no graph, e.g. the closed loop's opening look-around;
    # absent: the last graph at or before the action's log time)
    # 1.2: optional view_distances, node id -> metres: the distances of that graph as the
    # planner was shown it (absent: the logged graph's)
    "action": RecordKind(
        "action",
        "sgtool.Action",
        "1.2",
        "/sgtool/action",
        _obj(
            {
                "skill": _STR,
                "target": _NSTR,
                "outcome": {"enum": [*OUTCOMES]},
                "reason": _STR,
                "travelled_m": _NUM,
                "decision_time_s": _NUM,
                "planner": _NSTR,
                "step": _INT,
                "graph_time_ns": {"type": ["integer", "null"]},
                "view_distances": {"type": "object", "additionalProperties": _NUM},
            },
            ["skill", "outcome"],
        ),
    ),
    "scene_graph": RecordKind(
        "scene_graph",
        "sgtool.SceneGraph",
        "1.0",
        "/sgtool/scene_graph",
        _obj({"version": _STR, "rooms": {"type": "array"}, "objects": {"type": "array"}},
             ["version"]),
    ),
    "llm_exchange": RecordKind(
        "llm_exchange",
        "sgtool.LlmExchange",
        "1.0",
        "/sgtool/llm",
        _obj(
            {
                "model": _STR,
                "messages": {"type": "array"},
                "response": _NSTR,
                "latency_s": _NUM,
                "prompt_tokens": {"type": ["integer", "null"]},
                "completion_tokens": {"type": ["integer", "null"]},
                "error": _NSTR,
                "attempt": _INT,
            },
            ["model", "messages"],
        ),
    ),
}

RECORD_BY_SCHEMA = {k.schema_name: k for k in RECORDS.values()}


def format_version(v: tuple[int, int]) -> str:
    return f"{v[0]}.{v[1]}"


def parse_version(text: str) -> tuple[int, int]:
    major, _, minor = text.partition(".")
    return int(major), int(minor or 0)
