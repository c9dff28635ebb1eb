"""The one output check (:func:`sgtool.commands.options.check_output`) on every writing
command that uses it: a target in a read-only folder, in a missing folder, an existing
file without --force and a folder are each refused in one line (exit 2) before any work,
and leave nothing behind (the existing file keeps its bytes; click's own check of
``dir_okay=False`` names a folder first)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from click.testing import CliRunner
from support.read_only import make_read_only

from sgtool.cli import cli
from sgtool.datasets import demo_house
from sgtool.house.io import save_house

GOLDEN_LOG = Path(__file__).resolve().parents[2] / "golden" / "house6-tour.mcap"

# command line with {out} for the output, {house} for a house spec and {inputs} for its
# folder (writable); the output's suffix
COMMANDS = {
    "record": (["record", "--frames", "1", "-o", "{out}"], ".mcap"),
    "run": (["run", "--planner", "random", "--frames", "1", "-o", "{out}"], ".mcap"),
    "eval": (["eval", str(GOLDEN_LOG), "-o", "{out}"], ".txt"),
    "doctor --recover": (["doctor", str(GOLDEN_LOG), "--recover", "{out}"], ".mcap"),
    "scenes generate": (["scenes", "generate", "-o", "{out}"], ".json"),
    "scenes show": (["scenes", "show", "{house}", "-o", "{out}"], ".png"),
    "view": (["view", str(GOLDEN_LOG), "-o", "{out}"], ".rrd"),
    "replay": (["replay", str(GOLDEN_LOG), "-o", "{out}", "--no-progress"], ".mcap"),
    "replay --rrd": (["replay", str(GOLDEN_LOG), "-o", "{inputs}/derived.mcap", "--rrd",
                      "{out}", "--no-progress"], ".rrd"),
    "import rgbd": (["import", "rgbd", "{inputs}", "-o", "{out}", "--quiet"], ".mcap"),
    "export bag": (["export", "bag", str(GOLDEN_LOG), "-o", "{out}"], ".bag"),
    "export foxglove-layout": (["export", "foxglove-layout", "-o", "{out}"], ".json"),
}


def _files(folder: Path) -> dict[str, bytes]:
    return {p.relative_to(folder).as_posix(): p.read_bytes()
            for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.mark.parametrize("target", ["read-only", "missing", "existing", "folder"])
@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_a_bad_target_is_one_line_and_leaves_nothing(name: str, target: str, tmp_path: Path,
                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    args, suffix = COMMANDS[name]
    house = tmp_path / "inputs" / "house.json"
    house.parent.mkdir()
    save_house(demo_house(), house)
    where = tmp_path / "where"
    where.mkdir()
    out = where / f"out{suffix}"
    if target == "missing":
        out = where / "no" / "such" / f"out{suffix}"
    elif target == "existing":
        out.write_bytes(b"the user's file")
    elif target == "folder":
        out.mkdir()
        (out / "keep").write_bytes(b"the user's file")
    before = _files(where)
    if target == "read-only":
        make_read_only(where, monkeypatch)
    line = [a.replace("{out}", str(out)).replace("{house}", str(house))
            .replace("{inputs}", str(house.parent)) for a in args]
    if target == "folder":
        line.append("--force")
    try:
        r = CliRunner().invoke(cli, line)
    finally:
        where.chmod(0o755)
    assert r.exit_code == 2, r.output
    assert len(r.output.strip().splitlines()) == 1 and "Traceback" not in r.output, r.output
    expected = {"read-only": "Permission denied", "missing": "does not exist",
                "existing": r"not overwriting it \(use --force\)",
                "folder": "is a (folder|directory)"}[target]
    assert re.search(expected, r.output), r.output
    assert _files(where) == before  # the existing file keeps its bytes; no temp file left
    assert sorted(p.relative_to(where).as_posix() for p in where.rglob("*")) == \
        sorted({*before, *(["out" + suffix] if target == "folder" else [])})


@pytest.mark.parametrize("option", ["--report", "--junit"])
def test_golden_check_reports_are_checked_before_any_replay(option: str,
                                                            tmp_path: Path) -> None:
    # a report goes into a missing folder: refused before the pin folder is even read
    # (that folder does not exist either; its own error would come after)
    out = tmp_path / "no" / "such" / "report.txt"
    r = CliRunner().invoke(cli, ["golden", "check", "--dir", str(tmp_path / "pins"), option,
                                 str(out)])
    assert r.exit_code == 2, r.output
    assert len(r.output.strip().splitlines()) == 1 and "Traceback" not in r.output
    assert f"{option} {out}: folder {out.parent} does not exist" in r.output
    assert list(tmp_path.iterdir()) == []  # nothing made: no pin folder, no report folder


@pytest.mark.parametrize("given", [["--llm-transcript", "{out}"],
                                   ["-O", "moma-llm.transcript={out}"]])
def test_a_run_s_transcript_is_not_its_output_log(tmp_path, given) -> None:
    """`run -o X.mcap` with the transcript at X.mcap (either spelling) is one line naming
    both, before anything is written (it was a false "X exists")."""
    out = tmp_path / "ep.mcap"
    answers = tmp_path / "answers.jsonl"
    answers.write_text("")
    r = CliRunner().invoke(cli, ["run", "--planner", "moma-llm", "--frames", "1",
                                 "--llm-replay", str(answers), "-o", str(out),
                                 *(g.format(out=out) for g in given)])
    assert r.exit_code == 2 and f"transcript {out}: it is the output log (-o)" in r.output, \
        r.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["answers.jsonl"]


@pytest.mark.parametrize("given", [
    ["--llm-replay", "{a}", "-O", "moma-llm.transcript={a}"],
    ["-O", "moma-llm.replay={a}", "--llm-transcript", "{a}"],
])
def test_a_run_s_transcript_is_not_the_transcript_it_replays(tmp_path, given) -> None:
    """The replayed transcript given again as the transcript (either through -O) would be
    emptied before it is read: one line, and the file keeps its bytes."""
    answers = tmp_path / "answers.jsonl"
    answers.write_text('{"messages": [], "model": "m"}\n')
    r = CliRunner().invoke(cli, ["run", "--planner", "moma-llm", "--frames", "1", "-o",
                                 str(tmp_path / "ep.mcap"),
                                 *(g.format(a=answers) for g in given)])
    assert r.exit_code == 2 and "it is the replay transcript" in r.output, r.output
    assert answers.read_text() == '{"messages": [], "model": "m"}\n'
    assert sorted(p.name for p in tmp_path.iterdir()) == ["answers.jsonl"]


def test_an_input_that_cannot_be_looked_at_is_no_file(tmp_path: Path,
                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    """An input that is no path (`--noise none`), looked at in a working folder this user
    cannot read, is no file: the output check goes on (it said "Permission denied: none")."""
    from sgtool.output_check import check_log_output

    real = Path.is_file

    def unreadable(self: Path) -> bool:
        if not self.is_absolute():
            raise PermissionError(13, "Permission denied", str(self))
        return real(self)

    monkeypatch.setattr(Path, "is_file", unreadable)
    out = tmp_path / "x.mcap"
    assert check_log_output(out, inputs=("none",)) == out
