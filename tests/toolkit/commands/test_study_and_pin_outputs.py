"""The folder outputs of ``study noise -o`` and ``golden pin --dir`` on the targets a user
gets wrong: a non-empty folder, a file, a folder under a file. Each is one line (exit 2)
before any work, and nothing is written."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

from sgtool.cli import cli

GOLDEN_LOG = Path(__file__).resolve().parents[2] / "golden" / "house10-start.mcap"


def _commands(target: Path) -> dict[str, list[str]]:
    return {"study": ["study", "noise", "--houses", "1", "--no-progress", "-o", str(target)],
            "pin": ["golden", "pin", str(GOLDEN_LOG), "--dir", str(target)]}


def _tree(folder: Path) -> dict[str, bytes | None]:
    """Every path under ``folder``: a file's bytes, None for a folder."""
    return {p.relative_to(folder).as_posix(): p.read_bytes() if p.is_file() else None
            for p in sorted(folder.rglob("*"))}


@pytest.mark.parametrize("command", ["study", "pin"])
@pytest.mark.parametrize("case", ["non-empty folder", "a file", "under a file"])
def test_a_wrong_target_is_one_line_and_nothing_is_written(tmp_path: Path, command: str,
                                                           case: str) -> None:
    (tmp_path / "full").mkdir()
    (tmp_path / "full" / "mine.txt").write_text("mine\n")
    (tmp_path / "afile").write_text("a file\n")
    target = {"non-empty folder": tmp_path / "full", "a file": tmp_path / "afile",
              "under a file": tmp_path / "afile" / "out"}[case]
    before = _tree(tmp_path)
    r = CliRunner().invoke(cli, _commands(target)[command])
    assert r.exit_code == 2, r.output
    lines = r.output.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in r.output, r.output
    assert str(target) in lines[0] or target.name in lines[0], lines[0]
    assert _tree(tmp_path) == before
