"""`sgtool eval` keeps runs of one planner with other options apart: each episode record
carries the options its planner ran with (tables and logs alike), and two option sets under
one name are scored as two planners, ``NAME()`` and ``NAME(KEY=VALUE)``, never pooled
(sgtool.analysis.eval_run.per_options)."""

from __future__ import annotations

import dataclasses
import json

import pytest
from click.testing import CliRunner

from sgtool.analysis.eval_run import per_options
from sgtool.cli import cli
from sgtool.results import EpisodeResult, ResultsFormatError, read_jsonl, results_digest

RUN = EpisodeResult("scout", 0, "house-0", 0, "mug", True, steps=4, travelled_m=10.0,
                    shortest_m=9.48, source="a.mcap")
BENCH = ["bench", "--planners", "scout", "--houses", "1", "--episodes", "3", "--seeds", "1",
         "--max-steps", "8", "--no-progress"]


def test_options_round_trip_in_the_record_and_stay_out_when_none() -> None:
    tuned = dataclasses.replace(RUN, options={"delta": 0.3})
    assert tuned.to_dict()["options"] == {"delta": 0.3}
    assert EpisodeResult.from_dict(json.loads(tuned.to_json())) == tuned
    assert "options" not in RUN.to_dict()  # records of default runs are as before
    assert results_digest([tuned]) == results_digest([RUN])  # what was done, not how set
    with pytest.raises(ResultsFormatError, match="options: expected an object, got 3"):
        EpisodeResult.from_dict({**RUN.to_dict(), "options": 3})


def test_two_option_sets_of_one_planner_are_two_planners() -> None:
    rows = [RUN, dataclasses.replace(RUN, options={"delta": 0.3}),
            dataclasses.replace(RUN, planner="greedy")]
    out, notes = per_options(rows)
    assert [r.planner for r in out] == ["scout()", "scout(delta=0.3)", "greedy"]
    assert notes == ["planners ran with more than one set of options (scout: scout(), "
                     "scout(delta=0.3)): each set is scored as a planner of its own"]
    # an option given at its default is no option: one set, names kept
    same = [RUN, dataclasses.replace(RUN, options={"delta": 0.1})]
    assert per_options(same) == (same, [])
    # the sensor profile of per_noise stays last
    noisy = [dataclasses.replace(r, planner="scout [none]", noise="none") for r in rows[:2]]
    assert [r.planner for r in per_options(noisy, noisy=True)[0]] == \
        ["scout() [none]", "scout(delta=0.3) [none]"]


def test_eval_of_two_bench_runs_with_other_options(tmp_path) -> None:
    """Two bench runs of scout, one with -O: eval scores two planners of 3 episodes each
    (pooled, it was one planner of 6); a third run with the default given as -O is the
    first run again (each of its episodes is said to be given twice)."""
    runner = CliRunner()
    for name, extra in (("a", []), ("b", ["-O", "scout.delta=0.3"]),
                        ("c", ["-O", "scout.delta=0.1"])):
        r = runner.invoke(cli, [*BENCH, *extra, "--log-dir", str(tmp_path / name / "logs"),
                                "-o", str(tmp_path / name)])
        assert r.exit_code == 0, r.output
    assert {json.dumps(r.options) for r in read_jsonl(tmp_path / "b" / "episodes.jsonl")} \
        == {'{"delta": 0.3}'}
    r = runner.invoke(cli, ["eval", str(tmp_path / "a"), str(tmp_path / "b"),
                            str(tmp_path / "c"), "--json"])
    assert r.exit_code == 0, r.output
    doc = json.loads(r.stdout)
    assert {p: v["episodes"] for p, v in doc["planners"].items()} == \
        {"scout()": 3, "scout(delta=0.3)": 3}
    assert "scout: scout(), scout(delta=0.3)" in r.stderr
    assert "3 episode(s) were given twice" in r.stderr
    # the logs say the same as the tables: options are read from the episode records
    logs = [str(p) for p in sorted((tmp_path / "b" / "logs").rglob("*.mcap"))] + \
        [str(p) for p in sorted((tmp_path / "a" / "logs").rglob("*.mcap"))]
    r = runner.invoke(cli, ["eval", *logs, "--json", "--reference", "scout()"])
    assert r.exit_code == 0, r.output
    assert {p: v["episodes"] for p, v in json.loads(r.stdout)["planners"].items()} == \
        {"scout(delta=0.3)": 3, "scout()": 3}


def test_a_table_from_before_options_were_kept_takes_its_runs_options(tmp_path) -> None:
    """A bench table written before each record kept its options (rows without the field)
    takes them from its summary.json: its -O run is not taken for a default run, and its
    own logs given with it are the same runs (counted once)."""
    runner = CliRunner()
    for name, extra in (("a", []), ("b", ["-O", "scout.delta=0.3"])):
        r = runner.invoke(cli, [*BENCH, *extra, "--log-dir", str(tmp_path / name / "logs"),
                                "-o", str(tmp_path / name)])
        assert r.exit_code == 0, r.output
    table = tmp_path / "b" / "episodes.jsonl"
    rows = [json.loads(line) for line in table.read_text().splitlines()]
    table.write_text("".join(json.dumps({k: v for k, v in d.items() if k != "options"}) + "\n"
                             for d in rows))
    logs = [str(p) for p in sorted((tmp_path / "b" / "logs").rglob("*.mcap"))]
    r = runner.invoke(cli, ["eval", str(tmp_path / "a"), str(tmp_path / "b"), *logs,
                            "--json"])
    assert r.exit_code == 0, r.output
    assert {p: v["episodes"] for p, v in json.loads(r.stdout)["planners"].items()} == \
        {"scout()": 3, "scout(delta=0.3)": 3}
    assert "3 episode(s) were given twice" in r.stderr
    assert "rows pool them" not in r.stderr  # (the note before runs were told apart)


def test_runs_of_one_episode_with_other_shortest_paths_are_named(tmp_path) -> None:
    """Two runs of one (house, episode, seed, query) whose shortest paths differ (a
    closed-loop log from before SPL's shortest path was the pulled route) do not pair;
    eval says so rather than print an empty paired table."""
    from sgtool.results import write_jsonl

    write_jsonl([RUN, dataclasses.replace(RUN, planner="greedy", shortest_m=9.1)],
                tmp_path / "episodes.jsonl")
    r = CliRunner().invoke(cli, ["eval", str(tmp_path)])
    assert r.exit_code == 0, r.output
    assert ("1 episode(s) have other shortest paths in the inputs (first: house-0 episode "
            "0, mug: 9.1, 9.48 m) and are not paired") in r.stderr


def test_a_tables_python_only_or_secret_options_are_no_options(tmp_path) -> None:
    """A summary.json records options a record leaves out (an encoder object from Python,
    an API key, as text): rows without options do not take those, so the run is not split
    from a default run of the same episodes by an object's address; a -O option given as
    text is taken."""
    from sgtool.results import write_jsonl

    for name in ("a", "b"):
        (tmp_path / name).mkdir()
        write_jsonl([RUN], tmp_path / name / "episodes.jsonl")
    summary = tmp_path / "a" / "summary.json"
    for options, names in (({"encoder": "<SentenceEncoder object at 0x7f>",
                             "api_key": "<redacted>"}, ["scout"]),
                           ({"delta": "0.3"}, ["scout(delta=0.3)", "scout()"])):
        summary.write_text(json.dumps({"settings": {"planner_options": {"scout": options}}}))
        r = CliRunner().invoke(cli, ["eval", str(tmp_path / "a"), str(tmp_path / "b"),
                                     "--json"])
        assert r.exit_code == 0, r.output
        assert sorted(json.loads(r.stdout)["planners"]) == sorted(names)


def test_the_symbolic_benchs_own_shortest_path_is_no_unpaired_run(tmp_path) -> None:
    """The symbolic bench measures the grid geodesic, the closed loop the pulled route:
    rows of one episode under the two profiles never pair, and no note says to run them
    again."""
    from sgtool.results import write_jsonl

    write_jsonl([RUN, dataclasses.replace(RUN, shortest_m=9.1, noise="none",
                                          source="logs/none/scout/house-0/ep-000.mcap")],
                tmp_path / "episodes.jsonl")
    r = CliRunner().invoke(cli, ["eval", str(tmp_path)])
    assert r.exit_code == 0, r.output
    assert "other shortest paths" not in r.stderr
