"""`sgtool eval` scores search episodes only, and refuses figures that cannot be true."""

from __future__ import annotations

import dataclasses
import json
import math

import pytest
from click.testing import CliRunner
from support.paths import GOLDEN

from sgtool.analysis.offline import load_results
from sgtool.analysis.validity import episode_problem
from sgtool.cli import cli
from sgtool.log import LogWriter
from sgtool.log.records import Episode
from sgtool.results import EpisodeResult, write_jsonl

GOOD = EpisodeResult("greedy", 0, "h", 0, "mug", True, steps=4, travelled_m=10.0,
                     shortest_m=5.0)


@pytest.mark.parametrize(("change", "problem"), [
    ({"steps": -5}, "steps -5 is negative"),
    ({"n_open": -1}, "n_open -1 is negative"),
    ({"n_invalid": -2}, "n_invalid -2 is negative"),
    ({"n_failure": -3}, "n_failure -3 is negative"),
    ({"travelled_m": -1.0}, "travelled_m -1 m is negative"),
    ({"travelled_m": math.inf}, "travelled_m inf is not a finite number"),
    ({"shortest_m": -0.5}, "shortest_m -0.5 m is negative"),
    ({"shortest_m": math.nan}, "shortest_m nan is not a finite number"),
])
def test_impossible_figures_name_the_field(change, problem):
    assert episode_problem(dataclasses.replace(GOOD, **change)) == problem


@pytest.mark.parametrize("change", [
    {}, {"shortest_m": None}, {"shortest_m": 0.0, "travelled_m": 0.0, "steps": 0},
    {"success": False, "steps": 0, "travelled_m": 0.0},
])
def test_possible_figures_pass(change):
    assert episode_problem(dataclasses.replace(GOOD, **change)) is None


def test_eval_refuses_the_nonsense_episode_and_scores_the_rest(tmp_path):
    bad = dataclasses.replace(GOOD, episode=1, steps=-5, travelled_m=-1.0, shortest_m=0.0)
    eps = write_jsonl([GOOD, bad], tmp_path / "episodes.jsonl")
    r = CliRunner().invoke(cli, ["eval", str(eps), "--json"])
    assert r.exit_code == 0, r.output
    assert f"sgtool: note: {eps}: record 2: refused: steps -5 is negative" in r.stderr
    doc = json.loads(r.stdout)
    assert doc["episodes"] == 1
    assert doc["notes"] == [f"{eps}: record 2: refused: steps -5 is negative"]
    row = doc["planners"]["greedy"]
    assert row["sr"]["mean"] == 1.0 and row["spl"]["mean"] == pytest.approx(0.5)  # 5 / 10


def test_only_nonsense_is_a_one_line_error(tmp_path):
    bad = dataclasses.replace(GOOD, travelled_m=-1.0)
    eps = write_jsonl([bad], tmp_path / "episodes.jsonl")
    r = CliRunner().invoke(cli, ["eval", str(eps)])
    assert r.exit_code == 2
    assert r.stderr.strip().splitlines() == [
        f"sgtool: note: {eps}: record 1: refused: travelled_m -1 m is negative",
        f"sgtool: error: no search episodes to score in {eps} (1 skipped or refused, see "
        "the notes)"]


def test_recordings_and_imports_are_skipped_with_a_note(tmp_path):
    recording = GOLDEN / "house6-tour.mcap"  # a scripted recording (Episode kind recording)
    notes: list[str] = []
    results, logged = load_results([recording], notes)
    assert results == [] and logged == []
    assert notes == [f"{recording}: skipped 1 episode record(s) of kind recording "
                     "(not a search episode)"]
    eps = write_jsonl([GOOD], tmp_path / "episodes.jsonl")
    log = tmp_path / "imported.mcap"
    with LogWriter(log) as w:
        w.write_record(Episode(kind="import", status="started", frames=0), 0)
        w.write_record(Episode(kind="import", status="ended", frames=3), 10)
    r = CliRunner().invoke(cli, ["eval", str(log), str(recording), str(eps), "--json"])
    assert r.exit_code == 0, r.output
    assert json.loads(r.stdout)["episodes"] == 1  # not failed searches of planner "unknown"
    assert "unknown" not in r.stdout
    assert f"{log}: skipped 1 episode record(s) of kind import" in r.stderr
    assert f"{recording}: skipped 1 episode record(s) of kind recording" in r.stderr


def test_eval_help_states_the_rules():
    r = CliRunner().invoke(cli, ["eval", "-h"])
    text = " ".join(r.output.split())
    assert "logs of recordings and imports are skipped with a note" in text
    assert "is refused" in text and "A shortest_m of 0 is accepted" in text
