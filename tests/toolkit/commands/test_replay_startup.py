"""``sgtool replay`` does not import what only other paths need (start-up CPU)."""

from __future__ import annotations

import subprocess
import sys

import numpy as np

from sgtool.mapping.grid import OccupancyGrid
from sgtool.mapping.raster import polygon_mask


def test_replay_command_imports_neither_matplotlib_nor_networkx() -> None:
    code = ("import sys, sgtool.commands.replay, sgtool.replayers.derived_log; "
            "print(sorted(m for m in ('matplotlib', 'networkx') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "[]"


def test_polygon_rasterising_still_works_with_the_import_deferred() -> None:
    grid = OccupancyGrid(np.zeros((4, 4), np.int8), (0.0, 0.0), 1.0)
    mask = polygon_mask(grid, [(0.0, 0.0), (2.0, 0.0), (2.0, 2.0), (0.0, 2.0)])
    # centres 0.5 and 1.5 are inside the 2 m square, the border counts as inside
    assert mask.sum() == 4 and mask[:2, :2].all()


def test_a_replay_without_the_llm_classifier_loads_no_llm_client() -> None:
    # the room classifier factory of `sgtool replay`; the LLM modules pull in urllib and ssl
    code = ("import sys\n"
            "from sgtool.commands.room_llm import LlmOptions\n"
            "with LlmOptions().room_classifier() as r:\n"
            "    assert r.make('containment') is not None\n"
            "print(sorted(m for m in ('sgtool.llm.recorded', 'sgtool.llm.client', 'ssl')"
            " if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "[]"
