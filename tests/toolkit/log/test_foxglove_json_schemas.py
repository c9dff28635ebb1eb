"""The JSON records' schemas as written into a log are ones Foxglove (and Lichtblick) parse:
their ``parseJsonSchema`` (packages/mcap-support) takes one ``type`` string per field,
``properties`` on every object and ``items`` on every array, and throws on anything else,
which rejects the whole channel. The records themselves are still checked against the
full schemas (nullable fields, enumerations)."""

from __future__ import annotations

import json

import pytest

from sgtool.log import schemas as S

SCALARS = ("boolean", "string", "number", "integer")


def foxglove_fields(schema: dict, where: str) -> list[str]:
    """The fields Foxglove's parser makes of an object schema (a transliteration of its
    rules); AssertionError naming the field it would throw on."""
    assert schema.get("type") == "object", f"{where}: not an object"
    out = []
    for name, field in schema["properties"].items():
        path = f"{where}.{name}"
        kind = field.get("type")
        if kind in SCALARS:
            out.append(path)
        elif kind == "object":
            out += [path, *foxglove_fields(field, path)]
        elif kind == "array":
            items = field["items"]
            assert items.get("type") in (*SCALARS, "object"), f"{path}: array items"
            out += [path, *(foxglove_fields(items, path) if items["type"] == "object" else [])]
        else:
            raise AssertionError(f"{path}: type {kind!r} is not one Foxglove parses")
    return out


@pytest.mark.parametrize("name", sorted(S.RECORDS))
def test_every_record_schema_parses_in_foxglove(name: str) -> None:
    kind = S.RECORDS[name]
    written = json.loads(kind.schema_bytes())
    fields = foxglove_fields(written, "")
    # every field of the full schema is shown
    assert {f.split(".")[1] for f in fields} == set(kind.schema["properties"])


def test_the_written_form_keeps_the_full_schema_for_checks() -> None:
    action = S.RECORDS["action"]
    assert action.schema["properties"]["graph_time_ns"]["type"] == ["integer", "null"]
    written = json.loads(action.schema_bytes())
    assert written["properties"]["graph_time_ns"]["type"] == "integer"
    item = json.loads(S.RECORDS["instances"].schema_bytes())["properties"]["instances"]
    assert item["items"]["properties"]["kind"]["type"] == "string"
    assert item["items"]["properties"]["kind"]["enum"] == ["object", "furniture", "door",
                                                          "structure"]


def test_arrays_of_arrays_and_boolean_enums_are_written_as_foxglove_takes_them() -> None:
    """No record has them yet; a record that gets one must not take its channel down."""
    kind = S.RecordKind("probe", "sgtool.Probe", "1.0", "/sgtool/probe", {
        "type": "object",
        "properties": {"polygon": {"type": "array",
                                   "items": {"type": "array", "items": {"type": "number"}}},
                       "flag": {"enum": [True, False, None]}},
        "required": []})
    written = json.loads(kind.schema_bytes())
    assert sorted(foxglove_fields(written, "")) == [".flag", ".polygon"]
    assert written["properties"]["flag"]["type"] == "boolean"
