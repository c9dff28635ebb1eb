"""The instance table of the small two-room house (:mod:`support.small_house`)."""

from __future__ import annotations

from support.small_house import small_house

from sgtool.recorders.sim.body_instances import instance_table


def test_small_house_is_a_valid_spec() -> None:
    h = small_house()
    assert [r.id for r in h.rooms] == ["room_0", "room_1"]
    assert h.room_graph() == {"room_0": ("room_1",), "room_1": ("room_0",)}


def test_instance_ids_follow_spec_order() -> None:
    """1 floor, 6 walls (2-7), the door (8), its lintel (9), furniture (10-13), objects
    (14-18) with their parents' instance ids."""
    t = instance_table(small_house())
    assert [i.id for i in t] == list(range(1, 19))
    assert (t[0].category, t[0].kind) == ("floor", "structure")
    assert [i.spec_id for i in t[1:7]] == [f"wall_{k}" for k in range(6)]
    assert (t[7].spec_id, t[7].kind, t[7].openable) == ("door_0", "door", True)
    assert (t[8].category, t[8].kind, t[8].spec_id) == ("wall", "structure", None)
    assert [i.spec_id for i in t[9:13]] == [f"furn_{k}" for k in range(4)]
    mug, book = t[13], t[14]
    assert (mug.category, mug.parent, mug.relation) == ("mug", 10, "inside")
    assert (book.parent, book.relation) == (10, "ontop")
    assert t[9].openable and not t[10].openable and not t[12].openable
