"""``sgtool bench`` and ``run_bench`` on tiny settings: outputs, determinism (same bytes up to
wall-clock fields, whatever the worker count), option errors."""

from __future__ import annotations

import json
from typing import Any

import pytest
from click.testing import CliRunner
from support.foreign_house import QUERIES, write_cottage

from sgtool.analysis.bench import BenchConfig, BenchError, run_bench, run_benchmark
from sgtool.cli import cli
from sgtool.results import read_jsonl, results_digest

TINY = ["--houses", "2", "--episodes", "2", "--seeds", "2", "--planners", "random,greedy",
        "--no-progress"]


def _strip_wall(path) -> list[dict]:
    out = []
    for line in path.read_text().splitlines():
        d = json.loads(line)
        d.pop("wall")
        out.append(d)
    return out


def test_cli_writes_outputs_and_is_deterministic(tmp_path):
    runner = CliRunner()
    a = runner.invoke(cli, ["bench", *TINY, "-o", str(tmp_path / "a")])
    assert a.exit_code == 0, a.output
    assert "| random" in a.output and "| greedy" in a.output and "AUC-E budgets" in a.output
    assert "Unseen SR" in a.output
    files = sorted(p.name for p in (tmp_path / "a").iterdir())
    assert files == [".sgtool-output", "efficiency_distance.png", "efficiency_steps.png",
                     "episodes.jsonl", "per_house.jsonl", "per_house.md", "per_query.jsonl",
                     "per_query.md", "run.json", "run.md", "summary.json", "summary.md"]
    recs = read_jsonl(tmp_path / "a" / "episodes.jsonl")
    # 2 planners x 2 seeds x 2 houses x 2 episodes, ordered planner, house, episode, seed
    assert len(recs) == 16
    assert [(r.planner, r.house, r.episode, r.seed) for r in recs[:4]] == [
        ("random", "house-0", 0, 0), ("random", "house-0", 0, 1), ("random", "house-0", 1, 0),
        ("random", "house-0", 1, 1)]
    assert [r.key() for r in recs] == sorted(
        (r.key() for r in recs), key=lambda k: (["random", "greedy"].index(k[0]), k[2], k[3],
                                                k[1]))
    assert all(r.steps <= 50 and r.wall["decisions"] == r.steps for r in recs)
    summary = json.loads((tmp_path / "a" / "summary.json").read_text())
    assert summary["budgets"]["distance"]["max"] == 5000.0
    assert summary["budgets"]["steps"]["max"] == 50.0
    assert set(summary["planners"]) == {"random", "greedy"}
    assert summary["digest"] == results_digest(recs)
    # bootstrap intervals over the 2 houses and, without scout, greedy against the first
    # planner (the bytes of these lines are compared across worker counts below)
    iv = summary["intervals"]
    assert iv["bootstrap"]["resamples"] == 10000 and iv["cluster"] == "house"
    assert iv["planners"]["random"]["clusters"] == 2
    assert iv["planners"]["random"]["episodes"] == 8
    (pair,) = iv["paired"]
    assert (pair["planner"], pair["reference"], pair["episodes"]) == ("greedy", "random", 8)
    assert pair["wins"] + pair["losses"] + pair["ties"] == 2
    summary_md = (tmp_path / "a" / "summary.md").read_text()
    assert "SR and SPL with bootstrap intervals over houses" in summary_md
    assert "Paired comparisons on the same episodes" in summary_md
    assert "Paired comparisons on seen and on unseen queries" in summary_md
    assert len(iv["paired_seen"]) == len(iv["paired_unseen"]) == 1
    assert iv["paired_seen"][0]["episodes"] + iv["paired_unseen"][0]["episodes"] == 8
    assert "10000 resamples, seed 0" in summary_md and "| greedy  | random" in summary_md
    assert "Paired comparisons" in a.output
    # same command again, with two worker processes: same records up to wall-clock
    b = runner.invoke(cli, ["bench", *TINY, "-o", str(tmp_path / "b"), "--workers", "2"])
    assert b.exit_code == 0, b.output
    assert _strip_wall(tmp_path / "a" / "episodes.jsonl") == \
        _strip_wall(tmp_path / "b" / "episodes.jsonl")
    assert json.loads((tmp_path / "b" / "summary.json").read_text())["digest"] == \
        summary["digest"]
    # the summaries hold no wall-clock figure: the same bytes with one worker or two;
    # run.md/run.json hold the timing and the command
    for name in ("summary.md", "summary.json", "per_house.md", "per_query.jsonl"):
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes()
    assert "Decision time" not in (tmp_path / "a" / "summary.md").read_text()
    run_md = (tmp_path / "b" / "run.md").read_text()
    assert "Decision time" in run_md and "with 2 worker(s)" in run_md
    run = json.loads((tmp_path / "b" / "run.json").read_text())
    assert run["wall"]["workers"] == 2 and set(run["wall"]["decision_s"]) == {"random", "greedy"}


def _toy_priors(folder, queries) -> str:
    """A weights folder holding only a metadata.json with ``queries`` as its vocabulary."""
    folder.mkdir()
    (folder / "metadata.json").write_text(json.dumps({"training_queries": list(queries)}))
    return str(folder)


def test_cli_benches_a_hand_made_house_only(tmp_path):
    houses = tmp_path / "houses"
    write_cottage(houses)
    priors = _toy_priors(tmp_path / "toy", ["Mug", "pillow", "piano"])
    out = tmp_path / "o"
    r = CliRunner().invoke(cli, ["bench", "--house", str(houses), "--houses", "0",
                                 "--episodes", "5", "--seeds", "2", "--planners",
                                 "random,greedy", "--priors", priors, "--no-progress",
                                 "-o", str(out)])
    assert r.exit_code == 0, r.output
    recs = read_jsonl(out / "episodes.jsonl")
    assert len(recs) == 2 * 5 * 2 and {r.house for r in recs} == {"cottage"}
    assert sorted({r.query for r in recs}) == sorted(QUERIES)
    # seen = a training query of the toy priors (canonical text): mug and pillow
    assert {r.query for r in recs if r.seen} == {"mug", "pillow"}
    per_house = (out / "per_house.md").read_text().splitlines()
    assert len(per_house) == 3 + 1 and per_house[3].startswith("| cottage | 10 ")
    assert len((out / "per_house.jsonl").read_text().splitlines()) == 2  # 1 house x 2
    per_query = (out / "per_query.md").read_text().splitlines()
    assert [line.split("|")[1].strip() for line in per_query[3:]] == list(QUERIES)
    assert [line.split("|")[2].strip() for line in per_query[3:]] == \
        ["no", "yes", "yes", "no", "no"]
    assert len((out / "per_query.jsonl").read_text().splitlines()) == 10
    summary_md = (out / "summary.md").read_text()
    assert "quoted from SCOUT Table VII" in summary_md and "Per house" in summary_md
    assert "Per query" in summary_md and "3 training queries of " + priors in summary_md
    summary = json.loads((out / "summary.json").read_text())
    (random_row, greedy_row) = summary["seen_unseen"]
    # 2 seen queries x 2 seeds, 3 unseen x 2 seeds, per planner
    assert (random_row["seen_n"], random_row["seen_queries"]) == (4, 2)
    assert (greedy_row["unseen_n"], greedy_row["unseen_queries"]) == (6, 3)
    assert summary["houses"] == [{"id": "cottage", "source": str(houses / "cottage.json")}]
    assert summary["vocabulary"] == {"priors": priors, "training_queries": 3}


def test_house_files_next_to_generated_houses_sort_by_id(tmp_path):
    from sgtool.analysis.bench import planner_options_for

    path = write_cottage(tmp_path, "zz-cottage.json", id="Cottage")  # the spec's own id
    cfg = BenchConfig(planners=("greedy",), houses=1, house_seed=3, episodes=2, seeds=2,
                      house_files=(str(path),))
    res = run_benchmark(cfg)
    # plain string order of ids ("C" < "h"), then episode, then seed
    assert [(r.house, r.episode, r.seed) for r in res.results] == [
        ("Cottage", 0, 0), ("Cottage", 0, 1), ("Cottage", 1, 0), ("Cottage", 1, 1),
        ("house-3", 0, 0), ("house-3", 0, 1), ("house-3", 1, 0), ("house-3", 1, 1)]
    assert [h.id for h in res.houses] == ["house-3", "Cottage"]
    assert "1 generated houses (rooms 12-16) + houses from" in res.table
    # --priors reaches every planner of the learned priors, unless an option names other
    # weights; sbert uses none
    cfg = BenchConfig(priors_dir="/p", planner_options={"scout-noroom": {"weights_dir": "/q"}})
    assert planner_options_for(cfg, "scout") == {"weights_dir": "/p"}
    assert planner_options_for(cfg, "bayes-search") == {"weights_dir": "/p"}
    assert planner_options_for(cfg, "godhs") == planner_options_for(cfg, "esc") == \
        {"weights_dir": "/p"}
    assert planner_options_for(cfg, "scout-noroom") == {"weights_dir": "/q"}
    assert planner_options_for(cfg, "sbert") == {}
    # read off the registry: every planner with a weights_dir option, new ones included
    assert planner_options_for(cfg, "bayes-rooms") == {"weights_dir": "/p"}
    assert planner_options_for(cfg, "godhs-llm") == {"weights_dir": "/p"}
    assert planner_options_for(cfg, "moma-llm") == {}


def test_bad_house_files_stop_the_run_before_anything_is_written(tmp_path):
    good = write_cottage(tmp_path)
    bad = write_cottage(tmp_path, "bad.json", version="9.0")
    d = json.loads(good.read_text())
    d["objects"][0]["parent"] = "furn_piano"
    worse = write_cottage(tmp_path, "worse.json", objects=d["objects"])
    r = CliRunner().invoke(cli, ["bench", "--house", str(good), "--house", str(bad),
                                 "--house", str(worse), "--houses", "1", "--no-progress",
                                 "-o", str(tmp_path / "out")])
    assert r.exit_code == 2
    # one line per bad file, naming file and field (the wording is the house loader's)
    lines = r.output.removeprefix("sgtool: error: ").splitlines()
    assert len(lines) == 2
    assert lines[0].startswith(f"{bad}: version:") and "9.0" in lines[0]
    assert lines[1].startswith(f"{worse}: objects[0].parent:") and "furn_piano" in lines[1]
    assert str(good) not in r.output
    assert not (tmp_path / "out").exists()
    r = CliRunner().invoke(cli, ["bench", "--houses", "0", "--no-progress",
                                 "-o", str(tmp_path / "out")])
    assert r.exit_code == 2 and ">= 0 with --house" in r.output


def test_priors_without_a_vocabulary_are_refused(tmp_path):
    (tmp_path / "old").mkdir()
    (tmp_path / "old" / "metadata.json").write_text('{"metadata_version": 3}')
    r = CliRunner().invoke(cli, ["bench", *TINY, "--priors", str(tmp_path / "old"),
                                 "-o", str(tmp_path / "out")])
    assert r.exit_code == 2 and "training_queries: missing" in r.output
    assert not (tmp_path / "out").exists()


def test_seeds_change_starts_not_episodes():
    res = run_benchmark(BenchConfig(planners=("greedy",), houses=1, episodes=3, seeds=3))
    by_seed = {}
    for r in res.results:
        by_seed.setdefault(r.seed, []).append(r)
    assert [[r.query for r in rs] for rs in by_seed.values()] == \
        [[r.query for r in by_seed[0]]] * 3
    # greedy is deterministic: any difference between seeds comes from the start regions
    firsts = {tuple(s.target for s in r.trace[:2]) for r in res.results if r.episode == 0}
    assert len(firsts) >= 2


def test_run_bench_returns_the_tables():
    text = run_bench(planners=("random",), houses=1, episodes=2, seeds=1, progress=False)
    assert text.startswith("Symbolic benchmark")
    assert "| random" in text and "Seen vs unseen" in text
    # the result object a notebook prints: its settings and figures, not every episode's
    # trace and the tables (hundreds of kB at bench sizes)
    result = run_benchmark(BenchConfig(planners=("random",), houses=1, episodes=4, seeds=2))
    assert len(result.results) == 8 and len(repr(result)) < 2000
    # nor the planners' options, which may hold a secret (an API key given from Python)
    cfg = BenchConfig(planners=("moma-llm",), planner_options={"moma-llm": {
        "api_key": "sk-secret123"}})
    assert "sk-secret123" not in repr(cfg)


@pytest.mark.parametrize("args, message", [
    (["--planners", "random,oracle"], "unknown planner 'oracle'"),
    (["--rooms", "3-40"], "need 4 <= MIN <= MAX <= 30"),
    (["--rooms", "big"], "give N or MIN-MAX"),
    (["--seeds", "0"], "--seeds: must be >= 1"),
    (["--planners", "moma-llm", "--llm-replay", "/nonexistent/t.jsonl"],
     "no such transcript"),
    (["-O", "scout-delta"], "expected PLANNER.KEY=VALUE"),
    (["--planners", "random,greedy", "--reference", "scout"],
     "--reference: 'scout' is not one of --planners"),
    (["--planners", "random,greedy", "--reference", "random", "--all-pairs"],
     "--reference and --all-pairs: give one"),
    (["--planners", "random", "--llm-transcript", "t.jsonl"],
     "--llm-replay and --llm-transcript are for moma-llm: add it to --planners"),
])
def test_cli_option_errors(tmp_path, args, message):
    r = CliRunner().invoke(cli, ["bench", "-o", str(tmp_path), "--no-progress", *args])
    assert r.exit_code == 2
    assert message in r.output
    assert not (tmp_path / "episodes.jsonl").exists()


def test_all_pairs_compares_every_pair(tmp_path):
    r = CliRunner().invoke(cli, ["bench", "--houses", "2", "--episodes", "1", "--seeds", "1",
                                 "--planners", "random,greedy,scout", "--all-pairs",
                                 "--no-progress", "-o", str(tmp_path / "o")])
    assert r.exit_code == 0, r.output
    paired = json.loads((tmp_path / "o" / "summary.json").read_text())["intervals"]["paired"]
    assert [(p["planner"], p["reference"]) for p in paired] == [
        ("greedy", "random"), ("scout", "random"), ("scout", "greedy")]
    settings = json.loads((tmp_path / "o" / "summary.json").read_text())["settings"]
    assert "all_pairs" not in settings and "reference" not in settings  # no result changes


def test_config_check_rejects_duplicates():
    with pytest.raises(BenchError, match="named twice"):
        BenchConfig(planners=("random", "random")).check()
    from sgtool.planning.registry import make_planner

    with pytest.raises(BenchError, match="a TimedPlanner object, not a name; .* give yours "
                       "as module:Name"):
        BenchConfig(planners=(make_planner("random"), "scout")).check()  # type: ignore[arg-type]
    with pytest.raises(BenchError, match="planner_options: 'labplaner:Lab' is not one of the "
                       "planners run"):  # a typo, from Python: the CLI's -O notes it
        BenchConfig(planners=("labplanner:Lab",),
                    planner_options={"labplaner:Lab": {"k": 1}}).check()


class ScriptedLlm:
    """A stand-in chat model: reads MoMa-LLM's scene text and explores the first unexplored
    room, then the first room with an unexplored area, then opens the first closed thing."""

    model = "scripted"

    def complete(self, messages):
        import re

        from sgtool.llm.client import ChatResult

        user = messages[-1]["content"]
        m = re.search(r"Unexplored rooms seen through doors: ([^(,]+?) \(", user)
        cmd = "done()"
        if m:
            cmd = f"explore({m.group(1)})"
        else:
            for room, objs in re.findall(r"^- ([^:]+): \[(.*)\]$", user, re.M):
                if "unexplored area" in objs:
                    cmd = f"explore({room})"
                    break
                closed = re.search(r"closed ([^,\]]+)", objs)
                if closed:
                    cmd = f"go_to_and_open({room}, {closed.group(1)})"
                    break
        return ChatResult(text=f"Analysis: a\nReasoning: b\nCommand: {cmd}", model=self.model,
                          latency_s=0.0)


def test_moma_llm_transcript_then_replay(tmp_path):
    """moma-llm runs in the bench; its transcript replays to the same episodes offline."""
    transcript = tmp_path / "moma.jsonl"
    cfg = BenchConfig(planners=("moma-llm",), houses=1, episodes=2, seeds=1,
                      planner_options={"moma-llm": {"client": ScriptedLlm(),
                                                    "transcript": str(transcript)}})
    live = run_benchmark(cfg)
    assert transcript.stat().st_size > 0
    assert all(r.n_invalid == 0 for r in live.results)
    assert sum(r.steps for r in live.results) >= 4
    r = CliRunner().invoke(cli, ["bench", "--planners", "moma-llm", "--houses", "1",
                                 "--episodes", "2", "--seeds", "1", "--no-progress",
                                 "--llm-replay", str(transcript), "-o", str(tmp_path / "o")])
    assert r.exit_code == 0, r.output
    replayed = read_jsonl(tmp_path / "o" / "episodes.jsonl")
    assert results_digest(replayed) == live.digest
    assert "sgtool: note:" not in r.output
    # an endpoint's sampling setting changes no answer of a replay: a note says so
    r = CliRunner().invoke(cli, ["bench", "--planners", "moma-llm", "--houses", "1",
                                 "--episodes", "2", "--seeds", "1", "--no-progress",
                                 "--llm-replay", str(transcript), "-O",
                                 "moma-llm.temperature=0.7", "-o", str(tmp_path / "t")])
    assert r.exit_code == 0, r.output
    assert ("sgtool: note: -O moma-llm.temperature=0.7: --llm-replay serves the transcript's "
            "answers") in r.output
    assert results_digest(read_jsonl(tmp_path / "t" / "episodes.jsonl")) == live.digest
    # several transcripts (repeated, or a folder of them) serve as one
    lines = transcript.read_text().splitlines(keepends=True)
    parts = tmp_path / "parts"
    parts.mkdir()
    (parts / "a.jsonl").write_text("".join(lines[:len(lines) // 2]))
    (parts / "b.jsonl").write_text("".join(lines[len(lines) // 2:]))
    for given in ([str(parts / "a.jsonl"), str(parts / "b.jsonl")], [str(parts)]):
        out = tmp_path / f"parts{len(given)}"
        r = CliRunner().invoke(cli, ["bench", "--planners", "moma-llm", "--houses", "1",
                                     "--episodes", "2", "--seeds", "1", "--no-progress",
                                     *(x for g in given for x in ("--llm-replay", g)),
                                     "-o", str(out)])
        assert r.exit_code == 0, r.output
        assert results_digest(read_jsonl(out / "episodes.jsonl")) == live.digest
    # a run's transcript holds that run only (an earlier run's answers would be served
    # first by a replay of it), and cannot be the transcript it replays
    again = tmp_path / "again.jsonl"
    again.write_text('{"messages": [], "model": "an earlier run"}\n')
    r = CliRunner().invoke(cli, ["bench", "--planners", "moma-llm", "--houses", "1",
                                 "--episodes", "2", "--seeds", "1", "--no-progress",
                                 "--llm-replay", str(transcript), "--llm-transcript",
                                 str(again), "-o", str(tmp_path / "o2")])
    assert r.exit_code == 0, r.output
    assert "earlier run" not in again.read_text()
    assert len(again.read_text().splitlines()) == len(transcript.read_text().splitlines())
    r = CliRunner().invoke(cli, ["bench", "--planners", "moma-llm", "--houses", "1",
                                 "--episodes", "2", "--seeds", "1", "--no-progress",
                                 "--llm-replay", str(again), "--llm-transcript", str(again),
                                 "-o", str(tmp_path / "o3")])
    assert r.exit_code == 2 and "it is the --llm-replay transcript" in r.output
    assert again.read_text() and "earlier run" not in again.read_text()  # not emptied
    # the transcript of another house is no replay of this run: an error, nothing written
    r = CliRunner().invoke(cli, ["bench", "--planners", "moma-llm", "--houses", "1",
                                 "--house-seed", "5", "--episodes", "2", "--seeds", "1",
                                 "--no-progress", "--llm-replay", str(transcript), "-o",
                                 str(tmp_path / "other")])
    assert r.exit_code == 2, r.output
    assert "holds no (more) responses for this prompt" in r.output
    assert "(house-5, episode 0, seed 0)" in r.output
    assert not (tmp_path / "other" / "episodes.jsonl").exists()
    # a transcript of episode 0 only: the error names episode 1, where the replay ran out
    # (the retry of the failed task replayed from where the first attempt had stopped,
    # failed at episode 0 and named it)
    import json

    only0 = tmp_path / "only0.jsonl"
    first = json.loads(lines[0])["query"]
    only0.write_text("".join(x for x in lines if json.loads(x)["query"] == first))
    assert 0 < len(only0.read_text().splitlines()) < len(lines)
    r = CliRunner().invoke(cli, ["bench", "--planners", "moma-llm", "--houses", "1",
                                 "--episodes", "2", "--seeds", "1", "--no-progress",
                                 "--llm-replay", str(only0), "-o", str(tmp_path / "o4")])
    assert r.exit_code == 2 and "(house-0, episode 1, seed 0)" in r.output, r.output


@pytest.mark.parametrize("command", ["bench", "run-bench"])
def test_help_names_the_default_planners(command):
    """--help spells out the default of --planners: the bench's own list, in its order."""
    from sgtool.analysis.bench import DEFAULT_PLANNERS

    out = CliRunner().invoke(cli, [command, "--help"], terminal_width=400).output
    assert "Default: " + ", ".join(DEFAULT_PLANNERS) + " (" in " ".join(out.split())


def test_an_endpoint_that_never_answers_is_warned_about(tmp_path):
    """Every request fails (HTTP 500 from the start: a busy or broken server, no setup
    mistake the first request could name): an outage, the run stops in one line and writes
    no table (scored, every episode would be the planner giving up); an endpoint that
    answers, never with a command, is the planner's: the run completes and warns."""
    from support.semantics_fixtures import ChatServer

    def bench_against(srv: ChatServer, out: str) -> Any:
        return CliRunner().invoke(cli, ["bench", "--planners", "moma-llm", "--houses", "1",
                                        "--episodes", "1", "--seeds", "1", "--max-steps",
                                        "2", "--no-progress", "--llm-base-url", srv.base_url,
                                        "--llm-model", "m", "-o", str(tmp_path / out)])

    with ChatServer() as srv:  # HTTP 500 to every request
        r = bench_against(srv, "o")
    assert r.exit_code == 2, r.output
    assert "the LLM endpoint failed at all 5 attempts of a decision" in r.output
    assert len(r.output.strip().splitlines()) == 1
    assert not (tmp_path / "o" / "episodes.jsonl").exists()
    # an endpoint that answers every request, never with a command: warned about too
    with ChatServer(responder=lambda req: {"text": "<html>a web page</html>"}) as srv:
        r = bench_against(srv, "o3")
    assert r.exit_code == 0, r.output
    assert "sgtool: warning: moma-llm: none of its" in r.output
    assert "rejected, 0 faults); check the endpoint and model with `sgtool llm check`" \
        in r.output
    with ChatServer(responder=lambda req: {"status": 401}) as srv:  # a wrong key: stop
        r = CliRunner().invoke(cli, ["bench", "--planners", "moma-llm", "--houses", "1",
                                     "--episodes", "1", "--seeds", "1", "--no-progress",
                                     "--llm-base-url", srv.base_url, "--llm-model", "m",
                                     "-o", str(tmp_path / "o2")])
    assert r.exit_code == 2 and "refused the first request: HTTP 401" in r.output
    assert not (tmp_path / "o2" / "episodes.jsonl").exists()


def test_a_replay_folder_skips_logs_without_exchanges(tmp_path):
    """A --log-dir folder of a run that mixed moma-llm with other planners: the other
    planners' logs hold no LLM exchanges and are not transcripts; a folder with none is
    one line."""
    from support.logfixtures import synthetic_frame

    from sgtool.commands.llm_replay_options import replay_files
    from sgtool.errors import SgtoolError
    from sgtool.log import LogWriter

    (tmp_path / "scout").mkdir()
    k, _, depth, _, pose, _ = synthetic_frame(0)
    with LogWriter(tmp_path / "scout" / "seed0-ep0.mcap", seed=1) as w:
        w.write_frame(0, depth=depth, pose=pose, intrinsics=k)
    with pytest.raises(SgtoolError, match="no transcripts there"):
        replay_files([str(tmp_path)])
    (tmp_path / "moma.jsonl").write_text("")
    assert replay_files([str(tmp_path)]) == str(tmp_path / "moma.jsonl")


def test_episode_logs_record_the_planner_options(tmp_path):
    """A bench's episode logs keep the options each planner was built with (as closed-loop
    logs do), so `sgtool golden` asks the same planner again."""
    from sgtool.log import LogReader

    r = CliRunner().invoke(cli, ["bench", "--planners", "scout,greedy", "--houses", "1",
                                 "--episodes", "1", "--seeds", "1", "--max-steps", "3",
                                 "--no-progress", "-O", "scout.delta=0.3", "--log-dir",
                                 str(tmp_path / "logs"), "-o", str(tmp_path / "o")])
    assert r.exit_code == 0, r.output
    extras = {}
    for log in sorted((tmp_path / "logs").rglob("*.mcap")):
        with LogReader(log) as rd:
            (end,) = [e for _, e in rd.records("episode") if e["status"] != "started"]
        extras[end["planner"]] = end["extra"]
    assert extras["scout"]["planner_options"] == {"delta": 0.3}
    assert "planner_options" not in extras["greedy"]  # built with its defaults


def test_episode_logs_inside_the_output_folder(tmp_path):
    """`-o rl --log-dir rl/logs` (examples/README.md's command) on a new folder: the logs
    made rl non-empty while the run staged its outputs, so it took them for another run's
    and wrote rl.1; the log folder is the run's own now (under --force a user's file in
    it stays), and a log folder named as one of the outputs is refused."""
    args = ["bench", "--planners", "greedy", "--houses", "1", "--episodes", "2", "--seeds",
            "1", "--max-steps", "2", "--no-progress", "-o", str(tmp_path / "rl"),
            "--log-dir", str(tmp_path / "rl" / "logs")]
    r = CliRunner().invoke(cli, args)
    assert r.exit_code == 0, r.output
    assert not (tmp_path / "rl.1").exists()
    logs = sorted((tmp_path / "rl" / "logs").rglob("*.mcap"))
    assert len(logs) == 2 and (tmp_path / "rl" / "summary.md").is_file()
    assert CliRunner().invoke(cli, args).exit_code == 2  # not empty: --force to replace
    mine = tmp_path / "rl" / "logs" / "mine.txt"  # a user's file among the logs: kept
    mine.write_text("keep")
    r = CliRunner().invoke(cli, [*args, "--force"])
    assert r.exit_code == 0, r.output
    assert sorted((tmp_path / "rl" / "logs").rglob("*.mcap")) == logs
    assert mine.read_text() == "keep"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rl"]
    fresh = tmp_path / "new"  # (its log folder would have been taken for an output)
    r = CliRunner().invoke(cli, [*args[:-4], "-o", str(fresh), "--log-dir",
                                 str(fresh / "run.md")])
    assert r.exit_code == 2 and "run.md is a file the bench writes in" in r.output, r.output
    assert not fresh.exists()


def test_a_killed_runs_staging_folder_is_named(tmp_path):
    """A run killed outright leaves its hidden staging folder beside OUT; the next run
    that writes OUT names it (it never removes another run's folder)."""
    stale = tmp_path / ".o.k1ll3d00.partial"
    stale.mkdir()
    r = CliRunner().invoke(cli, ["bench", "--planners", "greedy", "--houses", "1",
                                 "--episodes", "1", "--seeds", "1", "--max-steps", "2",
                                 "--no-progress", "-o", str(tmp_path / "o")])
    assert r.exit_code == 0, r.output
    assert f"sgtool: note: {stale} is the unfinished output of a run that was killed" \
        in r.output
    assert stale.is_dir()
