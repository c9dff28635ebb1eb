"""The log fuzz campaign of tests/toolkit/log/test_fuzz.py, through the CLI (subprocesses).

Usage (from the repository root, by hand; ``tests/`` on the path for the test support
modules the campaign is built from)::

    PYTHONPATH=tests .venv/bin/python tools/fuzz_cli.py [--mutants 50] [--seed 14]
        [--ros2 PATH] [--commands info,doctor,recover,replay,view,eval]
        [--crafted NAME,...] [--no-crafted] [--timeout 120]

Seeded bit flips, record-head flips, overwrites and truncations of a small recorded sgtool
log (written here with support.logfixtures.write_log) and of a real ROS 2 MCAP (default:
the Nav2 recording in ../shared/data/logs/rosbag2-mcap/, skipped when absent), then the
crafted logs of tests/support/crafted_logs.py (wrong schemas and encodings, bad house
attachments, /tf cycles, instance tables out of range; ``--crafted`` picks some by name),
also through `replay --score`. Every log goes through `sgtool info`, `doctor`,
`doctor --recover`, `replay`, `view -o` and `eval`; prints a table logs x commands ->
clean (exit 0) / error (exit != 0, ending in one `sgtool: error:` line, no traceback) /
traceback / hang (no exit within --timeout seconds) / wrong (doctor says complete but a
reader sees changes, recovery gives back fewer messages than the chunks the mutant left
whole, or a crafted log read where it must be refused or the other way round), then the
first failures. Exits 1 when there is any failure. tests/test_tools.py runs it with tiny
arguments.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from collections import Counter
from pathlib import Path

try:
    from support.crafted_logs import CRAFTS
    from support.log_fuzz import campaign as prepare
    from support.log_fuzz import (
        crafted_expectation,
        crafted_logs,
        crafted_report_problem,
        message_count,
    )
    from support.logfixtures import write_log
except ModuleNotFoundError as e:  # run without tests/ on the path
    if e.name != "support":
        raise
    sys.exit("fuzz_cli: the test support modules are not importable: run it as "
             "PYTHONPATH=tests .venv/bin/python tools/fuzz_cli.py (from the repository root)")

REPO = Path(__file__).resolve().parents[1]
SGTOOL = str(Path(sys.executable).parent / "sgtool")
OUTCOMES = ("clean", "error", "traceback", "hang", "wrong")
COMMANDS = ("info", "doctor", "recover", "replay", "view", "eval")  # of argv, besides score
TIMEOUT_S = 120.0


def argv(cmd: str, log: Path, work: Path) -> list[str]:
    replay = ["replay", str(log), "--every", "100", "--voxel-size", "0.2", "--no-progress"]
    return {
        "info": ["info", str(log)],
        "doctor": ["doctor", str(log), "--json"],
        "recover": ["doctor", str(log), "--recover", str(work / "rec.mcap"), "--force",
                    "--json"],
        "replay": replay,
        "score": [*replay, "--score"],
        "view": ["view", str(log), "-o", str(work / "view.rrd"), "--force"],
        "eval": ["eval", str(log)],
    }[cmd]


def run(cmd: str, log: Path, work: Path) -> tuple[str, str]:
    """(outcome, output) of one command."""
    try:
        p = subprocess.run([SGTOOL, *argv(cmd, log, work)], capture_output=True, text=True,
                           timeout=TIMEOUT_S, check=False)
    except subprocess.TimeoutExpired:
        return "hang", f"no exit within {TIMEOUT_S:g} s"
    out = p.stdout + p.stderr
    if "Traceback (most recent call last)" in out:
        return "traceback", out.strip().splitlines()[-1]
    if p.returncode == 0 or (cmd in ("doctor", "recover") and p.returncode == 1):
        return "clean", p.stdout
    lines = p.stderr.strip().splitlines()  # notes (sgtool: note: ...) may come first
    if lines and lines[-1].startswith("sgtool: error:"):
        return "error", lines[-1]
    return "traceback", out[-300:]


def campaign(src: Path, n: int, seed: int, commands: list[str], work: Path
             ) -> tuple[Counter, list[str]]:
    import json

    c = prepare(src, n, seed)
    table: Counter[tuple[str, str]] = Counter()
    failures: list[str] = []
    for m in c.mutants:
        log = work / "mutant.mcap"
        log.write_bytes(m.data)
        for cmd in commands:
            outcome, text = run(cmd, log, work)
            if cmd in ("doctor", "recover") and outcome == "clean":
                d = json.loads(text)
                if d["status"] == "complete" and c.complete_is_wrong(log):
                    outcome, text = "wrong", "complete, but a reader sees changes"
                if cmd == "recover" and c.too_few(m, d["readable_messages"]):
                    outcome, text = "wrong", (f"recovered {d['readable_messages']}, fewer "
                                              "than the whole chunks hold")
            _tally(table, failures, cmd, outcome, f"{src.name} {m.name} {cmd}: {text}")
        print(".", end="", flush=True, file=sys.stderr)
    print(file=sys.stderr)
    return table, failures


def _tally(table: Counter, failures: list[str], cmd: str, outcome: str, line: str) -> None:
    """Count ``outcome`` of ``cmd``; a traceback, hang or wrong result adds ``line`` to
    the failures."""
    table[cmd, outcome] += 1
    if outcome in ("traceback", "hang", "wrong"):
        failures.append(line)


def crafted_campaign(commands: list[str], work: Path, names: set[str]
                     ) -> tuple[Counter, list[str]]:
    """The crafted logs called ``names`` through ``commands`` and ``replay --score``,
    judged as tests/toolkit/log/test_fuzz.py judges them in-process."""
    import json

    table: Counter[tuple[str, str]] = Counter()
    failures: list[str] = []
    for name, log in crafted_logs(work / "crafted"):
        if name not in names:
            continue
        want = crafted_expectation(name)
        for cmd in [*commands, "score"]:
            outcome, text = run(cmd, log, work)
            if outcome in ("clean", "error") and cmd in want and outcome != want[cmd]:
                outcome, text = "wrong", f"{outcome}, expected {want[cmd]}: {text[:200]}"
            elif cmd in ("doctor", "recover") and outcome == "clean":
                d = json.loads(text)
                wrong = crafted_report_problem(
                    name, cmd, d["status"], d.get("problems", []), d["readable_messages"],
                    d.get("dropped_messages", 0), message_count(log))
                if wrong:
                    outcome, text = "wrong", wrong
            _tally(table, failures, cmd, outcome, f"crafted {name} {cmd}: {text}")
        print(".", end="", flush=True, file=sys.stderr)
    print(file=sys.stderr)
    return table, failures


def print_table(title: str, table: Counter, commands: list[str]) -> None:
    print(f"\n{title}")
    print(f"{'':10}" + "".join(f"{c:>10}" for c in commands))
    for o in OUTCOMES:
        print(f"{o:10}" + "".join(f"{table[c, o]:>10}" for c in commands))


def main() -> None:
    global TIMEOUT_S
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--mutants", type=int, default=50)
    ap.add_argument("--seed", type=int, default=14)
    ap.add_argument("--ros2", type=Path, default=REPO.parent / "shared" / "data" / "logs"
                    / "rosbag2-mcap" / "evo_nav2_turtlebot.mcap")
    ap.add_argument("--commands", default=",".join(COMMANDS))
    ap.add_argument("--crafted", default=",".join(CRAFTS),
                    help="the crafted logs to run, by name [default: all]")
    ap.add_argument("--no-crafted", action="store_true", help="skip the crafted logs")
    ap.add_argument("--timeout", type=float, default=TIMEOUT_S,
                    help="seconds a command may run before it counts as a hang")
    a = ap.parse_args()
    TIMEOUT_S = a.timeout
    commands = [c for c in a.commands.split(",") if c]
    crafted = {c for c in a.crafted.split(",") if c}
    for given, known, what in ((commands, COMMANDS, "--commands"), (crafted, CRAFTS, "--crafted")):
        unknown = sorted(set(given) - set(known))
        if unknown:
            ap.error(f"{what}: unknown {', '.join(unknown)} (known: {', '.join(known)})")
    failures: list[str] = []
    totals: Counter[str] = Counter()
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        sources = [write_log(work / "small.mcap", n=12, flush_interval_ns=300_000_000)]
        if a.ros2.exists():
            sources.append(a.ros2)
        else:
            print(f"{a.ros2} is absent: the ROS 2 campaign is skipped")
        for src in sources:
            table, f = campaign(src, a.mutants, a.seed, commands, work)
            print_table(f"{a.mutants} mutants of {src.name}", table, commands)
            failures += f
            for (_, o), n in table.items():
                totals[o] += n
        if not a.no_crafted:
            (work / "crafted").mkdir()
            table, f = crafted_campaign(commands, work, crafted)
            print_table("crafted logs (tests/support/crafted_logs.py)", table,
                        [*commands, "score"])
            failures += f
            for (_, o), n in table.items():
                totals[o] += n
    print("\ntotal: " + ", ".join(f"{o} {totals[o]}" for o in OUTCOMES))
    print(f"{len(failures)} failures")
    for line in failures[:30]:
        print("  " + line)
    if failures:
        sys.exit(1)


if __name__ == "__main__":
    main()
