"""The log fuzz campaign of tests/toolkit/log/test_fuzz.py, through the CLI (subprocesses).

    .venv/bin/python benchmarks/fuzz_cli.py [--mutants 50] [--seed 14] [--ros2 PATH]
                                            [--commands info,doctor,recover,replay,view,eval]

Seeded bit flips, record-head flips, overwrites and truncations of a small recorded sgtool
log (written here with support.logfixtures.write_log) and of a real ROS 2 MCAP (default:
the Nav2 recording in ../shared/data/logs/rosbag2-mcap/, skipped when absent). Every
mutant goes through `sgtool info`, `doctor`, `doctor --recover`, `replay`, `view -o` and
`eval`; prints a table mutants x commands -> clean (exit 0) / error (exit != 0, one
line, no traceback) / traceback / wrong (doctor says complete but a reader sees changes,
or recovery gives back fewer messages than the chunks the mutant left whole), then the
first failures. Run by hand: about 1 s per mutant and command on 2 cores.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from collections import Counter
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests"))  # the test support modules
from support.log_fuzz import campaign as prepare  # noqa: E402
from support.logfixtures import write_log  # noqa: E402

SGTOOL = str(Path(sys.executable).parent / "sgtool")
OUTCOMES = ("clean", "error", "traceback", "wrong")


def argv(cmd: str, log: Path, work: Path) -> list[str]:
    return {
        "info": ["info", str(log)],
        "doctor": ["doctor", str(log), "--json"],
        "recover": ["doctor", str(log), "--recover", str(work / "rec.mcap"), "--force",
                    "--json"],
        "replay": ["replay", str(log), "--every", "100", "--voxel-size", "0.2",
                   "--no-progress"],
        "view": ["view", str(log), "-o", str(work / "view.rrd")],
        "eval": ["eval", str(log)],
    }[cmd]


def run(cmd: str, log: Path, work: Path) -> tuple[str, str]:
    """(outcome, output) of one command."""
    p = subprocess.run([SGTOOL, *argv(cmd, log, work)], capture_output=True, text=True,
                       timeout=600, check=False)
    out = p.stdout + p.stderr
    if "Traceback (most recent call last)" in out:
        return "traceback", out.strip().splitlines()[-1]
    if p.returncode == 0 or (cmd in ("doctor", "recover") and p.returncode == 1):
        return "clean", p.stdout
    lines = p.stderr.strip().splitlines()
    return ("error", lines[0]) if len(lines) == 1 else ("traceback", out[-300:])


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
            table[cmd, outcome] += 1
            if outcome in ("traceback", "wrong"):
                failures.append(f"{src.name} {m.name} {cmd}: {text}")
        print(".", end="", flush=True, file=sys.stderr)
    print(file=sys.stderr)
    return table, failures


def print_table(title: str, table: Counter, commands: list[str]) -> None:
    print(f"\n{title}")
    print(f"{'':10}" + "".join(f"{c:>10}" for c in commands))
    for o in OUTCOMES:
        print(f"{o:10}" + "".join(f"{table[c, o]:>10}" for c in commands))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--mutants", type=int, default=50)
    ap.add_argument("--seed", type=int, default=14)
    ap.add_argument("--ros2", type=Path, default=REPO.parent / "shared" / "data" / "logs"
                    / "rosbag2-mcap" / "evo_nav2_turtlebot.mcap")
    ap.add_argument("--commands", default="info,doctor,recover,replay,view,eval")
    a = ap.parse_args()
    commands = [c for c in a.commands.split(",") if c]
    failures: list[str] = []
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
    print(f"\n{len(failures)} failures")
    for line in failures[:30]:
        print("  " + line)


if __name__ == "__main__":
    main()
