"""`sgtool eval` prints the bench's intervals and paired comparisons, pooled over its
inputs: a run of one planner compared with a stored run of another on the same episodes
gives the figures of one bench run of both; episodes under one (house, episode, seed) with
other queries (houses of other sizes) are not paired."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

from click.testing import CliRunner

from sgtool.cli import cli
from sgtool.results import EpisodeResult, write_jsonl

BENCH = ["bench", "--houses", "2", "--episodes", "3", "--rooms", "4-5", "--seeds", "1",
         "--no-progress"]


def _bench(out: Path, planners: str) -> dict:
    r = CliRunner().invoke(cli, [*BENCH, "--planners", planners, "-o", str(out)])
    assert r.exit_code == 0, r.output
    return json.loads((out / "summary.json").read_text())


def test_two_runs_compared_as_one_bench_compares_them(tmp_path: Path) -> None:
    both = _bench(tmp_path / "both", "scout,greedy")["intervals"]
    _bench(tmp_path / "a", "scout")
    _bench(tmp_path / "b", "greedy")
    r = CliRunner().invoke(cli, ["eval", str(tmp_path / "a"), str(tmp_path / "b"),
                                 "--reference", "scout", "--json"])
    assert r.exit_code == 0, r.output
    got = json.loads(r.stdout)["intervals"]
    assert got["paired"] == both["paired"]  # greedy against scout, 6 episodes, 2 houses
    assert got["paired"][0]["episodes"] == 6 and got["paired"][0]["clusters"] == 2
    assert got["planners"] == both["planners"]
    assert got["paired_seen"] == both["paired_seen"]
    text = CliRunner().invoke(cli, ["eval", str(tmp_path / "a"), str(tmp_path / "b"),
                                    "--reference", "greedy"]).stdout
    paired = text.split("Paired comparisons on the same episodes\n", 1)[1]
    row = next(line for line in paired.splitlines() if line.startswith("| scout "))
    assert row.split("|")[2].strip() == "greedy"  # scout against the reference given
    assert "sgtool: note" not in r.stderr  # the same settings: nothing to say


def test_runs_made_apart_under_other_settings_are_named(tmp_path: Path) -> None:
    """A baseline stored with another step budget, a planner run with other options: eval
    pairs them as asked and says what differs."""
    _bench(tmp_path / "a", "scout")
    r = CliRunner().invoke(cli, [*BENCH, "--planners", "greedy,scout", "--max-steps", "10",
                                 "-O", "scout.delta=0.9", "-o", str(tmp_path / "b")])
    assert r.exit_code == 0, r.output
    r = CliRunner().invoke(cli, ["eval", str(tmp_path / "a"), str(tmp_path / "b")])
    assert r.exit_code == 0, r.output
    a, b = tmp_path / "a", tmp_path / "b"
    assert (f"sgtool: note: the runs given ran with different max_steps (50 in {a}, 10 in "
            f"{b}): their rows and paired comparisons mix them") in r.stderr
    assert "(scout: scout(), scout(delta=0.9)): each set is scored as a planner" in r.stderr
    assert "rows pool them" not in r.stderr
    # an option given at its default is no other option
    r = CliRunner().invoke(cli, [*BENCH, "--planners", "scout", "-O", "scout.delta=0.10",
                                 "-o", str(tmp_path / "c")])
    assert r.exit_code == 0, r.output
    r = CliRunner().invoke(cli, ["eval", str(a), str(tmp_path / "c")])
    assert r.exit_code == 0 and "other options" not in r.stderr, r.stderr


def test_runs_of_other_generated_houses_under_one_id_are_named(tmp_path: Path) -> None:
    """house-0 of 4-5 rooms and house-0 of 6 rooms are other houses: eval pooled them
    (two houses for four in the intervals) without a word."""
    a, b = tmp_path / "a", tmp_path / "b"
    _bench(a, "scout")
    r = CliRunner().invoke(cli, [*BENCH[:6], "6-6", *BENCH[7:], "--planners", "scout",
                                 "-o", str(b)])
    assert r.exit_code == 0, r.output
    r = CliRunner().invoke(cli, ["eval", str(a), str(b)])
    assert r.exit_code == 0, r.output
    assert (f"sgtool: note: the runs given generated their houses with different rooms "
            f"([4, 5] in {a}, [6, 6] in {b}): a house id names other houses in them") \
        in r.stderr, r.stderr
    c = tmp_path / "c"  # other houses under other ids (house-100): nothing to say
    r = CliRunner().invoke(cli, [*BENCH[:6], "6-6", *BENCH[7:], "--house-seed", "100",
                                 "--planners", "scout", "-o", str(c)])
    assert r.exit_code == 0, r.output
    r = CliRunner().invoke(cli, ["eval", str(a), str(c)])
    assert r.exit_code == 0 and "other houses" not in r.stderr, r.stderr


RUN = EpisodeResult("greedy", 0, "house-0", 0, "mug", True, steps=4, travelled_m=10.0,
                    shortest_m=9.48)


def test_other_houses_under_one_name_are_not_paired(tmp_path: Path) -> None:
    """house-0 of another size: another query, or the same query at another distance."""
    a, b = tmp_path / "a.jsonl", tmp_path / "b.jsonl"
    write_jsonl([RUN, dataclasses.replace(RUN, episode=1, query="bowl"),
                 dataclasses.replace(RUN, episode=2)], a)
    write_jsonl([dataclasses.replace(RUN, planner="random"),
                 dataclasses.replace(RUN, planner="random", episode=1, query="cup"),
                 dataclasses.replace(RUN, planner="random", episode=2, shortest_m=5.61)], b)
    r = CliRunner().invoke(cli, ["eval", str(a), str(b), "--all-pairs", "--json"])
    assert r.exit_code == 0, r.output
    (pair,) = json.loads(r.stdout)["intervals"]["paired"]
    assert (pair["planner"], pair["reference"], pair["episodes"]) == ("random", "greedy", 1)


def test_planners_pair_under_one_noise_profile_at_a_time(tmp_path: Path) -> None:
    """A run-bench under two profiles: each planner is PLANNER [NOISE]; scout is the
    reference under each profile, by its plain name too; nothing pairs across profiles."""
    rows = [dataclasses.replace(RUN, planner=p, noise=n, episode=e, success=(e + i) % 2 == 0)
            for i, p in enumerate(("greedy", "scout")) for n in ("none", "mild")
            for e in range(3)]
    a = tmp_path / "a.jsonl"
    write_jsonl(rows, a)
    for extra in ([], ["--reference", "scout"]):
        r = CliRunner().invoke(cli, ["eval", str(a), "--json", *extra])
        assert r.exit_code == 0, r.output
        pairs = {(p["planner"], p["reference"], p["episodes"])
                 for p in json.loads(r.stdout)["intervals"]["paired"]}
        assert pairs == {("greedy [none]", "scout [none]", 3),
                         ("greedy [mild]", "scout [mild]", 3)}
    r = CliRunner().invoke(cli, ["eval", str(a), "--json", "--all-pairs"])
    assert len(json.loads(r.stdout)["intervals"]["paired"]) == 2
    text = CliRunner().invoke(cli, ["eval", str(a), "--reference", "greedy"]).stdout
    paired = text.split("Paired comparisons on the same episodes\n", 1)[1].split("\n\n")[0]
    cells = [[c.strip() for c in line.split("|")[1:3]] for line in paired.splitlines()[2:]
             if line.startswith("|")]
    assert cells == [["scout [none]", "greedy [none]"], ["scout [mild]", "greedy [mild]"]]


def test_one_planner_has_intervals_and_no_pairs(tmp_path: Path) -> None:
    a = tmp_path / "a.jsonl"
    write_jsonl([RUN, dataclasses.replace(RUN, house="house-1")], a)
    text = CliRunner().invoke(cli, ["eval", str(a)]).stdout
    assert "| greedy " in text.split("SR and SPL with bootstrap intervals", 1)[1]
    assert "Paired comparisons: no two planners to pair." in text


def test_reference_mistakes_are_one_line(tmp_path: Path) -> None:
    a = tmp_path / "a.jsonl"
    write_jsonl([RUN], a)
    r = CliRunner().invoke(cli, ["eval", str(a), "--reference", "voi"])
    assert r.exit_code == 2
    assert r.stderr.strip().splitlines()[-1] == \
        "sgtool: error: --reference voi: no episode of that planner in the inputs " \
        "(planners: greedy)"
    r = CliRunner().invoke(cli, ["eval", str(a), "--reference", "greedy", "--all-pairs"])
    assert r.exit_code == 2 and "give one" in r.stderr and "Traceback" not in r.output


def test_bench_result_keeps_its_interval_methods() -> None:
    """BenchResult.intervals() / comparisons() as before the shared report."""
    import sgtool

    res = sgtool.run_benchmark(sgtool.BenchConfig(planners=("scout", "greedy"), houses=2,
                                                  episodes=3, seeds=1, rooms=(4, 5)),
                               progress=False)
    report = res.interval_report()
    assert res.intervals() == list(report.planners) and len(res.intervals()) == 2
    (pair,) = res.comparisons()
    assert (pair.planner, pair.reference, pair.episodes) == ("greedy", "scout", 6)
    assert res.comparisons(seen=True) == list(report.paired_seen)
    assert res.comparisons(seen=False) == list(report.paired_unseen)
    from sgtool.analysis.intervals import Bootstrap

    few = res.intervals(Bootstrap(resamples=100))  # the same figures, other intervals
    assert [r.sr.value for r in few] == [r.sr.value for r in res.intervals()]


def test_episodes_without_a_shortest_path_are_named(tmp_path: Path) -> None:
    """SR counts an episode whose shortest path is unknown, SPL leaves it out: eval says so,
    as the case where SPL (over fewer episodes) can stand above SR."""
    rows = tmp_path / "episodes.jsonl"
    write_jsonl([RUN, dataclasses.replace(RUN, episode=1, success=False, steps=50,
                                          shortest_m=None)], rows)
    r = CliRunner().invoke(cli, ["eval", str(rows)])
    assert r.exit_code == 0, r.output
    assert ("sgtool: note: 1 episode(s) have no shortest path (none was logged, or the target "
            "cannot be reached on the house's geometry): SPL leaves them out, SR counts them"
            ) in r.stderr
