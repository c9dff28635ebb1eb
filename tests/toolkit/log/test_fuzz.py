"""Fuzzing the log readers (issue 14): seeded bit flips, overwrites and truncations of a
recorded sgtool log and of a real ROS 2 MCAP, run in-process through the functions behind
``sgtool info`` (summarize), ``doctor`` (scan, recover), ``replay`` and ``eval``
(load_results). Each call succeeds or raises one SgtoolError; a "complete" verdict is
given only to a mutant a reader sees exactly as the original (tests/support/log_fuzz.py
says why header and metadata values are not part of that view); recovery gives back at
least the messages of the chunks the mutant left whole. Crafted logs (valid MCAP files
with wrong content: schemas, encodings, house attachments, /tf trees, instance tables) go
through the same functions, replay also with the house scoring, frames as ``view`` reads
them: each is read or refused in one line as tests/support/log_fuzz.py expects.
``tools/fuzz_cli.py`` runs both campaigns through the CLI.
"""

from __future__ import annotations

import traceback
from collections import Counter
from pathlib import Path
from typing import Any

import pytest
from support.log_fuzz import campaign as prepare
from support.log_fuzz import (
    crafted_expectation,
    crafted_logs,
    crafted_report_problem,
    message_count,
)
from support.logfixtures import write_log

from sgtool.errors import SgtoolError
from sgtool.log.recover import recover, scan

N_MUTANTS = 200
SEED = 14


@pytest.fixture(scope="module")
def sgtool_log(tmp_path_factory) -> Path:
    """12 frames, a chunk every 0.3 s of log time: five chunks, every channel type."""
    path = tmp_path_factory.mktemp("fuzz") / "small.mcap"
    return write_log(path, n=12, flush_interval_ns=300_000_000)


def _run(fn: Any) -> tuple[str, Any]:
    try:
        return "clean", fn()
    except SgtoolError as e:
        return "error", str(e)
    except Exception as e:  # noqa: BLE001 - what the fuzz test is looking for
        return "crash", f"{type(e).__name__}: {e}\n{traceback.format_exc(limit=-3)}"


def _commands(path: Path, out: Path) -> dict[str, tuple[str, Any]]:
    from sgtool.analysis.offline import load_results
    from sgtool.log.inspect import summarize
    from sgtool.replayers.derived_log import ReplayOptions, replay

    return {
        "info": _run(lambda: summarize(path)),
        "doctor": _run(lambda: scan(path)),
        "recover": _run(lambda: recover(path, out, overwrite=True)),
        # one refresh, coarse voxels: every frame is read and assembled, quickly
        "replay": _run(lambda: replay(path, None, ReplayOptions(every=100, voxel_size=0.2))),
        "eval": _run(lambda: load_results([path])),
    }


def campaign(src: Path, work: Path, n: int, seed: int) -> tuple[Counter, list[str]]:
    """(command, outcome) counts and the failures of ``n`` mutants of ``src``."""
    c = prepare(src, n, seed)
    table: Counter[tuple[str, str]] = Counter()
    failures: list[str] = []
    for m in c.mutants:
        path, out = work / "mutant.mcap", work / "recovered.mcap"
        path.write_bytes(m.data)
        res = _commands(path, out)
        verdict = res["doctor"][1].status if res["doctor"][0] == "clean" else None
        table["verdict", str(verdict)] += 1
        for cmd, (outcome, value) in res.items():
            if outcome == "crash":
                failures.append(f"{m.name} {cmd}: {value}")
            if cmd == "doctor" and verdict == "complete" and c.complete_is_wrong(path):
                outcome = "wrong"
                failures.append(f"{m.name}: doctor says complete, the reader sees changes")
            if cmd == "recover" and outcome == "clean" and (
                    c.too_few(m, value.readable_messages) or value.status != verdict):
                outcome = "wrong"
                failures.append(f"{m.name}: recovered {value.readable_messages} messages, "
                                f"fewer than the whole chunks hold ({value.status})")
            table[cmd, outcome] += 1
    return table, failures


def _print(title: str, table: Counter) -> None:
    cmds = ["info", "doctor", "recover", "replay", "eval"]
    print(f"\n{title}\n{'':8}" + "".join(f"{c:>9}" for c in cmds))
    for outcome in ("clean", "error", "crash", "wrong"):
        print(f"{outcome:8}" + "".join(f"{table[c, outcome]:>9}" for c in cmds))
    print("doctor verdicts: " + ", ".join(
        f"{v} {table['verdict', v]}" for v in ("complete", "truncated", "corrupt")))


def test_fuzz_sgtool_log(sgtool_log, tmp_path):
    table, failures = campaign(sgtool_log, tmp_path, N_MUTANTS, SEED)
    _print(f"{N_MUTANTS} mutants of a 12-frame sgtool log", table)
    assert not failures, "\n".join(failures[:10])
    # the campaign reached both sides: logs that read and logs that are refused
    for cmd in ("info", "replay"):
        assert table[cmd, "clean"] > 0 and table[cmd, "error"] > 0, cmd
    assert table["doctor", "clean"] == N_MUTANTS  # doctor diagnoses every MCAP file
    assert table["verdict", "truncated"] >= N_MUTANTS // 4  # every cut
    assert table["verdict", "corrupt"] > N_MUTANTS // 4


def test_fuzz_ros2_mcap(shared_data_dir, tmp_path):
    src = shared_data_dir / "logs" / "rosbag2-mcap" / "talker.mcap"
    if not src.exists():
        pytest.skip(f"{src} is absent")
    table, failures = campaign(src, tmp_path, N_MUTANTS, SEED)
    _print(f"{N_MUTANTS} mutants of the ROS 2 MCAP talker.mcap", table)
    assert not failures, "\n".join(failures[:10])
    assert table["info", "clean"] > 0 and table["info", "error"] > 0


def _scored(path: Path) -> Any:
    """replay --score in-process: the house attachment validated, the graph scored."""
    from sgtool.log import LogReader
    from sgtool.replayers.derived_log import ReplayOptions, replay
    from sgtool.replayers.score import score

    with LogReader(path) as r:
        spec = r.house_spec()
    if spec is None:
        raise SgtoolError(f"{path} has no house spec attachment")
    final: dict[str, Any] = {}
    replay(path, None, ReplayOptions(every=100, voxel_size=0.2),
           on_refresh=lambda ref, stream: final.update(ref=ref, stream=stream))
    return score(spec, final["stream"].builder.instances, final["ref"].layers,
                 final["ref"].graph)


def _frames(path: Path) -> int:
    from sgtool.log import LogReader

    with LogReader(path) as r:
        return sum(1 for _ in r.frames())


def test_fuzz_crafted_logs(tmp_path):
    """Every crafted log: no crash; doctor "complete", or "corrupt" for messages written
    malformed that replay refuses, recovery keeps every other message;
    replay (and replay --score) read or refuse it as expected, never a silently wrong
    result (an out-of-range instance table used to give an empty graph)."""
    table: Counter[tuple[str, str]] = Counter()
    failures: list[str] = []
    out = tmp_path / "recovered.mcap"
    for name, path in crafted_logs(tmp_path):
        res = _commands(path, out)
        res["score"] = _run(lambda p=path: _scored(p))
        res["frames"] = _run(lambda p=path: _frames(p))
        want = crafted_expectation(name)
        for cmd, (outcome, value) in res.items():
            if outcome == "crash":
                failures.append(f"{name} {cmd}: {value}")
            elif cmd in want and outcome != want[cmd]:
                failures.append(f"{name} {cmd}: {outcome}, expected {want[cmd]}: {value}")
                outcome = "wrong"
            elif cmd in ("doctor", "recover") and (wrong := crafted_report_problem(
                    name, cmd, value.status, value.problems, value.readable_messages,
                    value.dropped_messages, message_count(path))):
                failures.append(f"{name} {cmd}: {wrong}")
                outcome = "wrong"
            table[cmd, outcome] += 1
    cmds = ["info", "doctor", "recover", "replay", "score", "frames", "eval"]
    print(f"\n{table['doctor', 'clean']} crafted logs")
    print(f"{'':8}" + "".join(f"{c:>9}" for c in cmds))
    for outcome in ("clean", "error", "crash", "wrong"):
        print(f"{outcome:8}" + "".join(f"{table[c, outcome]:>9}" for c in cmds))
    assert not failures, "\n".join(failures[:10])
    assert table["replay", "clean"] > 0 and table["replay", "error"] > 0
