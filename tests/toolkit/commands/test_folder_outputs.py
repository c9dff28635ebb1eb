"""Every command that writes a folder (``bench -o``, ``run-bench -o``, ``replay --out-dir``)
on an existing non-empty target (refused in one line), with ``--force`` (the user's own
file survives, what sgtool wrote is replaced), under a read-only parent (one line) and
interrupted (Ctrl-C: the earlier state of the target stays, and the message says so)."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest
from click.testing import CliRunner
from support.logfixtures import write_log
from support.read_only import make_read_only

from sgtool.analysis import batch_replay
from sgtool.analysis import bench as bench_module
from sgtool.analysis import closed_loop_bench as clb
from sgtool.cli import cli
from sgtool.datasets.generator import generate_house
from sgtool.files import MANIFEST, read_manifest
from sgtool.house.io import save_house

BENCH = ["bench", "--houses", "1", "--rooms", "4-5", "--preset", "default", "--episodes", "1",
         "--seeds", "1", "--planners", "random", "--no-progress"]
RUN_BENCH = ["run-bench", "--planners", "random", "--episodes", "1", "--resolution", "64x48",
             "--max-steps", "2", "--frames", "60", "--no-progress"]
BENCH_FILES = {"efficiency_distance.png", "efficiency_steps.png", "episodes.jsonl",
               "per_house.jsonl", "per_house.md", "per_query.jsonl", "per_query.md", "run.json",
               "run.md", "summary.json", "summary.md"}


def _tree(folder: Path) -> dict[str, bytes]:
    return {p.relative_to(folder).as_posix(): p.read_bytes()
            for p in sorted(folder.rglob("*")) if p.is_file()}


def _run(args: list[str]) -> tuple[int, str]:
    r = CliRunner().invoke(cli, [str(a) for a in args])
    return r.exit_code, r.output


def _one_line_error(code: int, output: str) -> str:
    assert code == 2, output
    assert len(output.strip().splitlines()) == 1 and "Traceback" not in output, output
    return output


# ----------------------------------------------------------------------------------------
# bench -o
# ----------------------------------------------------------------------------------------
def test_bench_refuses_a_non_empty_folder_and_force_keeps_the_users_files(tmp_path: Path):
    fresh = tmp_path / "fresh"
    assert _run([*BENCH, "-o", fresh])[0] == 0
    out = tmp_path / "d"
    out.mkdir()
    (out / "summary.md").write_text("mine\n")  # the case: exit 0, file overwritten
    msg = _one_line_error(*_run([*BENCH, "-o", out]))
    assert "not empty" in msg and "--force" in msg
    assert _tree(out) == {"summary.md": b"mine\n"}
    assert sorted(os.listdir(tmp_path)) == ["d", "fresh"]
    # a file named as an output, no manifest: it may be the user's, so --force refuses
    msg = _one_line_error(*_run([*BENCH, "-o", out, "--force"]))
    assert "holds summary.md, named as this command's outputs but not listed" in msg
    assert _tree(out) == {"summary.md": b"mine\n"}
    # the user's notes alone are no obstacle
    (out / "summary.md").unlink()
    (out / "notes.txt").write_text("mine\n")
    code, output = _run([*BENCH, "-o", out, "--force"])
    assert code == 0, output
    assert set(os.listdir(out)) == BENCH_FILES | {"notes.txt", MANIFEST}
    assert (out / "notes.txt").read_text() == "mine\n"
    assert read_manifest(out) == ("bench", frozenset(BENCH_FILES))
    assert f"wrote {out / 'episodes.jsonl'}" in output  # the final paths, not the temporary
    # the same bytes as a bench into a new folder (run.* hold the command: its -o differs)
    for name in ("summary.md", "summary.json", "per_house.md", "per_query.jsonl"):
        assert (out / name).read_bytes() == (fresh / name).read_bytes()
    # what the manifest lists goes on the next --force, even under a name bench no longer
    # writes; the user's file stays
    (out / "efficiency_old.png").write_bytes(b"stale")
    doc = json.loads((out / MANIFEST).read_text())
    (out / MANIFEST).write_text(json.dumps({**doc, "files": [*doc["files"], "stale.md"]}))
    (out / "stale.md").write_text("an earlier sgtool file\n")
    assert _run([*BENCH, "-o", out, "--force"])[0] == 0
    assert set(os.listdir(out)) == BENCH_FILES | {"notes.txt", MANIFEST}


def test_bench_under_a_read_only_parent_is_one_line(tmp_path: Path,
                                                     monkeypatch: pytest.MonkeyPatch):
    parent = tmp_path / "ro"
    parent.mkdir()
    make_read_only(parent, monkeypatch)
    try:
        msg = _one_line_error(*_run([*BENCH, "-o", parent / "d"]))
    finally:
        parent.chmod(0o755)
    assert "Permission denied" in msg and str(parent / "d") in msg
    assert os.listdir(parent) == []


@pytest.mark.parametrize("earlier", [False, True])
def test_ctrl_c_during_bench_leaves_the_earlier_state(tmp_path: Path,
                                                      monkeypatch: pytest.MonkeyPatch,
                                                      earlier: bool):
    out = tmp_path / "d"
    if earlier:
        assert _run([*BENCH, "-o", out])[0] == 0
        (out / "notes.txt").write_text("mine\n")
    before = _tree(out) if earlier else None
    real = bench_module.atomic_write
    calls: list[Path] = []

    def interrupted(path: Path, data: str | bytes) -> Path:  # Ctrl-C amid the result files
        calls.append(Path(path))
        if len(calls) == 3:
            raise KeyboardInterrupt
        return real(path, data)

    monkeypatch.setattr(bench_module, "atomic_write", interrupted)
    code, output = _run([*BENCH, "-o", out, *(["--force"] if earlier else [])])
    assert code == 130 and len(calls) == 3
    assert len(output.strip().splitlines()) == 1 and "interrupted" in output
    assert "is as it was" in output and "half-written" not in output
    assert (_tree(out) if out.exists() else None) == before
    assert os.listdir(tmp_path) == (["d"] if earlier else [])  # no temporary folder left


def test_bench_log_dir_is_an_output_folder_too(tmp_path: Path,
                                               monkeypatch: pytest.MonkeyPatch):
    logs, out = tmp_path / "logs", tmp_path / "d"
    logs.mkdir()
    (logs / "notes.txt").write_text("mine\n")
    msg = _one_line_error(*_run([*BENCH, "-o", out, "--log-dir", logs]))
    assert "--log-dir" in msg and "--force" in msg and not out.exists()
    assert _run([*BENCH, "-o", out, "--log-dir", logs, "--force"])[0] == 0
    assert sorted(p.relative_to(logs).as_posix() for p in logs.rglob("*.mcap")) == \
        ["random/house-0/seed0-ep0.mcap"]
    assert (logs / "notes.txt").read_text() == "mine\n"
    # the logs in OUT itself: one folder, one manifest listing both
    both = tmp_path / "both"
    assert _run([*BENCH, "-o", both, "--log-dir", both])[0] == 0
    assert read_manifest(both) == ("bench", frozenset(BENCH_FILES | {"random"}))
    # Ctrl-C: both folders as they were
    before = _tree(logs), _tree(out)

    def interrupted(*args: object, **kw: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(bench_module, "write_outputs", interrupted)
    code, output = _run([*BENCH, "-o", out, "--log-dir", logs, "--force"])
    assert code == 130 and f"{out} and {logs} are as they were" in output
    assert (_tree(logs), _tree(out)) == before
    assert sorted(os.listdir(tmp_path)) == ["both", "d", "logs"]


# ----------------------------------------------------------------------------------------
# run-bench -o
# ----------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def house_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    p = tmp_path_factory.mktemp("houses") / "small.json"
    save_house(generate_house(6, rooms=(4, 4)), p)
    return p


def test_run_bench_refuses_another_folder_and_force_keeps_the_users_files(
        house_file: Path, tmp_path: Path):
    out = tmp_path / "rb"
    out.mkdir()
    (out / "notes.txt").write_text("mine\n")
    # --house without --houses: the given house only (no generated house is run)
    msg = _one_line_error(*_run([*RUN_BENCH, "--house", house_file, "-o", out]))
    assert "not empty" in msg and "--force" in msg
    assert _tree(out) == {"notes.txt": b"mine\n"}
    code, output = _run([*RUN_BENCH, "--house", house_file, "-o", out, "--force"])
    assert code == 0, output
    assert (out / "notes.txt").read_text() == "mine\n"
    logs = sorted(p.relative_to(out).as_posix() for p in out.rglob("*.mcap"))
    assert logs == ["logs/none/random/small/ep-000.mcap"]  # no generated house
    assert read_manifest(out)[0] == "run-bench"
    assert [p for p in os.listdir(tmp_path) if p != "rb"] == []
    # its own folder is resumed without --force (the log is read back, not run again)
    code, output = _run([*RUN_BENCH, "--house", house_file, "-o", out])
    assert code == 0, output
    assert (out / "notes.txt").read_text() == "mine\n"


def test_ctrl_c_during_a_forced_run_bench_leaves_the_earlier_state(
        house_file: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch):
    out = tmp_path / "rb"
    assert _run([*RUN_BENCH, "--house", house_file, "-o", out])[0] == 0
    (out / "notes.txt").write_text("mine\n")
    before = _tree(out)

    def interrupted(*args: object, **kw: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(clb, "run_episode", interrupted)
    code, output = _run([*RUN_BENCH, "--house", house_file, "-o", out, "--force"])
    assert code == 130 and len(output.strip().splitlines()) == 1
    assert "is as it was" in output and "kept" not in output
    assert _tree(out) == before
    assert os.listdir(tmp_path) == ["rb"]


def test_run_bench_under_a_read_only_parent_is_one_line(house_file: Path, tmp_path: Path,
                                                         monkeypatch: pytest.MonkeyPatch):
    parent = tmp_path / "ro"
    parent.mkdir()
    make_read_only(parent, monkeypatch)
    try:
        msg = _one_line_error(*_run([*RUN_BENCH, "--house", house_file,
                                     "-o", parent / "rb"]))
    finally:
        parent.chmod(0o755)
    assert "Permission denied" in msg and os.listdir(parent) == []


# ----------------------------------------------------------------------------------------
# replay --out-dir
# ----------------------------------------------------------------------------------------
REPLAY = ["replay", "--every", "4", "--voxel-size", "0.1", "--no-progress"]


@pytest.fixture(scope="module")
def logs(tmp_path_factory: pytest.TempPathFactory) -> list[Path]:
    d = tmp_path_factory.mktemp("logs")
    return [write_log(d / f"run{n}.mcap", n=n) for n in (4, 6)]


def test_replay_out_dir_refuses_another_folder_and_force_keeps_the_users_files(
        logs: list[Path], tmp_path: Path):
    out = tmp_path / "derived"
    out.mkdir()
    (out / "notes.txt").write_text("mine\n")
    msg = _one_line_error(*_run([*REPLAY, *logs, "--out-dir", out]))
    assert "--out-dir" in msg and "not empty" in msg and "--force" in msg
    assert _tree(out) == {"notes.txt": b"mine\n"}
    code, output = _run([*REPLAY, *logs, "--out-dir", out, "--force"])
    assert code == 0, output
    assert set(os.listdir(out)) == {"notes.txt", "run4.mcap", "run6.mcap", MANIFEST}
    assert f"wrote {out / 'run4.mcap'}: 4 frames" in output
    assert read_manifest(out) == ("replay", frozenset({"run4.mcap", "run6.mcap"}))
    # its own folder: complete outputs kept without --force
    code, output = _run([*REPLAY, *logs, "--out-dir", out])
    assert code == 0 and "0 replayed, 2 skipped" in output


def test_ctrl_c_during_a_forced_replay_leaves_the_earlier_state(
        logs: list[Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch):
    out = tmp_path / "derived"
    assert _run([*REPLAY, *logs, "--out-dir", out])[0] == 0
    (out / "notes.txt").write_text("mine\n")
    before = _tree(out)
    real = batch_replay.atomic_write
    calls: list[Path] = []

    def interrupted(path: Path, data: bytes) -> Path:  # after the first derived log
        calls.append(Path(path))
        if len(calls) == 2:
            raise KeyboardInterrupt
        return real(path, data)

    monkeypatch.setattr(batch_replay, "atomic_write", interrupted)
    code, output = _run([*REPLAY, *logs, "--out-dir", out, "--force"])
    assert code == 130 and len(calls) == 2 and len(output.strip().splitlines()) == 1
    assert "is as it was" in output and "kept" not in output
    assert _tree(out) == before
    assert os.listdir(tmp_path) == ["derived"]


def test_replay_out_dir_under_a_read_only_parent_is_one_line(
        logs: list[Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch):
    parent = tmp_path / "ro"
    parent.mkdir()
    make_read_only(parent, monkeypatch)
    try:
        msg = _one_line_error(*_run([*REPLAY, *logs, "--out-dir", parent / "derived"]))
    finally:
        parent.chmod(0o755)
    assert "Permission denied" in msg and os.listdir(parent) == []


def test_a_folder_name_near_the_limit_is_staged_beside_it(tmp_path: Path) -> None:
    """An output folder named with 250 bytes: its hidden staging folder
    (``.NAME.XXXXXXXX.partial``, 18 bytes longer) is cut to fit, and a stage a killed run
    left beside it is found."""
    from sgtool.files import output_folder
    from sgtool.leftovers import leftover_stages

    target = tmp_path / ("d" * 250)
    with output_folder(target, force=False, command="bench") as root:
        assert len(os.fsencode(root.name)) <= 255
        (root / "summary.md").write_text("x")
        stages = leftover_stages(target)
        assert stages == [root]  # while it is being built, it is the stage beside
    assert (target / "summary.md").read_text() == "x" and leftover_stages(target) == []
    other = tmp_path / ("d" * 249 + "e")  # the same first 249 bytes: not its stage
    with output_folder(other, force=False, command="bench") as root:
        assert leftover_stages(other) == [root] and leftover_stages(target) == []
