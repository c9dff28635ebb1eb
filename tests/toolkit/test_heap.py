"""sgtool.heap.frozen_heap: objects alive at the start are exempt from full collections
inside the block, and only there (also when the block raises). The test session freezes
its heap (tests/conftest.py); these tests run unfrozen, as a process that froze nothing."""

from __future__ import annotations

import gc
import weakref

import pytest

from sgtool.heap import frozen_heap

pytestmark = pytest.mark.usefixtures("unfrozen_heap")


def test_frozen_inside_the_block_only() -> None:
    keep = [object() for _ in range(10)]
    with frozen_heap():
        assert gc.get_freeze_count() >= len(keep)
    assert gc.get_freeze_count() == 0  # unfrozen: back in the oldest generation


def test_unfrozen_when_the_block_raises() -> None:
    with pytest.raises(ValueError), frozen_heap():
        assert gc.get_freeze_count() > 0
        raise ValueError("boom")
    assert gc.get_freeze_count() == 0


def test_a_cycle_made_before_is_collected_after_the_block() -> None:
    class Node:
        other: object

    a, b = Node(), Node()
    a.other, b.other = b, a
    alive = weakref.ref(a)
    with frozen_heap():
        del a, b  # garbage now, but frozen: a full collection skips the cycle
        gc.collect()
        assert alive() is not None
    gc.collect()  # unfrozen, the collector finds it
    assert alive() is None


def test_a_nested_block_leaves_the_outer_freeze_alone() -> None:
    class Node:
        other: object

    a, b = Node(), Node()
    a.other, b.other = b, a
    alive = weakref.ref(a)
    with frozen_heap():
        assert gc.get_freeze_count() > 0
        del a, b  # garbage now, frozen by the outer block
        with frozen_heap():
            pass
        # the inner block did not unfreeze: a full collection still skips the cycle (the
        # freeze count itself can drop while frozen objects are freed by reference count)
        gc.collect()
        assert alive() is not None
    assert gc.get_freeze_count() == 0
    gc.collect()
    assert alive() is None


def test_small_pages_turns_numpy_huge_pages_off_inside_the_block_only() -> None:
    from sgtool.heap import hugepage_setter, small_pages

    setter = hugepage_setter()
    assert setter is not None  # numpy 2.x has the switch
    before = setter(True)
    try:
        with small_pages():
            assert setter(False) is False  # off inside (setting it again returns that)
        assert setter(True) is True  # restored on the way out
    finally:
        setter(before)


def test_small_pages_blocks_overlapping_out_of_order_restore_the_setting() -> None:
    from sgtool.heap import hugepage_setter, small_pages

    setter = hugepage_setter()
    assert setter is not None
    before = setter(True)
    try:
        first, second = small_pages(), small_pages()
        first.__enter__()
        second.__enter__()
        first.__exit__(None, None, None)  # the first leaves while the second is inside
        assert setter(False) is False  # still off
        second.__exit__(None, None, None)
        assert setter(True) is True  # the last to leave restored it
    finally:
        setter(before)


def test_garbage_from_before_the_block_does_not_outlive_it() -> None:
    class Node:
        other: object

    for _ in range(3):  # task after task, as a bench worker runs them
        a, b = Node(), Node()
        a.other, b.other = b, a
        dead = weakref.ref(a)
        del a, b  # cyclic garbage, not yet collected
        with frozen_heap():
            assert dead() is None  # collected on entry, not frozen


def test_a_ctrl_c_as_the_heap_freezes_leaves_it_unfrozen(monkeypatch) -> None:
    """A KeyboardInterrupt raised just after gc.freeze (it arrives while the collection
    before it runs) must not leave the heap frozen for the rest of the process."""
    freeze = gc.freeze

    def freeze_then_interrupt() -> None:
        freeze()
        raise KeyboardInterrupt

    monkeypatch.setattr(gc, "freeze", freeze_then_interrupt)
    with pytest.raises(KeyboardInterrupt), frozen_heap():
        pass
    assert gc.get_freeze_count() == 0


def test_one_blas_thread_in_overlapping_blocks_restores_the_process_setting() -> None:
    """Two replays in threads whose blocks overlap out of order: the BLAS limit is back at
    the process's own setting after both, not at the 1 the second block saw on entry."""
    from threadpoolctl import threadpool_info

    from sgtool.blas import single_blas_thread

    def limits() -> list[int]:
        return [p["num_threads"] for p in threadpool_info() if p["user_api"] == "blas"]

    import numpy  # noqa: F401  (loads OpenBLAS)
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=2, user_api="blas"):  # the process's own setting
        before = limits()
        assert before and set(before) == {2}
        first, second = single_blas_thread(), single_blas_thread()
        first.__enter__()
        assert set(limits()) == {1}
        second.__enter__()
        first.__exit__(None, None, None)  # the first leaves while the second is inside
        assert set(limits()) == {1}
        second.__exit__(None, None, None)
        assert limits() == before
