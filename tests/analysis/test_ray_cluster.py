"""`sgtool run-bench --executor ray` on a real two-node Ray cluster on this machine: a head
(`ray start --head`, 1 CPU, resource ``head``) and a second node (`ray start --address`,
1 CPU, resource ``node2``, its own temp dir), each a process of its own. The second node
acts as another machine (``SGTOOL_MACHINE_ID``): it does not write into the output folder
but sends its logs back to the driver, as a node without the folder would. The driver is
the CLI in a process of its own too. One small generated house, 2 episodes per planner
for 2 planners at 48x36 with a frame budget: the episodes run on both nodes (run.json
names the node of each, and which logs were sent back), the results equal a `-w 1` run's
(summary.json byte for byte; the records and every log message but the measured decision
time), the logs reach the output folder while the driver still runs, and a driver killed
with SIGKILL mid-run resumes: the finished episodes are not run again, no partial log
stays, the result is the same.

Ray starts slowly on busy cores: generous deadlines, no timed assertion. The nodes are
stopped through their process groups (``ray stop`` would stop every Ray on the machine,
other users' too), in a finaliser that runs when a test fails. Ray's token authentication
is turned off for this throw-away local cluster (``RAY_AUTH_MODE=disabled``)."""

from __future__ import annotations

import contextlib
import json
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest
from click.testing import CliRunner

from sgtool.cli import cli

pytest.importorskip("ray", reason="Ray is not installed (pip install 'sgtool[ray]')")

pytestmark = pytest.mark.ci_only  # a cluster and four runs: minutes on two busy cores

START_S = 300.0  # deadline of the cluster's start-up
RUN_S = 900.0  # deadline of one run-bench
EPISODES = 4  # 2 planners x 1 house x 2 episodes
ARGS = ["run-bench", "--planners", "random,greedy", "--houses", "1", "--episodes", "2",
        "--rooms", "4-5", "--preset", "default", "--resolution", "48x36", "--frames", "200",
        "--max-steps", "10", "--no-progress"]
DRIVER = "import sys; from sgtool.cli import main; sys.exit(main())"
NODES = """
import sys, time, ray
ray.init(address=sys.argv[1], log_to_driver=False, configure_logging=False)
deadline = time.monotonic() + float(sys.argv[2])
while True:
    alive = [n for n in ray.nodes() if n["Alive"]]
    if len(alive) >= 2 or time.monotonic() > deadline:
        break
    time.sleep(0.5)
print(" ".join(("node2" if "node2" in n["Resources"] else "head") + "=" + n["NodeID"]
               for n in alive))
"""


@dataclass(frozen=True)
class Cluster:
    address: str
    env: dict[str, str]
    nodes: dict[str, str]  # head, node2 -> Ray node id


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _ray() -> str:
    here = Path(sys.executable).parent / "ray"
    return str(here) if here.exists() else (shutil.which("ray") or "ray")


def _start_node(args: list[str], temp: Path, env: dict[str, str]) -> subprocess.Popen[bytes]:
    """`ray start ... --block` in a session of its own (its process group holds the node's
    processes), output to ``temp``.out."""
    ports = ["--node-manager-port", "--object-manager-port", "--dashboard-agent-listen-port",
             "--dashboard-agent-grpc-port", "--runtime-env-agent-port", "--metrics-export-port"]
    cmd = [_ray(), "start", *args, "--block", "--num-cpus", "1", "--temp-dir", str(temp),
           "--disable-usage-stats", "--object-store-memory", str(100 * 2**20),
           "--min-worker-port", "0", "--max-worker-port", "0"]  # 0: ports the OS picks
    for opt in ports:
        cmd += [opt, str(_free_port())]
    with open(f"{temp}.out", "wb") as log:
        return subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, env=env,
                                start_new_session=True)


def _stop_node(proc: subprocess.Popen[bytes]) -> None:
    """SIGTERM to the node's process group (`ray start --block` then stops its processes),
    then SIGKILL to whatever of the group is left."""
    with contextlib.suppress(ProcessLookupError):
        os.killpg(proc.pid, signal.SIGTERM)
    with contextlib.suppress(subprocess.TimeoutExpired):
        proc.wait(timeout=60)
    with contextlib.suppress(ProcessLookupError):
        os.killpg(proc.pid, signal.SIGKILL)
    proc.wait(timeout=60)


def _tail(path: Path | str, n: int = 2000) -> str:
    try:
        return Path(path).read_text(errors="replace")[-n:]
    except OSError:
        return ""


@pytest.fixture(scope="module")
def cluster() -> Iterator[Cluster]:
    temp = Path(tempfile.mkdtemp(prefix="sgray", dir="/tmp"))  # short: Ray's socket paths
    env = {k: v for k, v in os.environ.items() if k != "RAY_ADDRESS"}
    env.update(RAY_AUTH_MODE="disabled", RAY_USAGE_STATS_ENABLED="0", HF_HUB_OFFLINE="1",
               TRANSFORMERS_OFFLINE="1", MPLBACKEND="Agg")
    nodes: list[subprocess.Popen[bytes]] = []
    try:
        port = _free_port()
        address = f"127.0.0.1:{port}"
        nodes.append(_start_node(["--head", "--port", str(port), "--include-dashboard",
                                  "false", "--resources", '{"head": 1}'], temp / "head", env))
        deadline = time.monotonic() + START_S
        while True:  # the head's GCS listens
            try:
                socket.create_connection(("127.0.0.1", port), timeout=1).close()
                break
            except OSError:
                assert nodes[0].poll() is None, _tail(temp / "head.out")
                assert time.monotonic() < deadline, "the head did not start"
                time.sleep(0.2)
        nodes.append(_start_node(["--address", address, "--resources", '{"node2": 1}'],
                                 temp / "node2", {**env, "SGTOOL_MACHINE_ID": "node2"}))
        found = subprocess.run([sys.executable, "-c", NODES, address, str(START_S)], env=env,
                               capture_output=True, text=True, timeout=START_S + 120)
        # the last line holds the ids (Ray may print to stdout before it)
        lines = found.stdout.strip().splitlines()
        ids = dict(w.split("=", 1) for w in (lines[-1].split() if lines else ()) if "=" in w)
        assert found.returncode == 0 and sorted(ids) == ["head", "node2"], (
            f"{found.stdout}{found.stderr[-2000:]}\n{_tail(temp / 'node2.out')}")
        yield Cluster(address, env, ids)
    finally:
        for proc in reversed(nodes):
            _stop_node(proc)
        shutil.rmtree(temp, ignore_errors=True)


@pytest.fixture(scope="module")
def reference(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The same run with `-w 1` (in this process)."""
    out = tmp_path_factory.mktemp("one") / "rb"
    res = CliRunner().invoke(cli, [*ARGS, "-w", "1", "-o", str(out)])
    assert res.exit_code == 0, res.output
    return out


def _driver(cluster: Cluster, out: Path) -> subprocess.Popen[bytes]:
    cmd = [sys.executable, "-c", DRIVER, *ARGS, "--executor", "ray", "--ray-address",
           cluster.address, "-o", str(out)]
    with open(f"{out}.out", "ab") as log:
        return subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, env=cluster.env)


def _logs(out: Path) -> list[Path]:
    return sorted(out.rglob("ep-*.mcap"))


def _wait(proc: subprocess.Popen[bytes], out: Path) -> None:
    assert proc.wait(timeout=RUN_S) == 0, _tail(f"{out}.out")


def _messages(path: Path) -> list[tuple[str, int, bytes]]:
    """A log's messages, the measured decision time zeroed (the only wall clock in it)."""
    from mcap.reader import make_reader

    with open(path, "rb") as f:
        return [(c.topic, m.log_time,
                 re.sub(rb'"decision_time_s":[0-9.e-]+', b'"decision_time_s":0', m.data))
                for _, c, m in make_reader(f).iter_messages()]


def _records(out: Path) -> list[dict[str, object]]:
    recs = [json.loads(s) for s in (out / "episodes.jsonl").read_text().splitlines()]
    for r in recs:
        r.pop("wall")  # wall clock
        assert (out / str(r["source"])).is_file()  # named relative to the run folder
    return recs


def _assert_same_results(out: Path, reference: Path) -> None:
    assert (out / "summary.json").read_bytes() == (reference / "summary.json").read_bytes()
    assert _records(out) == _records(reference) and len(_records(out)) == EPISODES
    logs = [p.relative_to(out) for p in _logs(out)]
    assert logs == [p.relative_to(reference) for p in _logs(reference)]
    for rel in logs:
        assert _messages(out / rel) == _messages(reference / rel), rel
    assert not list(out.rglob("*.partial"))


def _run_json(out: Path) -> dict[str, dict[str, object]]:
    return {e["log"]: e for e in json.loads((out / "run.json").read_text())["episodes"]}


def test_run_bench_runs_on_both_nodes_streams_logs_and_equals_one_worker(
        cluster: Cluster, reference: Path, tmp_path: Path) -> None:
    out = tmp_path / "rb"
    proc = _driver(cluster, out)
    logs_while_running: set[int] = set()  # log counts seen before the driver ended
    while proc.poll() is None:
        n = len(_logs(out))
        if not (out / "summary.json").exists():
            logs_while_running.add(n)
        time.sleep(0.1)
    _wait(proc, out)
    # the logs arrived one by one as episodes finished, not all at the end
    assert any(0 < n < EPISODES for n in logs_while_running), logs_while_running
    ran = _run_json(out)
    assert len(ran) == EPISODES and all(e["ran"] for e in ran.values())
    assert {e["node"] for e in ran.values()} == set(cluster.nodes.values())  # both nodes
    for e in ran.values():  # node2 sent its logs back, the head wrote into the folder
        assert e["sent"] is (e["node"] == cluster.nodes["node2"])
    _assert_same_results(out, reference)


def test_a_driver_killed_mid_run_resumes_without_running_finished_episodes_again(
        cluster: Cluster, reference: Path, tmp_path: Path) -> None:
    out = tmp_path / "rb"
    proc = _driver(cluster, out)
    try:
        deadline = time.monotonic() + RUN_S
        while not _logs(out):  # the first episode finished
            assert proc.poll() is None, _tail(f"{out}.out")
            assert time.monotonic() < deadline, "no episode finished"
            time.sleep(0.1)
        proc.send_signal(signal.SIGKILL)
    finally:
        proc.kill()
        proc.wait(timeout=60)
    finished = {p.relative_to(out).as_posix(): (p.stat().st_ino, p.stat().st_mtime_ns)
                for p in _logs(out)}
    assert 0 < len(finished) < EPISODES
    proc = _driver(cluster, out)  # the same command again
    _wait(proc, out)
    for rel, stamp in finished.items():  # read back, not run again
        p = out / rel
        assert (p.stat().st_ino, p.stat().st_mtime_ns) == stamp, rel
    ran = _run_json(out)
    assert all(not ran[rel]["ran"] for rel in finished)
    assert any(e["ran"] for e in ran.values())
    _assert_same_results(out, reference)
