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

# sha256 of RecordKind.schema_bytes(), the schema record written into every log (the
# form Foxglove parses since the session of 2026-12-06)
SCHEMA_SHA256 = {
    "episode": "0191bcdfc39786a325f18fdb0cc268e2d51c0411d2fde9ee5ecb0fadb63adc13",
    "instances": "8b1e4be18883ac4c982506a7e088cf11b1f6e37db37f371e2847087d514fbef2",
    "action": "ad4aec0059323cd4663298a47eb0c46769c945c2ef9a194fd6b495df4eea4640",
    "scene_graph": "871fff57ca45b5e9f0034ac6bb073b2aeeb90aef751c5ad64693e87a7845d0e2",
    "llm_exchange": "24dfebd4d01c95bc7371c37b4cdf6a593b3d9f72a37692a831fd67edca4fd6c4",
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
