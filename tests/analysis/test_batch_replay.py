"""``sgtool replay LOG... --out-dir DIR`` on the local executor: outputs byte-identical to
one-by-one replays, complete outputs kept unless --force, a log that fails is reported while
the others are written, one-line refusals; ``sgtool eval`` over a folder and a glob."""

from __future__ import annotations

import json

import pytest
from click.testing import CliRunner
from support.logfixtures import write_log

from sgtool.analysis.batch_inputs import expand_inputs
from sgtool.analysis.batch_replay import ReplayJob, is_complete, plan_jobs, replay_many
from sgtool.analysis.executor import LocalExecutor
from sgtool.cli import cli
from sgtool.errors import SgtoolError
from sgtool.replayers.derived_log import ReplayOptions, replay

OPTS = ReplayOptions(every=4, voxel_size=0.1)


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    d = tmp_path_factory.mktemp("logs")
    return [write_log(d / f"run{n}.mcap", n=n) for n in (6, 8, 10)]


def test_batch_equals_one_by_one_then_keeps_complete_outputs(logs, tmp_path):
    one = tmp_path / "one"
    one.mkdir()
    for p in logs:
        replay(p, one / p.name, OPTS)
    out = tmp_path / "out"
    out.mkdir()
    jobs = plan_jobs(logs, out, OPTS)
    report = replay_many(jobs, LocalExecutor(2))
    assert [r.status for r in report.logs] == ["replayed"] * 3
    assert [r.frames for r in report.logs] == [6, 8, 10]
    for p in logs:
        assert (out / p.name).read_bytes() == (one / p.name).read_bytes()
    assert sorted(f.name for f in out.iterdir()) == ["run10.mcap", "run6.mcap", "run8.mcap"]
    # again: every output is complete with these options, nothing runs
    again = replay_many(jobs, LocalExecutor(1))
    assert [r.status for r in again.logs] == ["skipped"] * 3
    assert again.lines()[-1].startswith("0 replayed, 3 skipped, 0 failed in ")
    # other options, or a damaged output, are not complete
    assert not is_complete(ReplayJob(str(logs[0]), str(out / "run6.mcap"),
                                     ReplayOptions(every=5, voxel_size=0.1)))
    (out / "run8.mcap").write_bytes((out / "run8.mcap").read_bytes()[:-100])
    assert not is_complete(jobs[1])
    third = replay_many(jobs, LocalExecutor(1))
    assert [r.status for r in third.logs] == ["skipped", "replayed", "skipped"]
    assert (out / "run8.mcap").read_bytes() == (one / "run8.mcap").read_bytes()


def test_a_log_that_fails_is_reported_and_the_others_are_written(logs, tmp_path):
    bad = tmp_path / "in" / "broken.mcap"
    bad.parent.mkdir()
    bad.write_bytes(logs[0].read_bytes()[:3000])  # cut inside the first chunk
    out = tmp_path / "out"
    r = CliRunner().invoke(cli, ["replay", str(logs[0]), str(bad), str(logs[1]), "--out-dir",
                                 str(out), "--every", "4", "--voxel-size", "0.1",
                                 "--no-progress"])
    assert r.exit_code == 2
    lines = r.stdout.splitlines()
    assert lines[0] == f"wrote {out / 'run6.mcap'}: 6 frames, 2 refreshes"
    assert lines[1].startswith(f"failed {bad}: ") and "ends without the MCAP" in lines[1]
    assert f"{bad}: {bad}" not in lines[1]  # named once, before its error
    assert lines[2] == f"wrote {out / 'run8.mcap'}: 8 frames, 2 refreshes"
    assert lines[3].startswith("2 replayed, 0 skipped, 1 failed in ")
    assert r.stderr.startswith(f"sgtool: error: 1 of 3 log(s) failed to replay (after a "
                               f"retry); the first: {bad}: ")
    assert f"{bad}: {bad}" not in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1
    assert sorted(f.name for f in out.iterdir()) == [".sgtool-output", "run6.mcap",
                                                     "run8.mcap"]


def test_folder_and_glob_inputs_and_json(logs, tmp_path):
    folder = logs[0].parent
    assert expand_inputs([folder], (".mcap",)) == sorted(logs)
    assert expand_inputs([str(folder / "run1*.mcap"), logs[2]], (".mcap",)) == [logs[2]]
    out = tmp_path / "o"
    r = CliRunner().invoke(cli, ["replay", str(folder), "--out-dir", str(out), "--json",
                                 "--every", "4", "--voxel-size", "0.1", "--no-progress"])
    assert r.exit_code == 0, r.output
    doc = json.loads(r.stdout)
    assert [(d["status"], d["frames"]) for d in doc["logs"]] == \
        [("replayed", 10), ("replayed", 6), ("replayed", 8)]  # name order: run10 < run6


@pytest.mark.parametrize("args, message", [
    (["A", "B"], "several logs (or a folder) replay into a folder: give --out-dir DIR"),
    (["A", "--out-dir", "O", "-o", "x.mcap"], "-o takes one log; leave it out with --out-dir"),
    (["A", "--out-dir", "O", "--score"], "--score takes one log; leave it out with --out-dir"),
    (["A", "-w", "2"], "--executor, --workers and --ray-address run many logs: give "
                       "--out-dir DIR"),
    (["A", "nothing*.mcap", "--out-dir", "O"], "nothing*.mcap: the pattern matches no file"),
    (["A", "missing.mcap", "--out-dir", "O"], "missing.mcap: no such file"),
    (["A", "sub/A", "--out-dir", "O"], "and sub/A.mcap would both be replayed into O/A.mcap"),
])
def test_one_line_refusals(logs, tmp_path, monkeypatch, args, message):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "sub").mkdir()
    for name in ("A.mcap", "B.mcap", "sub/A.mcap"):
        (tmp_path / name).write_bytes(logs[0].read_bytes())
    args = [a + ".mcap" if a in ("A", "B", "sub/A") else a for a in args]
    r = CliRunner().invoke(cli, ["replay", *args, "--no-progress"])
    assert r.exit_code == 2, r.output
    assert len(r.stderr.strip().splitlines()) == 1 and message in r.stderr
    assert not (tmp_path / "O").exists() or not any((tmp_path / "O").iterdir())


def test_outputs_must_not_overwrite_inputs(logs):
    with pytest.raises(SgtoolError, match="the outputs must not overwrite the inputs"):
        plan_jobs([logs[0]], logs[0].parent, OPTS)


def test_eval_over_a_folder_equals_eval_of_each_file(tmp_path):
    from sgtool.analysis.batch_eval import load_many
    from sgtool.analysis.offline import load_results
    from sgtool.results import EpisodeResult, write_jsonl

    def rec(i: int, planner: str) -> EpisodeResult:
        return EpisodeResult(planner=planner, house="h", episode=i, seed=0, query="mug",
                             success=i % 2 == 0, steps=3 + i, travelled_m=4.0 + i,
                             shortest_m=2.0)

    a = write_jsonl([rec(0, "greedy"), rec(1, "greedy")], tmp_path / "a.jsonl")
    b = write_jsonl([rec(2, "random")], tmp_path / "b.jsonl")
    results, logged, notes, failed = load_many([a, b], LocalExecutor(2))
    assert results == load_results([a, b])[0] and [r.planner for r in results] == \
        ["greedy", "greedy", "random"]
    assert logged == [] and notes == [] and failed == []


def test_replay_logs_from_python(logs, tmp_path):
    """``sgtool.replay_logs``: a folder of logs into a folder, as the command writes it;
    a log that fails is in the report, not raised; wrong arguments are one line."""
    import sgtool

    src = tmp_path / "in"
    src.mkdir()
    for p in logs[:2]:
        (src / p.name).write_bytes(p.read_bytes())
    (src / "cut.mcap").write_bytes(logs[2].read_bytes()[:3000])
    out = tmp_path / "out"
    report = sgtool.replay_logs(src, out, OPTS, executor=sgtool.make_executor("local", 2))
    assert [(r.status, r.frames) for r in report.logs] == [
        ("failed", 0), ("replayed", 6), ("replayed", 8)]  # cut, run6, run8: sorted
    assert report.logs[0].error
    cli_out = tmp_path / "cli"
    r = CliRunner().invoke(cli, ["replay", str(src / "run6.mcap"), str(src / "run8.mcap"),
                                 "--out-dir", str(cli_out), "--every", "4",
                                 "--voxel-size", "0.1"])
    assert r.exit_code == 0, r.output
    for name in ("run6.mcap", "run8.mcap"):
        assert (out / name).read_bytes() == (cli_out / name).read_bytes()
    assert not (out / "cut.mcap").exists()
    again = sgtool.replay_logs([src / "run6.mcap"], out, OPTS)  # complete: kept
    assert [r.status for r in again.logs] == ["skipped"]
    for kwargs, message in (({"logs": None}, "logs: a log's path, a folder or a list"),
                            ({"logs": []}, "logs: a log's path"),
                            ({"logs": ""}, "logs: a log's path"),
                            ({"out_dir": None}, "out_dir: a folder's path, got None"),
                            ({"out_dir": ""}, "out_dir: a folder's path, got ''"),
                            ({"options": "every=4"}, "options: a ReplayOptions, got str"),
                            ({"options": {}}, "options: a ReplayOptions, got dict"),
                            ({"force": "no"}, "force: True or False, got str"),
                            ({"executor": 2}, "executor: one of sgtool.make_executor"),
                            ({"executor": type("E", (), {"run": 1})()}, "executor: one of")):
        args = {"logs": src, "out_dir": tmp_path / "x", **kwargs}
        with pytest.raises(SgtoolError, match=message):
            sgtool.replay_logs(args.pop("logs"), args.pop("out_dir"), **args)
    assert not (tmp_path / "x").exists()


def test_an_output_of_another_input_with_that_name_is_replayed_again(tmp_path):
    """A log recorded again under its name is not the input its derived log was made from:
    the derived log records its input's sha256, and a folder replay compares it."""
    src = write_log(tmp_path / "run.mcap", n=6)
    out = tmp_path / "out"
    out.mkdir()
    jobs = plan_jobs([src], out, OPTS)
    assert [r.status for r in replay_many(jobs, LocalExecutor(1)).logs] == ["replayed"]
    assert [r.status for r in replay_many(jobs, LocalExecutor(1)).logs] == ["skipped"]
    write_log(src, n=8)  # the same name, another recording
    assert not is_complete(jobs[0])
    assert [r.status for r in replay_many(jobs, LocalExecutor(1)).logs] == ["replayed"]
    fresh = tmp_path / "fresh.mcap"
    replay(src, fresh, OPTS)
    assert (out / "run.mcap").read_bytes() == fresh.read_bytes()


def test_a_double_star_pattern_matches_any_depth(tmp_path):
    """A quoted ``**`` pattern finds the logs of every subfolder (run-bench writes
    logs/NOISE/PLANNER/HOUSE/), as a shell with globstar does, instead of one level."""
    for sub in ("a", "a/b/c", "a/b"):
        (tmp_path / sub).mkdir(parents=True, exist_ok=True)
        (tmp_path / sub / "x.mcap").write_bytes(b"")
    got = expand_inputs([str(tmp_path / "**" / "*.mcap")], (".mcap",))
    assert got == sorted(tmp_path / s / "x.mcap" for s in ("a", "a/b", "a/b/c"))
    assert expand_inputs([str(tmp_path / "a" / "b" / "**" / "*.mcap")], (".mcap",)) == \
        sorted([tmp_path / "a/b/c/x.mcap", tmp_path / "a/b/x.mcap"])
