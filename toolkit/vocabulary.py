"""The closed vocabularies of sgtool's log contract and planner interface, as ``Literal`` types.

One place names each set of allowed strings; mypy checks every use, and the runtime checks
(the log schemas' enumerations in :mod:`sgtool.log.schemas`, the instance table's
validation) read the same values through the ``*_VALUES`` tuples, in the order written
here (the order the log schemas list them, so schema bytes do not change).

The values stay plain ``str`` at run time (``Literal``, not an enum): records compare,
hash and serialise exactly as before.

================  ===================================================================
type              values and where they appear
================  ===================================================================
``RecordName``    the JSON record kinds (``sgtool.log.records.RECORD_TYPES`` keys)
``EpisodeKind``   ``sgtool.Episode`` ``kind``: how the log came about
``EpisodeStatus`` ``sgtool.Episode`` ``status``: started, or how the run ended
``Skill``         a planner's :class:`sgtool.planning.base.Action` skill
``LoggedSkill``   a skill an sgtool recorder logs (``Skill`` plus the closed loop's
                  ``look_around``); the ``sgtool.Action`` schema itself admits any string
``Outcome``       the outcome of an executed action (``sgtool.Action`` ``outcome``)
``InstanceKind``  what an instance id is (``sgtool.Instances`` item ``kind``)
``OpenState``     the state of an openable thing (``state``; ``None`` for the rest)
``Relation``      how a small object rests on its parent (``relation``)
================  ===================================================================
"""

from __future__ import annotations

from typing import Final, Literal, get_args

RecordName = Literal["episode", "instances", "action", "scene_graph", "llm_exchange"]
EpisodeKind = Literal["recording", "search", "import"]
EpisodeStatus = Literal["started", "success", "failure", "ended"]
Skill = Literal["navigate", "open", "close", "explore", "done"]
LoggedSkill = Literal[Skill, "look_around"]
Outcome = Literal["success", "failure", "invalid"]
InstanceKind = Literal["object", "furniture", "door", "structure"]
OpenState = Literal["open", "closed"]
Relation = Literal["inside", "ontop"]

RECORD_NAMES: Final[tuple[RecordName, ...]] = get_args(RecordName)
EPISODE_KINDS: Final[tuple[EpisodeKind, ...]] = get_args(EpisodeKind)
EPISODE_STATUSES: Final[tuple[EpisodeStatus, ...]] = get_args(EpisodeStatus)
SKILLS: Final[tuple[Skill, ...]] = get_args(Skill)
LOGGED_SKILLS: Final[tuple[LoggedSkill, ...]] = get_args(LoggedSkill)
OUTCOMES: Final[tuple[Outcome, ...]] = get_args(Outcome)
INSTANCE_KINDS: Final[tuple[InstanceKind, ...]] = get_args(InstanceKind)
OPEN_STATES: Final[tuple[OpenState, ...]] = get_args(OpenState)
RELATIONS: Final[tuple[Relation, ...]] = get_args(Relation)
