"""The closed vocabularies (sgtool.vocabulary): one source for the Literal types, the log
schemas' enumerations and the instance table's checks; the schema bytes every log carries
do not change."""

from __future__ import annotations

import copy
import hashlib
import pickle

import pytest

from sgtool.log import schemas as S
from sgtool.log.records import ABSENT, RECORD_TYPES, Absent, Action, Episode, given
from sgtool.scenegraph.instances import InstanceInfo
from sgtool.vocabulary import (
    EPISODE_KINDS,
    EPISODE_STATUSES,
    INSTANCE_KINDS,
    LOGGED_SKILLS,
    OPEN_STATES,
    OUTCOMES,
    RECORD_NAMES,
    RELATIONS,
    SKILLS,
)

# sha256 of RecordKind.schema_bytes(), the schema record written into every log
SCHEMA_SHA256 = {
    "episode": "09a772f2cd73b39c60a9ef1a2689d2220978bcfbc5d9aff52e924e59884cba49",
    "instances": "3a7144fe8a9f4bcfbd2d10db092c8adef810eda86696e0b0cd0e39c992add11d",
    "action": "9a37e0244a879ed2d3622b932947537a31fdb048995b5fe543ab9f4783ff6e06",
    "scene_graph": "d75746a34e204e347ce74f3eba19ac3715d2c79915dbcfc496545997f41253ed",
    "llm_exchange": "ebee81511fa0b81154bcbf905d2fa55e1dd344f1af15df72ee35b147bbfb7ac4",
}


def test_the_values_in_schema_order() -> None:
    assert EPISODE_KINDS == ("recording", "search", "import")
    assert EPISODE_STATUSES == ("started", "success", "failure", "ended")
    assert SKILLS == ("navigate", "open", "close", "explore", "done")
    assert LOGGED_SKILLS == (*SKILLS, "look_around")
    assert OUTCOMES == ("success", "failure", "invalid")
    assert INSTANCE_KINDS == ("object", "furniture", "door", "structure")
    assert OPEN_STATES == ("open", "closed")
    assert RELATIONS == ("inside", "ontop")
    assert set(RECORD_NAMES) == set(RECORD_TYPES) == set(S.RECORDS)


def test_the_schemas_enumerate_the_vocabularies() -> None:
    episode = S.RECORDS["episode"].schema["properties"]
    assert episode["kind"]["enum"] == list(EPISODE_KINDS)
    assert episode["status"]["enum"] == list(EPISODE_STATUSES)
    item = S.RECORDS["instances"].schema["properties"]["instances"]["items"]["properties"]
    assert item["kind"]["enum"] == list(INSTANCE_KINDS)
    assert item["state"]["enum"] == [*OPEN_STATES, None]
    assert item["relation"]["enum"] == [*RELATIONS, None]
    action = S.RECORDS["action"].schema["properties"]
    assert action["outcome"]["enum"] == list(OUTCOMES)
    assert action["skill"] == {"type": "string"}  # open: imported logs name their own


@pytest.mark.parametrize("name", sorted(SCHEMA_SHA256))
def test_schema_bytes_unchanged(name: str) -> None:
    assert hashlib.sha256(S.RECORDS[name].schema_bytes()).hexdigest() == SCHEMA_SHA256[name]


def test_a_value_outside_a_vocabulary_is_refused() -> None:
    with pytest.raises(ValueError, match="kind must be one of"):
        InstanceInfo(1, "cup", kind="thing")
    with pytest.raises(ValueError, match="state must be"):
        InstanceInfo(1, "cup", state="ajar")
    with pytest.raises(ValueError, match="relation must be"):
        InstanceInfo(1, "cup", relation="under")
    assert InstanceInfo(1, "box", kind="furniture", state="closed").state == "closed"


def test_absent_is_one_falsy_object() -> None:
    assert isinstance(ABSENT, Absent) and not ABSENT and repr(ABSENT) == "ABSENT"
    assert pickle.loads(pickle.dumps(ABSENT)) is ABSENT
    assert copy.deepcopy(ABSENT) is ABSENT
    a = Action(skill="done", outcome="success")
    assert a.step is ABSENT and "step" not in a.to_json()
    assert pickle.loads(pickle.dumps(a)) == a


def test_given_takes_absent_and_null_out() -> None:
    e = Episode(kind="search", status="started", query=None, steps=3)
    assert given(e.query) is None and given(e.query, "") == ""
    assert given(e.planner, "unknown") == "unknown"  # absent
    assert given(e.steps, 0) == 3
    assert given(Episode(kind="import", status="ended", query="cup").query) == "cup"
