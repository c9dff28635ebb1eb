"""Ids and file names that end in characters str.isdigit() accepts but int() does not
(superscripts) sort as text instead of crashing; decimal digits of any script sort by value.
File names: tests/recorders/importers/test_folder_inputs.py."""

from __future__ import annotations

from sgtool.planning.candidates import natural_key
from sgtool.scenegraph.graph import _idkey


def test_node_ids_with_superscripts_sort_as_text() -> None:
    assert natural_key("obj:²") == ("obj", ((1, "²"),))
    assert _idkey("obj:²") == ("obj", ((1, "²"),))
    assert sorted(["obj:10", "obj:²", "obj:2"], key=natural_key) == ["obj:2", "obj:10", "obj:²"]
    assert natural_key("room:١٢") == ("room", ((0, 12),))  # Arabic-Indic digits: a number


def test_a_house_seed_that_is_no_integer_is_none() -> None:
    from sgtool.log.inspect import _SEED

    assert [bool(_SEED.fullmatch(s)) for s in ("12", "-3", "--5", "²", "1-", "")] == \
        [True, True, False, False, False, False]
