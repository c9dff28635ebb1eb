"""The local executor (in process and a pool of 2): results in task order, a failing task
retried once then reported, Ctrl-C keeps what finished, a kill of the driver stops the
workers and leaves no partial output; option errors are one line, Ray
missing or unreachable too (no Ray started here: see test_ray_executor.py)."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from sgtool.analysis.executor import (
    ExecutorError,
    LocalExecutor,
    Outcome,
    Task,
    check_reachable,
    chunks,
    error_line,
    failure_lines,
    make_executor,
    retry_lines,
)
from sgtool.errors import SgtoolError

CALLS: list[int] = []


def square_but_three(x: int) -> int:
    CALLS.append(x)
    if x == 3:
        raise ValueError(f"no square for {x}\nsecond line")
    return x * x


def interrupted_at_two(x: int) -> int:
    if x == 2:
        raise KeyboardInterrupt
    return x


@pytest.mark.parametrize("workers", [1, 2])
def test_outcomes_in_task_order_and_a_failure_is_reported_after_one_retry(workers):
    CALLS.clear()
    tasks = [Task(f"t{i}", i) for i in range(6)]
    seen = []
    outs = LocalExecutor(workers).run(square_but_three, tasks, on_result=seen.append)
    assert [o.id for o in outs] == ["t0", "t1", "t2", "t3", "t4", "t5"]
    assert [o.value for o in outs] == [0, 1, 4, None, 16, 25]
    bad = outs[3]
    assert not bad.ok and bad.attempts == 2 and bad.error == "ValueError: no square for 3"
    assert all(o.ok and o.attempts == 1 for o in outs if o.id != "t3")
    assert failure_lines(outs) == ["t3: ValueError: no square for 3 (after 2 attempts)"]
    assert sorted(o.id for o in seen) == [t.id for t in tasks]  # each final outcome once
    if workers == 1:  # in this process: the failing task ran twice, the others once
        assert sorted(CALLS) == [0, 1, 2, 3, 3, 4, 5]


@pytest.mark.parametrize("workers", [1, 2])
def test_ctrl_c_stops_the_run_and_keeps_what_finished(workers):
    """In process or in a worker (a worker killed alone): the run stops, not retried."""
    seen = []
    with pytest.raises(KeyboardInterrupt):
        LocalExecutor(workers).run(interrupted_at_two, [Task(str(i), i) for i in range(5)],
                                   on_result=seen.append)
    if workers == 1:
        assert [o.value for o in seen] == [0, 1]
    assert 2 not in [o.value for o in seen] and len(seen) < 5


def test_chunks_cut_near_equal_contiguous_runs():
    assert list(chunks("abcde", 2)) == [("a", "b", "c"), ("d", "e")]
    assert list(chunks("abc", 5)) == [("a",), ("b",), ("c",)]
    assert list(chunks("ab", 1)) == [("a", "b")]


def test_option_errors_are_one_line():
    with pytest.raises(ExecutorError, match="--workers: must be >= 1, got 0"):
        make_executor("local", 0)
    with pytest.raises(ExecutorError, match="--ray-address needs --executor ray"):
        make_executor("local", 1, "127.0.0.1:6379")
    with pytest.raises(ExecutorError, match="--executor: one of local, ray, got 'dask'"):
        make_executor("dask", 1)
    with pytest.raises(ValueError, match="unique"):
        LocalExecutor(1).run(abs, [Task("a", 1), Task("a", 2)])


def test_error_line_unwraps_a_cause_and_keeps_the_first_line():
    class Wrapped(Exception):
        cause = KeyError("k")

    assert error_line(Wrapped("x")) == "KeyError: 'k'"
    assert error_line(RuntimeError("one\ntwo")) == "RuntimeError: one"
    assert error_line(RuntimeError()) == "RuntimeError"
    # a message written for the user goes without its class name
    assert error_line(SgtoolError("x.mcap has no channel /camera/depth\nmore")) == \
        "x.mcap has no channel /camera/depth"


def test_ray_not_installed_says_how_to_install_it(monkeypatch):
    monkeypatch.setitem(sys.modules, "ray", None)  # import ray -> ImportError
    with pytest.raises(ExecutorError) as e:
        make_executor("ray", 2)
    assert str(e.value) == "--executor ray needs Ray: pip install 'sgtool[ray]'"


def test_unreachable_ray_cluster_is_one_line_and_quick():
    with socket.socket() as s:  # a port nothing listens on (bound, then closed)
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    with pytest.raises(ExecutorError) as e:
        check_reachable(f"127.0.0.1:{port}", timeout_s=2.0)
    text = str(e.value)
    assert "\n" not in text
    assert text.startswith(f"Ray cluster at 127.0.0.1:{port} is not reachable (")
    assert "ray start --head" in text
    with pytest.raises(ExecutorError, match="give HOST:PORT"):
        check_reachable("nohost")
    check_reachable("auto")  # Ray's own: passed on


def test_cli_ray_address_unreachable_is_one_line(tmp_path):
    from click.testing import CliRunner

    from sgtool.cli import cli

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    r = CliRunner().invoke(cli, ["bench", "--houses", "1", "--episodes", "1", "--seeds", "1",
                                 "--planners", "random", "--executor", "ray",
                                 "--ray-address", f"127.0.0.1:{port}", "--no-progress",
                                 "-o", str(tmp_path / "o")])
    assert r.exit_code == 2
    assert r.stderr.strip().splitlines() == [
        f"sgtool: error: Ray cluster at 127.0.0.1:{port} is not reachable (Connection "
        "refused); start one with `ray start --head` there, or leave out --ray-address "
        "and RAY_ADDRESS to start a local Ray"]
    assert not (tmp_path / "o").exists()


def exit_hard_at_one(x: int) -> int:
    import os

    if x == 1:
        os._exit(3)  # a worker that dies (killed, out of memory, crashed)
    return x


def test_a_dead_pool_worker_is_reported_and_the_pool_replaced():
    outs = LocalExecutor(2).run(exit_hard_at_one, [Task(str(i), i) for i in range(4)])
    assert [o.id for o in outs] == ["0", "1", "2", "3"]
    assert not outs[1].ok and outs[1].error.startswith("BrokenProcessPool")
    assert outs[1].attempts == 2
    # the others ran, or shared a pool when it broke (twice: retried, then reported)
    for o in outs:
        if o.id != "1":
            assert (o.ok and o.value == int(o.id)) or o.error.startswith("BrokenProcessPool")


def test_no_tasks_starts_nothing():
    assert LocalExecutor(2).run(abs, []) == []


KILLED_DRIVER = '''
import os, sys, time
from pathlib import Path
from sgtool.analysis.executor import LocalExecutor, Task
from sgtool.cli import _terminate_as_interrupt
from sgtool.errors import stop_exit_code
from sgtool.files import atomic_output

OUT = Path(sys.argv[1])

def slow(i):
    (OUT / f"pid-{i}").write_text(str(os.getpid()))
    with atomic_output(OUT / f"out-{i}.bin") as tmp:
        tmp.write_bytes(b"half")
        time.sleep(120)

if __name__ == "__main__":
    _terminate_as_interrupt()
    try:
        LocalExecutor(2).run(slow, [Task(str(i), i) for i in range(2)])
    except KeyboardInterrupt as e:
        sys.exit(stop_exit_code(e))
'''


def _gone(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/status").read_text()
    except FileNotFoundError:
        return True
    return "State:\tZ" in state  # exited, not yet reaped (no init reaps in a container)


def _driver_mid_write(tmp_path: Path) -> tuple[subprocess.Popen, Path]:
    """The KILLED_DRIVER script started, once both its tasks are mid-write (their partial
    outputs there): the process and its output folder."""
    script = tmp_path / "driver.py"
    script.write_text(KILLED_DRIVER)
    out = tmp_path / "out"
    out.mkdir()
    proc = subprocess.Popen([sys.executable, str(script), str(out)])
    deadline = time.monotonic() + 120
    while len(list(out.glob("*.partial"))) < 2:  # both tasks are mid-write
        if proc.poll() is not None or time.monotonic() > deadline:
            proc.kill()
            raise AssertionError("the driver's tasks never got to write")
        time.sleep(0.1)
    return proc, out


@pytest.mark.parametrize("sig, code", [(signal.SIGTERM, 143), (signal.SIGINT, 130),
                                       (signal.SIGHUP, 129)])
def test_kill_of_the_driver_stops_the_workers_and_leaves_no_partial_output(tmp_path, sig,
                                                                           code):
    """A kill, a closed terminal, or a Ctrl-C sent to the driver alone (the workers ignore
    SIGINT), stops the tasks mid-write: they clean up, the workers end, and the driver
    exits after them, with 128 + the signal."""
    proc, out = _driver_mid_write(tmp_path)
    try:
        pids = [int((out / f"pid-{i}").read_text()) for i in range(2)]
        proc.send_signal(sig)
        assert proc.wait(timeout=60) == code
    finally:
        proc.kill()
    assert sorted(p.name for p in out.iterdir()) == ["pid-0", "pid-1"]  # no partial, no out
    deadline = time.monotonic() + 10
    while not all(_gone(p) for p in pids) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert all(_gone(p) for p in pids)


def test_a_folder_mark_is_recognised_only_where_that_very_folder_is(tmp_path):
    from dataclasses import replace

    from sgtool.analysis.executor import FolderMark

    out = tmp_path / "out"
    out.mkdir()
    mark = FolderMark.of(out)
    assert mark.here() and mark.path == str(out)
    assert not replace(mark, machine="elsewhere/0").here()  # another machine
    out.rename(tmp_path / "old")  # the old folder is kept, so the new one has another inode
    out.mkdir()
    assert not mark.here()  # the same path, another folder
    out.rmdir()
    assert not mark.here()  # no folder there


def test_sgtool_machine_id_makes_a_process_another_machine(tmp_path, monkeypatch):
    from sgtool.analysis.executor import FolderMark

    mark = FolderMark.of(tmp_path)
    monkeypatch.setenv("SGTOOL_MACHINE_ID", "node2")
    assert not mark.here()
    assert FolderMark.of(tmp_path).here()  # marked there, seen there


def test_a_task_on_this_machine_names_no_node():
    outs = LocalExecutor(1).run(abs, [Task("a", -2)])
    assert outs == [Outcome("a", 2, None, 1, "")]


def test_a_run_without_progress_leaves_the_start_method_unset() -> None:
    """run_benchmark(progress=False) in a user's process: no progress bar object is made,
    so multiprocessing's start method stays the caller's to set (tqdm made a lock that
    fixed it, and set_start_method("spawn") then failed)."""
    import subprocess
    import sys

    code = ("import multiprocessing as mp\n"
            "from sgtool.analysis.executor import LocalExecutor, Task\n"
            "LocalExecutor(1).run(abs, [Task('a', -1)])\n"
            "mp.set_start_method('spawn')\nprint('ok')\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120)
    assert done.stdout.strip() == "ok", done.stderr


def fails_once(arg: tuple[int, str]) -> int:
    """Raises the first time it is called for 1 (a marker file says it was), then works."""
    x, marker = arg
    if x == 1 and not os.path.exists(marker):
        open(marker, "w").close()
        raise RuntimeError("flaky")
    return x


@pytest.mark.parametrize("workers", [1, 2])
def test_a_task_that_succeeds_on_its_retry_is_told(workers, tmp_path):
    """The retry of a task that raised once is no silent event: its outcome keeps the
    first error, and retry_lines names it (bench prints and writes it in run.md)."""
    marker = str(tmp_path / "failed-once")
    outs = LocalExecutor(workers).run(fails_once, [Task(f"t{i}", (i, marker))
                                                    for i in range(3)])
    assert [o.value for o in outs] == [0, 1, 2] and all(o.ok for o in outs)
    assert retry_lines(outs) == ["t1: RuntimeError: flaky (succeeded on attempt 2)"]


def test_workers_of_a_driver_killed_outright_leave_and_clean_up(tmp_path):
    """SIGKILL of the driver alone (no shutdown of the pool): the workers, mid-task, stop
    their tasks as SIGTERM does (no partial output left) and leave; they waited for the
    next task forever, deaf to SIGTERM."""
    proc, out = _driver_mid_write(tmp_path)
    try:
        pids = [int((out / f"pid-{i}").read_text()) for i in range(2)]
        proc.kill()
        proc.wait(timeout=60)
    finally:
        proc.kill()
    deadline = time.monotonic() + 30
    while not all(_gone(p) for p in pids) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert all(_gone(p) for p in pids)
    assert sorted(p.name for p in out.iterdir()) == ["pid-0", "pid-1"]


def test_a_port_that_answers_but_is_no_ray_cluster_is_one_line(tmp_path, monkeypatch):
    """Something listens (a dashboard port given for the cluster's): Ray's own connection
    error was a traceback, and `golden check` then exited 1, "changed"."""
    pytest.importorskip("ray")
    import ray

    def refuse(*_a, **_k):  # noqa: ANN202 - what Ray raises when no GCS answers
        raise ConnectionError("Failed to connect to Ray cluster at 127.0.0.1:1\nmore")

    monkeypatch.setattr(ray, "init", refuse)
    with socket.socket() as s:  # accepts connections, speaks no Ray
        s.bind(("127.0.0.1", 0))
        s.listen()
        port = s.getsockname()[1]
        with pytest.raises(ExecutorError) as e:
            make_executor("ray", 1, address=f"127.0.0.1:{port}").connect()
    text = str(e.value)
    assert "\n" not in text and f"127.0.0.1:{port}: no Ray cluster answers there" in text
    assert "port 6379" in text


def test_a_web_server_given_as_the_ray_address_is_one_line_and_quick(tmp_path):
    """Ray's dashboard port (a web server) given for the cluster's: `ray.init` waited for
    minutes there and ignored SIGTERM; the reachability check now knows a web server."""
    import http.server
    import threading

    server = http.server.HTTPServer(("127.0.0.1", 0), http.server.SimpleHTTPRequestHandler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    try:
        port = server.server_address[1]
        with pytest.raises(ExecutorError) as e:
            check_reachable(f"127.0.0.1:{port}")
    finally:
        server.shutdown()
    text = str(e.value)
    assert "\n" not in text and "a web server answers there, not a Ray cluster" in text
    with socket.socket() as s:  # a server that says nothing (a GCS waiting for gRPC) passes
        s.bind(("127.0.0.1", 0))
        s.listen()
        check_reachable(f"127.0.0.1:{s.getsockname()[1]}", timeout_s=0.5)
