"""The ``sgtool`` command's usage errors: a bad option value, a missing argument, an output
path that is a folder, an unknown option or command are ONE line on stderr naming the
command (not click's usage / hint / error lines), with exit code 2, through the console
script's ``main`` and through click's own standalone mode; --help is unchanged."""

from __future__ import annotations

import json

import click
import pytest
from click.testing import CliRunner

from sgtool.cli import Interrupted, Killed, LazyGroup, cli, main
from sgtool.errors import SgtoolError, Terminated

CASES = [
    (["import", "rgbd", "{d}", "-o", "{d}/x.mcap", "--every", "abc"],
     "sgtool import rgbd: error: Invalid value for '--every': 'abc' is not a valid integer. "
     "(see --help)"),
    (["import", "rgbd"], "sgtool import rgbd: error: Missing argument 'FOLDER'. (see --help)"),
    (["import", "rgbd", "{d}", "-o", "{d}"],
     "sgtool import rgbd: error: Invalid value for '-o' / '--output': File '{d}' is a "
     "directory. (see --help)"),
    (["import", "rgbd", "{d}", "--no-such-flag"],
     "sgtool import rgbd: error: No such option '--no-such-flag'. (see --help)"),
    (["no-such-command"], "sgtool: error: No such command 'no-such-command'. (see --help)"),
    (["--no-such-flag"], "sgtool: error: No such option '--no-such-flag'. (see --help)"),
    (["import", "no-such-kind"], "sgtool import: error: No such command 'no-such-kind'. "
     "(see --help)"),
]


@pytest.mark.parametrize("args, line", CASES)
def test_usage_errors_are_one_line_through_main(tmp_path, capsys, args, line):
    d = str(tmp_path)
    with pytest.raises(SystemExit) as e:
        main([a.format(d=d) for a in args])
    assert e.value.code == 2
    out, err = capsys.readouterr()
    assert out == "" and err == line.format(d=d) + "\n"
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("args, line", CASES[:3])
def test_usage_errors_are_one_line_in_standalone_mode(tmp_path, args, line):
    d = str(tmp_path)
    r = CliRunner().invoke(cli, [a.format(d=d) for a in args], prog_name="sgtool")
    assert r.exit_code == 2 and r.output == line.format(d=d) + "\n"


def test_help_is_unchanged(capsys):
    main(["import", "rgbd", "--help"])  # exit code 0: main returns
    out = capsys.readouterr().out
    assert out.startswith("Usage: sgtool import rgbd [OPTIONS] FOLDER\n") and "--every" in out
    r = CliRunner().invoke(cli, ["import"], prog_name="sgtool")  # a group alone: its help
    assert r.output.startswith("Usage: sgtool import [OPTIONS] COMMAND [ARGS]...")
    assert "Commands:" in r.output and "error" not in r.output


class _OneCommand(LazyGroup):
    """A group whose one command ``go`` raises ``exc``."""

    def __init__(self, exc: BaseException) -> None:
        super().__init__(name="sgtool")
        self.exc = exc

    def list_commands(self, ctx: click.Context) -> list[str]:
        return ["go"]

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command:
        exc = self.exc

        @click.command("go")
        def go() -> None:
            raise exc

        return go


@pytest.mark.parametrize("exc, kind, code", [(KeyboardInterrupt(), Interrupted, 130),
                                             (Terminated(), Killed, 143)])
def test_an_interrupt_is_one_line_with_its_exit_code(capsys, exc, kind, code):
    with pytest.raises(Interrupted) as e:
        _OneCommand(exc).main(["go"], standalone_mode=False)
    assert type(e.value) is kind and e.value.exit_code == code
    assert Interrupted.exit_code == 130  # a kill does not change the Ctrl-C code
    e.value.show()
    assert capsys.readouterr().err == "sgtool: interrupted; no output was left half-written\n"


class _OwnError(SgtoolError):
    """A plug-in's error whose ``__init__`` does not call SgtoolError's."""

    def __init__(self, what: str) -> None:
        self.what = what

    def __str__(self) -> str:
        return f"{self.what} is not set"


@pytest.mark.parametrize("exc, err", [
    (_OwnError("map_file"), "sgtool: error: map_file is not set\n"),
    (SgtoolError("no such topic", details="a table\nof topics"),
     "a table\nof topics\nsgtool: error: no such topic\n")])
def test_an_error_is_one_line_after_its_details(capsys, exc, err):
    """An error's ``details`` come before its one line; a subclass that sets none (its own
    ``__init__``) is one line, not an AttributeError."""
    with pytest.raises(click.ClickException) as e:
        _OneCommand(exc).main(["go"], standalone_mode=False)
    e.value.show()
    assert capsys.readouterr().err == err


def test_a_reader_that_stops_early_is_no_error(tmp_path):
    """`sgtool scenes episodes HOUSE | head -1`: the closed pipe ends the command with exit
    code 0 and no error on stderr (click's own handling exits 1)."""
    import subprocess
    import sys

    from support.datasets_fixtures import two_rooms

    house = tmp_path / "h.json"
    house.write_text(json.dumps(two_rooms()))
    code = "import sys; from sgtool.cli import main; main(sys.argv[1:])"
    p = subprocess.Popen([sys.executable, "-c", code, "scenes", "episodes", str(house)],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    assert p.stdout is not None and p.stderr is not None
    p.stdout.readline()
    p.stdout.close()
    assert p.wait(timeout=60) == 0
    err = p.stderr.read().decode()
    assert "rror" not in err and "Traceback" not in err and "Exception" not in err, err


def test_a_verdict_is_never_zero_when_the_reader_stops_early():
    """`sgtool diff A B | head -1` on logs that differ: the closed pipe may cut the report,
    but the exit code is never 0 ("the same"): 1, or 141 (128 + SIGPIPE) when the pipe
    closed first."""
    import subprocess
    import sys

    from support.paths import GOLDEN

    code = "import sys; from sgtool.cli import main; main(sys.argv[1:])"
    p = subprocess.Popen([sys.executable, "-c", code, "diff", str(GOLDEN / "house6-tour.mcap"),
                          str(GOLDEN / "house10-start.mcap")],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    assert p.stdout is not None and p.stderr is not None
    p.stdout.close()
    assert p.wait(timeout=120) in (1, 141)
    assert "Traceback" not in p.stderr.read().decode()


def test_nohup_keeps_a_command_running_through_a_hang_up(tmp_path):
    """SIGHUP stops a command as a kill does, unless it is ignored (`nohup sgtool ...`):
    then the command keeps it ignored and finishes."""
    import signal
    import subprocess
    import sys
    import time
    from pathlib import Path

    log = Path(__file__).resolve().parents[1] / "golden" / "house6-tour.mcap"
    code = ("import signal, sys; signal.signal(signal.SIGHUP, signal.SIG_IGN); "
            "from sgtool.cli import main; main(sys.argv[1:])")
    out = tmp_path / "d.mcap"
    p = subprocess.Popen([sys.executable, "-c", code, "replay", str(log), "-o", str(out)],
                         stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 60
        while not list(tmp_path.glob("d.mcap*")) and p.poll() is None:
            assert time.monotonic() < deadline
            time.sleep(0.05)
        p.send_signal(signal.SIGHUP)
        assert p.wait(timeout=120) == 0, p.stderr.read() if p.stderr else ""
    finally:
        p.kill()
    assert out.is_file() and not list(tmp_path.glob("*.partial"))


@pytest.mark.parametrize("command", [["record"], ["run"], ["bench"], ["run-bench"],
                                     ["study", "noise"], ["scenes", "generate"]])
def test_rooms_help_states_the_range_the_generator_takes(command: list[str]) -> None:
    """--rooms 2-4 was refused with "need 4 <= MIN <= MAX <= 30", which no help said."""
    from sgtool.datasets.generator import MAX_ROOMS

    r = CliRunner().invoke(cli, [*command, "--help"], terminal_width=200)
    assert r.exit_code == 0, r.output
    text = " ".join(r.output.split())
    assert f"4..{MAX_ROOMS}" in text, text
