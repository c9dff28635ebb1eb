"""The Ray executor on one local Ray instance of 2 CPUs (started once for the module: Ray's
start-up costs seconds): a small bench and a 3-log batch replay give what the local
executor gives, and a log whose replay raises is reported after its retry, not lost."""

from __future__ import annotations

import dataclasses
import os

import pytest
from support.logfixtures import write_log

ray = pytest.importorskip("ray", reason="Ray is not installed (pip install 'sgtool[ray]')")

from sgtool.analysis.batch_replay import plan_jobs, replay_many  # noqa: E402
from sgtool.analysis.bench import BenchConfig, run_benchmark  # noqa: E402
from sgtool.analysis.executor import LocalExecutor, RayExecutor  # noqa: E402
from sgtool.replayers.derived_log import ReplayOptions, replay  # noqa: E402


@pytest.fixture(scope="module")
def local_ray():
    if ray.is_initialized():  # pragma: no cover - another module's instance
        ray.shutdown()
    os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
    ray.init(address="local", num_cpus=2, include_dashboard=False, log_to_driver=False,
             configure_logging=False)
    yield
    ray.shutdown()


def _without_wall(results):
    return [dataclasses.replace(r, wall={}) for r in results]


def test_bench_on_ray_equals_local(local_ray):
    cfg = BenchConfig(planners=("random", "greedy"), houses=2, episodes=2, seeds=2,
                      rooms=(4, 6), preset="default")
    local = run_benchmark(cfg)
    on_ray = run_benchmark(dataclasses.replace(cfg, executor="ray", workers=2))
    assert ray.is_initialized()  # the module's instance is used and left running
    assert len(local.results) == 2 * 2 * 2 * 2 and not local.failed and not on_ray.failed
    assert _without_wall(on_ray.results) == _without_wall(local.results)
    assert on_ray.digest == local.digest


def test_batch_replay_on_ray_equals_one_by_one_and_reports_a_failing_log(local_ray, tmp_path):
    opts = ReplayOptions(every=4, voxel_size=0.1)
    logs = [write_log(tmp_path / f"run{n}.mcap", n=n) for n in (6, 8, 10)]
    broken = tmp_path / "broken.mcap"
    broken.write_bytes(logs[0].read_bytes()[:3000])
    for p in logs:
        replay(p, tmp_path / f"one-{p.name}", opts)
    out = tmp_path / "out"
    out.mkdir()
    jobs = plan_jobs([*logs, broken], out, opts)
    report = replay_many(jobs, RayExecutor(2))
    assert [r.status for r in report.logs] == ["replayed", "replayed", "replayed", "failed"]
    assert report.logs[3].error and "ends without the MCAP" in report.logs[3].error
    for p in logs:
        assert (out / p.name).read_bytes() == (tmp_path / f"one-{p.name}").read_bytes()
    assert not (out / "broken.mcap").exists()
    # the local executor gives the same report, but for the wall clock
    local = replay_many(jobs, LocalExecutor(1), force=True)
    assert local.logs == report.logs


KILLED_RAY_DRIVER = '''
import signal, sys, time
from pathlib import Path
from sgtool.analysis.executor import RayExecutor, Task
from sgtool.errors import raise_terminated, stop_exit_code

OUT = Path(sys.argv[1])

def slow(i):
    (OUT / "started").write_text("1")
    time.sleep(120)

if __name__ == "__main__":
    signal.signal(signal.SIGTERM, raise_terminated)  # as the CLI does
    try:
        RayExecutor(1).run(slow, [Task("0", 0)])
    except KeyboardInterrupt as e:
        print("stopped", file=sys.stderr)
        sys.exit(stop_exit_code(e))
'''


def test_a_kill_of_a_ray_driver_ends_as_sgtool_s_own(tmp_path):
    """ray.init sets a SIGTERM handler of its own (sys.exit(15), no clean-up) and Ray's
    native failure handler turns SIGTERM into an abort with stack dumps (exit 134); the
    executor keeps the caller's handler and disables Ray's, so a kill is an interrupt."""
    import subprocess
    import sys
    import time

    script = tmp_path / "driver.py"
    script.write_text(KILLED_RAY_DRIVER)
    env = {k: v for k, v in os.environ.items() if k != "RAY_ADDRESS"}
    proc = subprocess.Popen([sys.executable, str(script), str(tmp_path)], env=env,
                            stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 120
        while not (tmp_path / "started").exists():
            assert proc.poll() is None and time.monotonic() < deadline
            time.sleep(0.2)
        proc.terminate()
        assert proc.wait(timeout=120) == 143
        err = proc.stderr.read() if proc.stderr else ""
    finally:
        proc.kill()
    assert "stopped" in err and "SIGTERM received" not in err, err
