"""The scripts of ``tools/`` that tests/test_benchmarks.py does not run: a smoke run of each
with tiny arguments (exit 0, no figure checked), so none rots silently.

``tools/fuzz_cli.py`` drives the CLI in subprocesses over the mutants and crafted logs of
``tests/support`` (it needs ``tests/`` on ``PYTHONPATH``, as its usage says); here one
mutant and one crafted log go through ``sgtool info`` (and ``replay --score``).
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
FUZZ_CLI = REPO / "tools" / "fuzz_cli.py"
OFFLINE = {"HF_HUB_OFFLINE": "1", "TRANSFORMERS_OFFLINE": "1", "MPLBACKEND": "Agg"}


def _run(args: list[str], pythonpath: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, **OFFLINE, "PYTHONPATH": pythonpath}
    return subprocess.run([sys.executable, str(FUZZ_CLI), *args], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=600, check=False)


def test_fuzz_cli_runs_with_tiny_arguments(tmp_path: Path) -> None:
    proc = _run(["--mutants", "1", "--commands", "info", "--crafted", "depth-cdr",
                 "--ros2", str(tmp_path / "absent.mcap")], str(REPO / "tests"), tmp_path)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    assert "1 mutants of small.mcap" in proc.stdout
    assert "crafted logs" in proc.stdout and "0 failures" in proc.stdout


def test_fuzz_cli_without_the_support_modules_says_how_to_run_it(tmp_path: Path) -> None:
    proc = _run(["--mutants", "1"], "", tmp_path)
    assert proc.returncode == 1
    assert proc.stderr.strip().splitlines() == [
        "fuzz_cli: the test support modules are not importable: run it as "
        "PYTHONPATH=tests .venv/bin/python tools/fuzz_cli.py (from the repository root)"]


def test_every_mutation_of_tools_mutations_still_applies() -> None:
    """Each mutation's text is in its file exactly once (a refactor that moves it would
    make the tool report the mutation as not applied)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("tool_mutations", REPO / "tools" /
                                                  "mutations.py")
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    sys.modules["tool_mutations"] = mod  # (dataclasses look their module up)
    try:
        spec.loader.exec_module(mod)
        stale = [(m.parameter, m.label) for m in mod.MUTATIONS
                 if (REPO / "toolkit" / m.file).read_text().count(m.old) != 1]
    finally:
        del sys.modules["tool_mutations"]
    assert not stale


def test_room_types_compares_the_named_rooms_with_the_house(tmp_path: Path) -> None:
    """The golden tour's three rooms: its corridor (joining two rooms) is named by what it
    holds, the bathroom and the kitchen by theirs."""
    env = {**os.environ, **OFFLINE}
    proc = subprocess.run([sys.executable, str(REPO / "tools" / "room_types.py"),
                           str(REPO / "tests" / "golden" / "house6-tour.mcap"), "--rooms"],
                          cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600,
                          check=False)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert "room:0: true corridor, named living_room, narrow True, joins 2" in proc.stdout
    assert "rooms named right: 2 of 3" in proc.stdout
