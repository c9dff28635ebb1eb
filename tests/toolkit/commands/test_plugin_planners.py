"""Plug-in planners on the command line (``module:Name`` from PYTHONPATH): their rows sit
beside the built-ins' in every table and log of ``sgtool bench`` (also in worker
processes), ``eval -p`` asks them, failures are one line; ``-O PLANNER.KEY=VALUE`` on every
command (the bare form of ``run`` deprecated), ``--list-planners``, and the one LLM option
group."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from click.testing import CliRunner

from sgtool.cli import cli
from sgtool.commands.options import (
    LlmEndpoint,
    planner_options,
    run_planner_options,
    split_planner_key,
)
from sgtool.errors import SgtoolError
from sgtool.log import LogReader

PLUGIN = textwrap.dedent('''
    from sgtool.planning.planners import GreedyPlanner


    class MyPlanner(GreedyPlanner):
        """Greedy under its own name, with a knob that must arrive."""

        def __init__(self, k=1, weights: "tuple[float, float]" = (0.5, 0.5)):
            super().__init__()
            if k != 3:
                raise ValueError(f"k={k}, expected 3")
            self.name = "mine"


    def raises():
        raise RuntimeError("out of coffee")


    class Talker(GreedyPlanner):
        """Greedy that prints what it does, as research code does."""

        def decide(self, graph):
            print("deciding on", len(graph.objects), "objects")
            return super().decide(graph)


    def not_a_planner():
        return "greedy"


    def exits():
        raise SystemExit(3)


    def exits_loud():  # as a script's argument handling does
        raise SystemExit("usage: lab [-h] --k K\\nlab: error: --k is required")


    class Verbose(GreedyPlanner):
        """A planner whose exception tells a story."""

        def decide(self, graph):
            raise ValueError("line one\\nline two\\nline three")


    class Stumbles(GreedyPlanner):
        """A planner that breaks on its first decision."""

        def decide(self, graph):
            raise ZeroDivisionError("no rooms to divide by")


    class Flies(GreedyPlanner):
        """A planner with a skill of its own."""

        def decide(self, graph):
            from sgtool.planning.base import Action

            return Action("fly", "room:0")


    class NamesNothing(GreedyPlanner):
        """A planner whose target is no node of any graph."""

        def decide(self, graph):
            from sgtool.planning.base import Action

            return Action("navigate", "room:999")


    class CountsRooms(GreedyPlanner):
        """A planner whose target is a number."""

        def decide(self, graph):
            from sgtool.planning.base import Action

            return Action("navigate", 5)
''')
SMALL = ["--houses", "1", "--episodes", "2", "--seeds", "1", "--rooms", "4-5", "--preset",
         "default", "--no-progress"]


@pytest.fixture
def plugin_dir(tmp_path: Path) -> Path:
    d = tmp_path / "plugins"
    d.mkdir()
    (d / "mymod_cli.py").write_text(PLUGIN)
    (d / "script_cli.py").write_text("raise SystemExit(2)  # a script parsing its arguments\n")
    return d


def _rows(md: str, planner: str) -> list[str]:
    return [ln for ln in md.splitlines() if ln.startswith(f"| {planner} ")]


def test_bench_runs_a_plugin_beside_greedy_in_worker_processes(plugin_dir: Path,
                                                               tmp_path: Path) -> None:
    """The issue's check, as a user types it: PYTHONPATH=DIR sgtool bench --planners
    mymod:MyPlanner,greedy ... with two worker processes (each planner in its own task, so
    the plug-in is imported in a worker). The plug-in is greedy under another name, so its
    rows carry greedy's figures."""
    out, logs = tmp_path / "out", tmp_path / "logs"
    env = {**os.environ, "PYTHONPATH": str(plugin_dir), "HF_HUB_OFFLINE": "1",
           "TRANSFORMERS_OFFLINE": "1", "MPLBACKEND": "Agg"}
    cmd = [sys.executable, "-m", "sgtool.cli", "bench", "--planners",
           "mymod_cli:MyPlanner,greedy", *SMALL, "-w", "2", "-O", "mymod_cli:MyPlanner.k=3",
           "--log-dir", str(logs), "-o", str(out)]
    r = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    summary, paired = (out / "summary.md").read_text().split(
        "Paired comparisons on the same episodes")
    mine, greedy = _rows(summary, "mymod_cli:MyPlanner"), _rows(summary, "greedy")
    assert len(mine) == len(greedy) == 4  # the table, the side-by-side, seen/unseen, intervals
    for a, b in zip(mine, greedy, strict=True):
        assert a.split("|")[2:] == b.split("|")[2:]
    # greedy against the first planner, itself under another name: no difference, a tie
    (row, *_) = _rows(paired, "greedy")
    assert "mymod_cli:MyPlanner" in row and "+0.000 [-]" in row and "0/0/1" in row
    assert "mymod_cli:MyPlanner SR / SPL" in (out / "per_house.md").read_text()
    assert "mymod_cli:MyPlanner SR / SPL" in (out / "per_query.md").read_text()
    planners = json.loads((out / "summary.json").read_text())["planners"]
    assert set(planners) == {"mymod_cli:MyPlanner", "greedy"}
    assert planners["mymod_cli:MyPlanner"]["sr"] == planners["greedy"]["sr"]
    episodes = [json.loads(x) for x in (out / "episodes.jsonl").read_text().splitlines()]
    assert [e["planner"] for e in episodes] == ["mymod_cli:MyPlanner"] * 2 + ["greedy"] * 2
    assert sorted(p.name for p in (logs / "mymod_cli__MyPlanner" / "house-0").iterdir()) == [
        "seed0-ep0.mcap", "seed0-ep1.mcap"]


def test_eval_asks_a_plugin_and_reads_its_logs(plugin_dir: Path, tmp_path: Path,
                                               monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.syspath_prepend(str(plugin_dir))
    logs = tmp_path / "logs"
    r = CliRunner().invoke(cli, ["bench", "--planners", "mymod_cli:MyPlanner", *SMALL,
                                 "-O", "mymod_cli:MyPlanner.k=3", "--log-dir", str(logs),
                                 "-o", str(tmp_path / "out")])
    assert r.exit_code == 0, r.output
    files = sorted(str(p) for p in logs.rglob("*.mcap"))
    r = CliRunner().invoke(cli, ["eval", *files, "-p", "mymod_cli:MyPlanner,greedy",
                                 "-O", "mymod_cli:MyPlanner.k=3", "--json"])
    assert r.exit_code == 0, r.output
    doc = json.loads(r.output)
    assert list(doc["planners"]) == ["mymod_cli:MyPlanner"]  # the logs' own planner
    offline = doc["offline"]
    assert set(offline) == {"mymod_cli:MyPlanner", "greedy"}
    assert offline["mymod_cli:MyPlanner"]["same_action"] == 1.0  # it decides as logged
    assert offline["mymod_cli:MyPlanner"]["decisions"] == offline["greedy"]["decisions"] > 0
    # asked without -O: with its defaults (here refused, k=1), and a note says how it ran
    r = CliRunner().invoke(cli, ["eval", *files, "-p", "mymod_cli:MyPlanner"])
    assert ('sgtool: note: -p mymod_cli:MyPlanner asks it with its default options; its logs '
            'ran it with {"k": 3} (give them with -O mymod_cli:MyPlanner.KEY=VALUE to ask it '
            "as it ran)") in r.output, r.output
    # the folders themselves: --log-dir by its logs in PLANNER/HOUSE/, -o by its table
    by_logs = CliRunner().invoke(cli, ["eval", str(logs), "--json"])
    by_out = CliRunner().invoke(cli, ["eval", str(tmp_path / "out"), "--json"])
    assert by_logs.exit_code == by_out.exit_code == 0, by_logs.output + by_out.output
    for r in (by_logs, by_out):
        assert json.loads(r.output)["planners"] == doc["planners"]
    # a run folder and its own logs given together (as run-bench writes them): once each
    logs.rename(tmp_path / "out" / "logs")
    both = CliRunner().invoke(cli, ["eval", str(tmp_path / "out"), str(tmp_path / "out" /
                                                                        "logs"), "--json"])
    assert both.exit_code == 0, both.output
    assert "episode(s) were given twice" in both.stderr and "each is scored once" in both.stderr
    got, want = json.loads(both.stdout)["planners"], json.loads(by_out.output)["planners"]
    assert {p: v["episodes"] for p, v in got.items()} == \
        {p: v["episodes"] for p, v in want.items()} == {"mymod_cli:MyPlanner": 2}


@pytest.mark.parametrize(("planner", "message"), [
    ("nomod_cli:X", "planner 'nomod_cli:X': cannot import module 'nomod_cli'"),
    ("mymod_cli:raises", "planner 'mymod_cli:raises': raised RuntimeError: out of coffee"),
    ("mymod_cli:not_a_planner", "planner 'mymod_cli:not_a_planner': returned a str, not a "
     "Planner"),
    ("mymod_cli:MyPlanner", "planner 'mymod_cli:MyPlanner': raised ValueError: k=1, "
     "expected 3"),
    ("mymod_cli", "unknown planner 'mymod_cli'"),
    ("script_cli:P", "planner 'script_cli:P': cannot import module 'script_cli' (exited "
     "(SystemExit: 2))"),
    ("mymod_cli:exits", "planner 'mymod_cli:exits': exited (SystemExit: 3)"),
    ("mymod_cli:exits_loud", "planner 'mymod_cli:exits_loud': exited (SystemExit: usage: lab "
     "[-h] --k K ...)"),
])
def test_a_failing_plugin_is_one_line_before_any_episode(plugin_dir: Path, tmp_path: Path,
                                                         monkeypatch: pytest.MonkeyPatch,
                                                         planner: str, message: str) -> None:
    monkeypatch.syspath_prepend(str(plugin_dir))
    out = tmp_path / "out"
    r = CliRunner().invoke(cli, ["bench", "--planners", f"greedy,{planner}", *SMALL,
                                 "-o", str(out)])
    lines = [ln for ln in r.output.splitlines() if ln.strip()]
    assert r.exit_code == 2 and len(lines) == 1 and message in lines[0], r.output
    assert not out.exists()


def test_a_plugin_that_raises_in_decide_is_one_line(plugin_dir: Path, tmp_path: Path,
                                                    monkeypatch: pytest.MonkeyPatch) -> None:
    """What a user's planner raises while it runs is one line naming it and the method (a
    built-in's exception stays a traceback: a bug of ours), here in a one-process run."""
    monkeypatch.syspath_prepend(str(plugin_dir))
    from sgtool.planning.registry import make_planner

    r = CliRunner().invoke(cli, ["run", "-p", "mymod_cli:Stumbles", "--frames", "40",
                                 "--max-steps", "2", "-o", str(tmp_path / "r.mcap")])
    assert r.exit_code == 2, r.output
    assert r.output.strip() == ("sgtool: error: planner 'mymod_cli:Stumbles': decide() raised "
                                "ZeroDivisionError: no rooms to divide by")
    assert not (tmp_path / "r.mcap").exists()
    with pytest.raises(SgtoolError, match="'mymod_cli:Flies': decide\\(\\) returned an Action "
                       "with skill 'fly'; the skills are navigate, open, close, explore, done"):
        make_planner("mymod_cli:Flies").decide(None)
    greedy = make_planner("greedy")
    monkeypatch.setattr(greedy.inner, "decide", lambda graph: 1 / 0)
    with pytest.raises(ZeroDivisionError):
        greedy.decide(None)
    # untimed, the same: one line, and the contract still checked
    r = CliRunner().invoke(cli, ["run", "-p", "mymod_cli:Stumbles", "-O",
                                 "mymod_cli:Stumbles.timed=false", "--frames", "40",
                                 "--max-steps", "2", "-o", str(tmp_path / "u.mcap")])
    assert r.exit_code == 2 and "decide() raised ZeroDivisionError" in r.output, r.output
    with pytest.raises(SgtoolError, match="returned an Action with skill 'fly'"):
        make_planner("mymod_cli:Flies", timed=False).decide(None)
    with pytest.raises(SgtoolError) as err:  # a message of many lines: its first
        make_planner("mymod_cli:Verbose").decide(None)
    assert str(err.value) == ("planner 'mymod_cli:Verbose': decide() raised ValueError: "
                              "line one ...")


def test_sgtool_traceback_shows_where_a_plugin_raised(plugin_dir: Path, tmp_path: Path,
                                                    monkeypatch: pytest.MonkeyPatch) -> None:
    """SGTOOL_TRACEBACK=1: the plug-in's own traceback before the one line (no option
    showed it), in one process and from a worker process (once: the line naming the
    failed task held it again)."""
    monkeypatch.syspath_prepend(str(plugin_dir))
    monkeypatch.setenv("PYTHONPATH", str(plugin_dir))  # (the workers import it too)
    monkeypatch.setenv("SGTOOL_TRACEBACK", "1")
    frame = 'raise ZeroDivisionError("no rooms to divide by")'
    r = CliRunner().invoke(cli, ["run", "-p", "mymod_cli:Stumbles", "--frames", "40",
                                 "--max-steps", "2", "-o", str(tmp_path / "r.mcap")])
    assert r.exit_code == 2 and frame in r.output and "in decide" in r.output, r.output
    assert r.output.rstrip().splitlines()[-1] == (
        "sgtool: error: planner 'mymod_cli:Stumbles': decide() raised ZeroDivisionError: "
        "no rooms to divide by")
    r = CliRunner().invoke(cli, ["bench", "--planners", "mymod_cli:Stumbles", "--houses", "2",
                                 "--episodes", "1", "--seeds", "1", "--rooms", "4-4", "-w",
                                 "2", "--no-progress", "-o", str(tmp_path / "b")])
    assert r.exit_code == 2 and r.output.count(frame) == 1, r.output  # once, not per line
    assert r.output.rstrip().splitlines()[-1].endswith("raised ZeroDivisionError: no rooms "
                                                       "to divide by (after 2 attempts)")
    monkeypatch.setenv("SGTOOL_TRACEBACK", "0")  # off: the one line alone
    r = CliRunner().invoke(cli, ["run", "-p", "mymod_cli:Stumbles", "--frames", "40",
                                 "--max-steps", "2", "-o", str(tmp_path / "r.mcap")])
    assert r.exit_code == 2 and r.output.count("\n") == 1, r.output


def test_a_report_of_a_stored_run_needs_no_plugin(plugin_dir: Path, tmp_path: Path,
                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    """run-bench --report-only re-tables logs run already: on a machine where the lab's
    plug-in does not import it failed ("cannot import module"), and then refused its list
    option (typed in the logs, text on the command line); it writes the same summary.json
    now."""
    import sys

    monkeypatch.syspath_prepend(str(plugin_dir))
    out = tmp_path / "rb"
    r = CliRunner().invoke(cli, [
        "run-bench", "--planners", "mymod_cli:MyPlanner,greedy", "-O",
        "mymod_cli:MyPlanner.k=3", "-O", "mymod_cli:MyPlanner.weights=0.2,0.8", "--houses",
        "1", "--rooms", "4-4", "--episodes", "1",
        "--frames", "40", "--max-steps", "2", "-w", "1", "--no-progress", "-o", str(out)])
    assert r.exit_code == 0, r.output
    before = (out / "summary.json").read_bytes()
    monkeypatch.setattr(sys, "path", [p for p in sys.path if p != str(plugin_dir)])
    monkeypatch.delitem(sys.modules, "mymod_cli")
    r = CliRunner().invoke(cli, ["run-bench", "-o", str(out), "--report-only"])
    assert r.exit_code == 0, r.output
    assert (out / "summary.json").read_bytes() == before


def test_a_plugin_that_raises_in_a_run_bench_leaves_no_folders(
        plugin_dir: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """run-bench stops on a plug-in that raises with one line naming the episode, and leaves
    no folder of logs never written: a fresh output folder is gone, a resumed one holds what
    it held."""
    monkeypatch.syspath_prepend(str(plugin_dir))
    out = tmp_path / "rb"

    def run_bench(planners: str) -> list[str]:
        r = CliRunner().invoke(cli, [
            "run-bench", "--planners", planners, "--houses", "1", "--rooms", "4-4",
            "--episodes", "1", "--frames", "40", "--max-steps", "2", "-w", "1",
            "--no-progress", "-o", str(out)])
        assert r.exit_code == (2 if "Stumbles" in planners else 0), r.output
        if "Stumbles" in planners:
            assert "decide() raised ZeroDivisionError" in r.output, r.output
            assert "(house-0, episode 0; the logs written are kept" in r.output, r.output
        return sorted(p.relative_to(out).as_posix() for p in out.rglob("*.mcap"))

    assert run_bench("mymod_cli:Stumbles") == [] and not out.exists()
    logs = run_bench("greedy")
    assert logs == ["logs/none/greedy/house-0/ep-000.mcap"]
    assert run_bench("greedy,mymod_cli:Stumbles") == logs
    assert sorted(p.name for p in (out / "logs" / "none").iterdir()) == ["greedy"]


def test_log_paths_of_a_plugin_are_safe_and_fixed(monkeypatch: pytest.MonkeyPatch) -> None:
    from sgtool.analysis.bench import BenchError, check_planner_list
    from sgtool.analysis.closed_loop_bench import log_path
    from sgtool.planning import plugins

    # an installed package registering the name a__B (entry-point names are free text)
    monkeypatch.setattr(plugins, "entry_points", lambda: {"a__B": object()})
    assert log_path(Path("r"), "none", "pkg.mod:Cls", "house-0", 2) == Path(
        "r/none/pkg.mod__Cls/house-0/ep-002.mcap")
    with pytest.raises(BenchError, match="would share the log folder 'a__B'"):
        check_planner_list(["a:B", "a__B"])
    with pytest.raises(BenchError, match="a plug-in is named module:Name"):
        check_planner_list(["greedy", "a:"])


@pytest.mark.parametrize(("key", "planners", "expect"), [
    ("scout.delta", (), ("scout", "delta")),
    ("moma-llm.base_url", ("moma-llm",), ("moma-llm", "base_url")),
    ("mymod:MyPlanner.k", (), ("mymod:MyPlanner", "k")),
    ("pkg.mod:Cls.k", (), ("pkg.mod:Cls", "k")),
    ("pkg.mod:Cls.Inner.k", ("pkg.mod:Cls.Inner",), ("pkg.mod:Cls.Inner", "k")),
    ("my.ep.name.k", ("my.ep.name",), ("my.ep.name", "k")),  # an entry point with dots
    ("delta", (), ("", "")),
])
def test_the_planner_part_may_hold_colons_and_dots(key: str, planners: tuple[str, ...],
                                                   expect: tuple[str, str]) -> None:
    assert split_planner_key(key, planners) == expect


def test_option_values_are_typed_by_the_planners_fields(plugin_dir: Path,
                                                        monkeypatch: pytest.MonkeyPatch
                                                        ) -> None:
    monkeypatch.syspath_prepend(str(plugin_dir))
    got = planner_options(("scout.delta=0.2", "bayes-search.blend=no", "moma-llm.model=7b",
                           "mymod_cli:MyPlanner.k=3", "mymod_cli:MyPlanner.tag=a.b"),
                          ("scout", "bayes-search", "moma-llm", "mymod_cli:MyPlanner"))
    assert got == {"scout": {"delta": 0.2}, "bayes-search": {"blend": False},
                   "moma-llm": {"model": "7b"}, "mymod_cli:MyPlanner": {"k": 3, "tag": "a.b"}}
    with pytest.raises(SgtoolError, match="expected PLANNER.KEY=VALUE"):
        planner_options(("scout.del ta=1",), ("scout",))


def test_run_takes_planner_dot_key_and_still_the_bare_form(
        capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    assert run_planner_options(("scout.delta=0.2",), "scout") == {"delta": 0.2}
    assert capsys.readouterr().err == ""
    assert run_planner_options(("delta=0.2",), "scout") == {"delta": 0.2}
    assert "write -O scout.delta=VALUE (the bare KEY=VALUE form is deprecated)" in \
        capsys.readouterr().err
    r = CliRunner().invoke(cli, ["run", "--planner", "scout", "-O", "scout.delta=-1",
                                 "-o", str(tmp_path / "never.mcap")])
    assert r.exit_code == 2 and "option delta=-1: must be >= 0" in r.output
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("command", [["bench"], ["run-bench"], ["run"], ["eval"]])
def test_list_planners(command: list[str]) -> None:
    r = CliRunner().invoke(cli, [*command, "--list-planners"])
    assert r.exit_code == 0, r.output
    assert r.output.startswith("Planners (-O PLANNER.KEY=VALUE")
    assert "\nbayes-search: " in r.output and "    horizon (int, default 3): " in r.output
    assert "Plug-ins registered in the entry-point group sgtool.planners" in r.output
    # a misspelt name before it is said, as without --list-planners
    opt = "--planner" if command in (["run"], ["eval"]) else "--planners"
    r = CliRunner().invoke(cli, [*command, opt, "scoutt", "--list-planners"])
    assert r.exit_code == 2 and "unknown planner 'scoutt'" in r.output


@pytest.mark.parametrize("command", [["bench"], ["run"], ["run-bench"], ["eval"], ["replay"],
                                     ["distill"], ["llm", "check"]])
def test_one_llm_option_group_everywhere(command: list[str]) -> None:
    r = CliRunner().invoke(cli, [*command, "--help"])
    assert r.exit_code == 0, r.output
    for flag in ("--llm-base-url", "--llm-model", "--llm-api-key", "--llm-timeout"):
        assert flag in r.output, (command, flag)
    assert "[env SGTOOL_LLM_BASE_URL]" in " ".join(r.output.split())


def test_the_llm_group_fills_llm_planners_and_o_wins(capsys: pytest.CaptureFixture[str]
                                                     ) -> None:
    opts = {"moma-llm": {"base_url": "http://given/v1"}}
    LlmEndpoint("http://group/v1", "m", "k", 5.0).fill(opts, ["moma-llm", "godhs-llm",
                                                              "scout"])
    assert opts == {"moma-llm": {"base_url": "http://given/v1", "model": "m", "api_key": "k",
                                 "timeout_s": 5.0},
                    "godhs-llm": {"base_url": "http://group/v1", "model": "m", "api_key": "k",
                                  "timeout_s": 5.0}}
    LlmEndpoint(model="m").fill(opts, ["scout"])
    assert "no LLM planner is run" in capsys.readouterr().err


def test_bench_endpoint_comes_from_the_group_unless_o_names_one(tmp_path: Path) -> None:
    """An unreachable endpoint's one-line error names the URL the planner was given."""
    base = ["bench", "--planners", "moma-llm", *SMALL, "--episodes", "1", "--llm-timeout",
            "2", "-o", str(tmp_path / "o")]
    r = CliRunner().invoke(cli, [*base, "--llm-base-url", "http://127.0.0.1:9/v1"])
    assert r.exit_code == 2 and "cannot reach the LLM endpoint http://127.0.0.1:9/v1" \
        in r.output, r.output
    r = CliRunner().invoke(cli, [*base, "--llm-base-url", "http://127.0.0.1:9/v1",
                                 "-O", "moma-llm.base_url=http://127.0.0.1:7/v1"])
    assert r.exit_code == 2 and "cannot reach the LLM endpoint http://127.0.0.1:7/v1" \
        in r.output, r.output


def test_an_api_key_of_the_group_is_never_written(tmp_path: Path,
                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    key = "sk-group-SECRET-123456"
    out = tmp_path / "out"
    args = ["bench", "--planners", "random", *SMALL, "--llm-api-key", key, "-o", str(out)]
    monkeypatch.setattr(sys, "argv", ["sgtool", *args])  # the command line in run.md
    r = CliRunner().invoke(cli, args)
    assert r.exit_code == 0, r.output
    assert key not in r.output
    for p in out.iterdir():
        if p.suffix in (".md", ".json", ".jsonl"):
            assert key not in p.read_text(), p.name
    assert "--llm-api-key '<redacted>'" in (out / "run.md").read_text()


@pytest.mark.parametrize("command", [["bench", "--planners"], ["run", "-p"], ["eval", "-p"]])
def test_list_planners_describes_a_plugin_named_with_it(
        plugin_dir: Path, monkeypatch: pytest.MonkeyPatch, command: list[str]) -> None:
    monkeypatch.syspath_prepend(str(plugin_dir))
    said = ("mymod_cli:MyPlanner: a plug-in without an Options dataclass (its -O values are "
            "converted to its parameters' annotated types, else passed as int, float, "
            "true/false or text)")
    r = CliRunner().invoke(cli, [*command, "mymod_cli:MyPlanner", "--list-planners"])
    assert r.exit_code == 0 and said in r.output, r.output
    # its parameter without an annotation is listed too, as -O passes it
    assert "    k (int, float, true/false or text, default 1)" in r.output, r.output
    # named after it, or as --opt=VALUE: the same
    flag = command[-1]
    for words in (["--list-planners", flag, "mymod_cli:MyPlanner"],
                  ["--list-planners", f"{flag}=mymod_cli:MyPlanner"]):
        r = CliRunner().invoke(cli, [*command[:-1], *words])
        assert r.exit_code == 0 and said in r.output, (words, r.output)
    # one that cannot be imported: listed with why, and the exit says so
    r = CliRunner().invoke(cli, [*command, "nomod_cli:X", "--list-planners"])
    assert r.exit_code == 2 and "nomod_cli:X: planner 'nomod_cli:X': cannot import" in r.output
    assert r.output.splitlines()[-1].startswith(
        "sgtool: error: planner 'nomod_cli:X': cannot import"), r.output


def test_an_untimed_plugin_keeps_its_name_in_the_closed_loop(plugin_dir: Path, tmp_path: Path,
                                                             monkeypatch: pytest.MonkeyPatch
                                                             ) -> None:
    """`-O P.timed=false` on a plug-in: the log names the planner as given (not the name
    its class sets), and the log, which records timed among the options, pins."""
    monkeypatch.syspath_prepend(str(plugin_dir))
    log = tmp_path / "u.mcap"
    r = CliRunner().invoke(cli, ["run", "-p", "mymod_cli:MyPlanner", "-O",
                                 "mymod_cli:MyPlanner.k=3", "-O",
                                 "mymod_cli:MyPlanner.timed=false", "--frames", "40",
                                 "--max-steps", "2", "--quiet", "-o", str(log)])
    assert r.exit_code == 0, r.output
    with LogReader(log) as rd:
        acts = [a for _, a in rd.records("action")]
        (ep,) = [e for _, e in rd.records("episode") if e["status"] != "started"]
    assert ep["planner"] == "mymod_cli:MyPlanner"
    assert {a["planner"] for a in acts if a.get("planner")} == {"mymod_cli:MyPlanner"}
    r = CliRunner().invoke(cli, ["golden", "pin", str(log), "--dir", str(tmp_path / "g"),
                                 "--max-frames", "20"])
    assert r.exit_code == 0, r.output


def test_invalid_actions_are_told_and_a_target_must_be_a_node_id(
        plugin_dir: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A plug-in naming nodes that are not there runs (an LLM planner may), but the bench
    says so (with its tables, on stdout) and in summary.md; a target that is no text is one
    line; a user's planner object given to run_one or run_closed_loop is held to the same
    contract, sgtool's own is not (its bug keeps its traceback)."""
    monkeypatch.syspath_prepend(str(plugin_dir))
    out = tmp_path / "out"
    r = CliRunner().invoke(cli, ["bench", "--planners", "greedy,mymod_cli:NamesNothing",
                                 *SMALL, "--max-steps", "5", "-o", str(out)])
    assert r.exit_code == 0, r.output
    note = ("mymod_cli:NamesNothing: 10 of its 10 actions (in 2 of 2 episodes) were invalid, "
            "a target that is no node of the scene graph it was given or a skill the node "
            "does not offer, and spent a step each (n_invalid in episodes.jsonl)")
    assert f"sgtool: note: {note}" in r.stdout
    assert note in (out / "summary.md").read_text()
    assert "note: greedy:" not in r.stdout  # greedy's actions were all valid
    from sgtool.planning.registry import make_planner

    with pytest.raises(SgtoolError, match="'mymod_cli:CountsRooms': decide\\(\\) returned an "
                       "Action whose target is 5 \\(int\\); a target is a node id"):
        make_planner("mymod_cli:CountsRooms").decide(None)
    import mymod_cli

    import sgtool
    from sgtool.datasets.generator import generate_house

    house = generate_house(0, rooms=(4, 5))
    query = house.objects[0].category
    with pytest.raises(SgtoolError, match="skill 'fly'"):
        sgtool.run_one(house, mymod_cli.Flies(), query)
    with pytest.raises(SgtoolError, match="target is 5"):
        sgtool.run_one(house, mymod_cli.CountsRooms(), query)

    class Nameless:  # runs under "planner", as before the check
        def reset(self, query: str, seed: int = 0) -> None: ...
        def decide(self, graph: object) -> sgtool.Action:
            return sgtool.Action("done")
        def feedback(self, fb: object) -> None: ...

    assert sgtool.run_one(house, Nameless(), query).planner == "planner"
    with pytest.raises(SgtoolError, match=r"^planner: a object is not a Planner \(it lacks "
                       r"reset, decide, feedback\)$"):
        sgtool.run_one(house, object(), query)  # type: ignore[arg-type]
    greedy = make_planner("greedy", timed=False)  # sgtool's own: its bug keeps its traceback
    monkeypatch.setattr(greedy, "decide", lambda graph: {}["no such key"])
    with pytest.raises(KeyError):
        sgtool.run_one(house, greedy, query)
    # the closed loop holds a planner object to the same contract, and leaves no log
    _, ep = sgtool.pick_episode(house)
    out = tmp_path / "cl.mcap"
    with pytest.raises(SgtoolError, match=r"^planner 'greedy': decide\(\) raised "
                       r"ZeroDivisionError: no rooms to divide by$"):
        sgtool.run_closed_loop(house, ep, mymod_cli.Stumbles(), out, sgtool.ClosedLoopOptions(
            max_steps=2, frames=40, camera=sgtool.CameraConfig(width=64, height=48)))
    assert not list(tmp_path.glob("cl.mcap*"))


def test_eval_json_stays_json_when_a_plug_in_prints(plugin_dir: Path, tmp_path: Path) -> None:
    """`sgtool eval LOGS -p mod:Talker --json | jq`: what the plug-in prints goes to stderr
    (it broke the JSON on stdout), in the process and in its workers."""
    env = {**os.environ, "PYTHONPATH": str(plugin_dir), "HF_HUB_OFFLINE": "1",
           "TRANSFORMERS_OFFLINE": "1", "MPLBACKEND": "Agg"}
    logs = tmp_path / "logs"
    bench = [sys.executable, "-m", "sgtool.cli", "bench", "--planners", "greedy", *SMALL,
             "--log-dir", str(logs), "-o", str(tmp_path / "out")]
    assert subprocess.run(bench, env=env, capture_output=True, timeout=600).returncode == 0
    for workers in ("1", "2"):
        r = subprocess.run([sys.executable, "-m", "sgtool.cli", "eval", str(logs), "-p",
                            "mymod_cli:Talker", "--json", "-w", workers], env=env,
                           capture_output=True, text=True, timeout=600)
        assert r.returncode == 0, r.stderr
        assert "mymod_cli:Talker" in json.loads(r.stdout)["offline"]
        assert "deciding on" in r.stderr
