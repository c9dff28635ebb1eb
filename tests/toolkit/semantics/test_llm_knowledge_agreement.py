"""Agreement of LLM-generated relational labels with a reference set, and ``--llm-slice``."""

from __future__ import annotations

import math

import pytest
from click.testing import CliRunner

from sgtool.cli import cli
from sgtool.commands.distill import _slice
from sgtool.errors import SgtoolError
from sgtool.semantics.llm_knowledge import agreement
from sgtool.semantics.relational_set import table_to_set


def test_agreement_on_common_pairs() -> None:
    llm = table_to_set("containment", {("kitchen", "frying pans"): 0.9, ("bathroom", "pot"): 0.6,
                                       ("bathroom", "soap"): 0.8, ("garage", "car"): 1.0})
    ref = table_to_set("containment", {("kitchen", "frying_pan"): 0.3, ("bathroom", "pot"): 0.0,
                                       ("bathroom", "soap"): 0.5, ("kitchen", "soap"): 0.0})
    a = agreement(llm, ref)
    # three pairs in both (names compared as singular words); the pot in the bathroom: no
    assert (a.relation, a.common, a.agree, a.llm_pairs) == ("containment", 3, 2, 4)
    assert a.rate == pytest.approx(2 / 3)
    empty = agreement(table_to_set("containment", {("attic", "x"): 1.0}), ref)
    assert empty.common == 0 and math.isnan(empty.rate)


def test_slice_option() -> None:
    assert _slice(None) == {}
    assert _slice("3,2,4") == {"max_rooms": 3, "max_categories": 2, "max_objects": 4}
    for bad in ("3,2", "a,b,c", "0,1,1"):
        with pytest.raises(SgtoolError, match="--llm-slice"):
            _slice(bad)
    r = CliRunner().invoke(cli, ["distill", "--source", "llm", "--llm-slice", "1,2"])
    assert r.exit_code == 2 and r.output.startswith("sgtool: error: --llm-slice '1,2'")
