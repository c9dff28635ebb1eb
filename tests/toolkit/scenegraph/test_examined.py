"""Which pieces count as looked at from close by (:mod:`sgtool.scenegraph.examined`), and the
rule shared with the symbolic environment."""

from __future__ import annotations

import numpy as np
import pytest

from sgtool.scenegraph.examined import EXAMINE, EXAMINE_RANGE_M, close_views, examinable


def _frame(patches: list[tuple[int, int, float]], shape=(12, 16)) -> tuple[np.ndarray, np.ndarray]:
    """ids and depth images: each patch (instance, pixels, depth) fills the next pixels."""
    ids = np.zeros(shape, dtype=np.int32)
    depth = np.full(shape, 4.0, dtype=np.float32)
    flat_i, flat_d = ids.reshape(-1), depth.reshape(-1)
    at = 0
    for iid, n, d in patches:
        flat_i[at:at + n] = iid
        flat_d[at:at + n] = d
        at += n
    return ids, depth


def test_near_enough_pixels_count_and_far_or_few_do_not() -> None:
    ids, depth = _frame([(5, 20, 1.5), (6, 20, 3.0), (7, 3, 1.0), (9, 12, EXAMINE_RANGE_M)])
    assert close_views(ids, depth, min_points=10) == [5, 9]  # 9: exactly at the range
    assert close_views(ids, depth, min_points=3) == [5, 7, 9]
    assert close_views(ids, depth, min_points=10, max_depth=3.0) == [5, 6, 9]
    big = ids.astype(np.int64) << 24  # ids too large to count by index: the sorted path
    assert close_views(big, depth, min_points=10) == [5 << 24, 9 << 24]


def test_the_mean_depth_decides_and_invalid_depth_is_ignored() -> None:
    ids, depth = _frame([(4, 10, 1.0), (4, 10, 3.5)])  # mean 2.25 m: too far
    assert close_views(ids, depth, min_points=5) == []
    ids, depth = _frame([(4, 10, 1.0), (4, 10, np.nan), (4, 5, 0.0)])  # 10 valid pixels at 1 m
    assert close_views(ids, depth, min_points=10) == [4]
    assert close_views(ids, depth, min_points=11) == []
    background, _ = _frame([])
    assert close_views(background, depth, min_points=1) == []  # id 0 is no instance


@pytest.mark.parametrize("affordances,small,expected", [
    (("supporter",), False, True), (("container", "openable"), False, True),
    (("Supporter",), False, True), ((), False, False), (("openable",), False, False),
    (("supporter",), True, False), (("container",), True, True),
])
def test_examinable_pieces(affordances, small, expected) -> None:
    assert examinable(affordances, small_object=small) is expected
    assert EXAMINE == "examine"
