"""`sgtool eval` scores every run once and says when its inputs do not add up: a run given
twice (a copy of a log, a table and its logs) counts once; runs of one name that ended
otherwise (other houses under the generated name house-0) are kept, pooled and named;
planners run on other queries under the same (house, episode, seed) are not comparable;
a run-bench table without seen/unseen flags gets them as its logs do
(sgtool.analysis.eval_run.once_each)."""

from __future__ import annotations

import dataclasses
import json

from click.testing import CliRunner

from sgtool.analysis.eval_run import once_each
from sgtool.cli import cli
from sgtool.results import EpisodeResult, write_jsonl

RUN = EpisodeResult("greedy", 0, "house-0", 0, "mug", True, steps=4, travelled_m=10.0,
                    shortest_m=9.48, source="logs/a.mcap")


def test_a_run_given_twice_counts_once() -> None:
    copy = dataclasses.replace(RUN, source="copy.mcap", wall={"decision_s": 0.1})
    kept, notes = once_each([RUN, copy])
    assert kept == [RUN]
    assert notes == ["1 episode(s) were given twice (a copy of a log, or a log and a table "
                     "that lists it): each is scored once"]


def test_runs_of_one_name_that_ended_otherwise_are_kept_and_named() -> None:
    other = dataclasses.replace(RUN, success=False, steps=50)
    kept, notes = once_each([RUN, other])
    assert kept == [RUN, other]
    assert len(notes) == 1 and "greedy on house-0" in notes[0] and "pooled" in notes[0]
    # another query under the same (house, episode, seed) is another episode: no note
    assert once_each([RUN, dataclasses.replace(RUN, query="bowl")])[1] == []


def test_eval_notes_planners_run_on_other_queries_and_fills_seen(tmp_path) -> None:
    """Two tables of house-0 episode 0 with other queries (houses of other sizes): the
    planners' rows are not comparable, and eval says so; rows without seen/unseen get it
    from the query split, as logs do."""
    a, b = tmp_path / "a" / "episodes.jsonl", tmp_path / "b" / "episodes.jsonl"
    a.parent.mkdir()
    b.parent.mkdir()
    write_jsonl([dataclasses.replace(RUN, planner="random", seen=None)], a)
    write_jsonl([dataclasses.replace(RUN, query="bowl", seen=None)], b)
    r = CliRunner().invoke(cli, ["eval", str(a.parent), str(b.parent), "--json"])
    assert r.exit_code == 0, r.output
    assert "the planners ran on different episodes (greedy 1, random 1; 0 in common)" \
        in r.stderr
    doc = json.loads(r.stdout)
    assert {p: v["episodes"] for p, v in doc["planners"].items()} == {"greedy": 1, "random": 1}
    assert {(s["planner"], s["seen_n"] + s["unseen_n"]) for s in doc["seen_unseen"]} == \
        {("greedy", 1), ("random", 1)}  # (a row without the flag was in neither)


def test_p_without_logged_decisions_says_so(tmp_path) -> None:
    """-p on a table (no MCAP log): the error says there is no logged decision, not that
    the logs lack scene graphs."""
    write_jsonl([RUN], tmp_path / "episodes.jsonl")
    r = CliRunner().invoke(cli, ["eval", str(tmp_path), "-p", "greedy"])
    assert r.exit_code == 2 and "the inputs' logs hold no decision" in r.output, r.output


def test_one_episode_under_two_noise_profiles_is_two_runs(tmp_path) -> None:
    """An older run-bench table (rows without a noise field; the profile is the folder of
    each log) where an episode ended alike under two profiles: two runs, one per
    profile, not one given twice."""
    rows = [dataclasses.replace(RUN, noise="", source=f"logs/{noise}/greedy/house-0/ep-000.mcap")
            for noise in ("none", "strong")]
    write_jsonl(rows, tmp_path / "episodes.jsonl")
    r = CliRunner().invoke(cli, ["eval", str(tmp_path), "--json"])
    assert r.exit_code == 0, r.output
    assert "given twice" not in r.stderr and "different episodes" not in r.stderr, r.stderr
    doc = json.loads(r.stdout)
    assert {p: v["episodes"] for p, v in doc["planners"].items()} == \
        {"greedy [none]": 1, "greedy [strong]": 1}


def test_eval_takes_the_auc_e_budgets_the_run_was_made_with(tmp_path) -> None:
    """A bench run made with --step-budget 30 --distance-budget 1000 is re-scored with
    them (its summary.json records them), unless eval is given others."""
    run = tmp_path / "run"
    run.mkdir()
    write_jsonl([RUN, dataclasses.replace(RUN, episode=1, success=False, steps=50)],
                run / "episodes.jsonl")
    (run / "summary.json").write_text(json.dumps(
        {"settings": {"distance_budget": 1000.0, "step_budget": 30.0}}))

    def budgets(*args: str) -> dict[str, float]:
        r = CliRunner().invoke(cli, ["eval", str(run), "--json", *args])
        assert r.exit_code == 0, r.output
        return {k: v["max"] for k, v in json.loads(r.output)["budgets"].items()}

    assert budgets() == {"distance": 1000.0, "steps": 30.0}
    assert budgets("--step-budget", "40") == {"distance": 1000.0, "steps": 40.0}
    (run / "summary.json").unlink()  # nothing recorded: MoMa-LLM's
    assert budgets() == {"distance": 5000.0, "steps": 50.0}


def test_a_stricter_success_rule_says_what_it_turned(tmp_path) -> None:
    """--success done on episodes recorded under observed (no done() at the end): their
    successes become failures, and a note says why instead of an SR of 0 alone."""
    write_jsonl([RUN], tmp_path / "episodes.jsonl")
    r = CliRunner().invoke(cli, ["eval", str(tmp_path / "episodes.jsonl"), "--success",
                                 "done"])
    assert r.exit_code == 0, r.output
    assert "--success done: successes of greedy that end without done() naming an object " \
        "count as failures" in r.output


def test_a_truncated_log_among_the_inputs_is_left_out_not_fatal(tmp_path) -> None:
    """One cut-off MCAP beside a readable table: the metrics of what was read are printed,
    then the one line saying the log was left out (exit 2), as for an unreadable table."""
    from support.paths import GOLDEN

    write_jsonl([RUN], tmp_path / "episodes.jsonl")
    data = (GOLDEN / "house6-tour.mcap").read_bytes()
    (tmp_path / "half.mcap").write_bytes(data[: len(data) // 2])
    r = CliRunner().invoke(cli, ["eval", str(tmp_path / "episodes.jsonl"),
                                 str(tmp_path / "half.mcap")])
    assert r.exit_code == 2
    assert "| greedy" in r.output  # the metrics of the table
    assert "1 of 2 input(s) could not be read and are left out" in r.output
    assert r.output.count("not read (") == 1, r.output  # the note says why, the line not again
    assert "half.mcap" not in r.output.strip().splitlines()[-1], r.output


def test_seen_unseen_figures_are_rounded_as_the_planners_are(tmp_path) -> None:
    """eval --json printed 0.47400000000000003 in seen_unseen, 0.474 in planners."""
    runs = [dataclasses.replace(RUN, episode=i, seen=True, success=i < 2,
                                travelled_m=10.0 + i / 3) for i in range(3)]
    write_jsonl(runs, tmp_path / "episodes.jsonl")
    r = CliRunner().invoke(cli, ["eval", str(tmp_path / "episodes.jsonl"), "--json"])
    assert r.exit_code == 0, r.output
    (row,) = json.loads(r.stdout)["seen_unseen"]
    assert row["seen_spl"] == round(row["seen_spl"], 6) and row["seen_sr"] == round(2 / 3, 6)


def test_p_with_decisions_naming_no_graph_says_which_field(tmp_path) -> None:
    """A hand-written log whose action names a graph_time_ns before its only scene graph:
    the error names the field, not "no graph before it" (there is one)."""
    import sgtool

    graph = sgtool.SceneGraph.from_dict({"version": "1.0", "robot": {"position": [0, 0]}})
    log = tmp_path / "hand.mcap"
    with sgtool.LogWriter(log) as w:
        w.write_record(sgtool.EpisodeRecord(kind="search", status="started", query="mug",
                                            planner="greedy"), 0)
        w.write_record(sgtool.SceneGraphRecord.of_graph(graph), 1)
        w.write_record(sgtool.ActionRecord("explore", None, "look", outcome="success",
                                            graph_time_ns=0), 2)
    r = CliRunner().invoke(cli, ["eval", str(log), "-p", "greedy"])
    assert r.exit_code == 2, r.output
    assert "has a SceneGraph record at or before its graph_time_ns" in r.output, r.output


def test_a_hand_written_log_takes_its_own_seed(tmp_path) -> None:
    """Two logs written with LogWriter(seed=1) and (seed=2), their records without extra:
    two seeds of one episode, not one run given twice with other endings."""
    import sgtool

    for seed, ok in ((1, True), (2, False)):
        with sgtool.LogWriter(tmp_path / f"s{seed}.mcap", seed=seed) as w:
            start = dict(kind="search", query="mug", planner="mine", house_id="h")
            w.write_record(sgtool.EpisodeRecord(status="started", **start), 0)
            w.write_record(sgtool.EpisodeRecord(
                status="success" if ok else "failure", steps=2, travelled_m=3.0,
                shortest_m=3.0, **start), 1)
    r = CliRunner().invoke(cli, ["eval", str(tmp_path / "s1.mcap"), str(tmp_path / "s2.mcap"),
                                 "--json"])
    assert r.exit_code == 0, r.output
    assert "pooled" not in r.stderr, r.stderr
    doc = json.loads(r.stdout)
    assert doc["planners"]["mine"]["episodes"] == 2
