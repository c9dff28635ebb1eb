"""Golden-log regression in your own test suite, with sgtool's pytest plug-in.

Pin your logs once and commit the folder::

    sgtool golden pin runs/*.mcap --dir tests/golden-logs --copy

Then either run every pinned log as a test case (the report is the failure message)::

    pytest --sgtool-golden=tests/golden-logs tests/golden-logs

or check chosen logs from your tests with the ``sgtool_golden`` fixture, as this file does
with sgtool's own golden logs (``tests/golden``, pinned by the same command)::

    python -m pytest examples/test_golden_logs.py
    python -m pytest examples/test_golden_logs.py --sgtool-golden-update   # accept a change

``sgtool_golden.check(log, folder, **replay_options)`` pins a log on its first run (the
test fails once, asking you to commit the pin), then fails with what changed layer by
layer (rooms, objects, doors, frontiers, Voronoi graph, quality figures) whenever the
current code replays it differently. The plug-in comes with sgtool (entry point
``pytest11``); nothing to import.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

PINS = Path(os.environ.get("SGTOOL_GOLDEN_DIR",
                           Path(__file__).resolve().parents[1] / "tests" / "golden"))


@pytest.mark.parametrize("name", ["house6-tour"])
def test_the_log_replays_as_pinned(sgtool_golden, name):
    sgtool_golden.check(PINS / f"{name}.mcap", PINS)


def test_a_coarser_map_would_change_it(sgtool_golden):
    """What a parameter change would do: the same log, replayed with 8 cm voxels, is no
    longer what was pinned (the fixture fails with the report)."""
    with pytest.raises(pytest.fail.Exception, match=r"refresh \d+ at .* differs"):
        sgtool_golden.check(PINS / "house10-start.mcap", PINS, every=10,
                            classifier="containment", voxel_size=0.08)
