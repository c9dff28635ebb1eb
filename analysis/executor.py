"""Independent tasks on a local process pool or on a Ray cluster, with the same results.

A :class:`Task` is an id and the arguments of one call of a module-level function (so it
pickles by reference and a Ray worker imports it). Tasks must be deterministic and seeded
by what they carry (the benchmark's (seed, house, episode), a log's bytes), never by which
worker runs them or when: then :meth:`run` gives the same outcomes whatever the executor,
the number of workers or the order tasks finish, because it returns them in task order.

- :class:`LocalExecutor`: ``workers == 1`` runs the tasks in this process; more use a pool
  of spawned processes (each imports sgtool once and keeps what it caches between tasks).
- :class:`RayExecutor`: connects to ``address`` (``--ray-address``, else ``RAY_ADDRESS``)
  after checking that something listens there, else starts a local Ray instance with
  ``num_cpus = workers`` (no dashboard, worker logs not forwarded); a Ray instance that is
  already initialised in this process (a test's) is used as it is and left running.

Both keep at most ``2 * workers`` tasks in flight (one in process), advance one progress
bar (tqdm, on stderr) per finished task wherever it ran, retry a task that raised once,
and then give up on it: its :class:`Outcome` carries the error as one line, for the
caller's summary, and the Ray node it ran on (``node``; empty on this machine).

Files a task writes land on the machine that runs it. :class:`FolderMark` tells a task
whether it sees the driver's output folder itself (same machine, same folder), so that it
writes there directly; elsewhere it must send its files back with its value for the
driver to write (what ``run-bench`` does, :mod:`sgtool.analysis.closed_loop_bench_run`).
Ctrl-C cancels the tasks not finished yet and re-raises, so a caller that writes its
outputs from ``on_result`` (atomically) is left with complete outputs only. Pool workers
ignore SIGINT: the driver stops them, on Ctrl-C (to the terminal's whole process group or
to the driver alone) as on a SIGTERM to the driver (turned into
:class:`~sgtool.errors.Terminated` by the CLI), by passing a SIGTERM on to the workers,
whose running tasks then clean up as on Ctrl-C; the driver waits for them
(:data:`STOP_GRACE_S`, then kills what is left), so nothing a task writes outlives it.
"""

from __future__ import annotations

import contextlib
import os
import signal
import socket
import sys
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sgtool.errors import (
    STOP_SIGNALS,
    SgtoolError,
    Terminated,
    raise_terminated,
    set_stop_handlers,
    traceback_text,
)
from sgtool.extras import missing_message

EXECUTORS: tuple[str, ...] = ("local", "ray")
RETRIES = 1  # a task that raised runs once more before it is reported
STOP_GRACE_S = 30.0  # how long stopped workers get to clean up before they are killed


class ExecutorError(SgtoolError):
    """An executor that cannot be used (Ray missing or unreachable, a bad option)."""


@dataclass(frozen=True)
class Task:
    """One call ``fn(args)``; ``id`` names it in the summary and the failure list."""

    id: str
    args: Any


@dataclass(frozen=True)
class Outcome:
    """What a task returned, or its error (one line) after its last attempt."""

    id: str
    value: Any = None
    error: str | None = None
    attempts: int = 1
    node: str = ""  # the Ray node (hex id) of the last attempt; "" on this machine
    retried: str | None = None  # the first attempt's error, when a later attempt ran

    @property
    def ok(self) -> bool:
        return self.error is None


def error_line(e: BaseException) -> str:
    """``Type: first line of the message`` (a Ray task error is unwrapped to its cause);
    the message alone for an :class:`~sgtool.errors.SgtoolError`, which is written for
    the user."""
    cause = getattr(e, "cause", None)
    if isinstance(cause, BaseException):
        e = cause
    text = str(e).strip().splitlines()
    if text and isinstance(e, SgtoolError):
        return text[0]
    return f"{type(e).__name__}: {text[0]}" if text else type(e).__name__


def failure_lines(outcomes: Sequence[Outcome]) -> list[str]:
    """One line per failed task: ``ID: Type: message (after N attempts)``."""
    return [f"{o.id}: {o.error} (after {o.attempts} attempts)" for o in outcomes if not o.ok]


def retry_lines(outcomes: Sequence[Outcome]) -> list[str]:
    """One line per task that succeeded after an error: ``ID: Type: message (succeeded on
    attempt N)`` (a worker lost, or a planner that raises now and then)."""
    return [f"{o.id}: {o.retried} (succeeded on attempt {o.attempts})" for o in outcomes
            if o.ok and o.retried is not None]


class _Executor:
    """Retry, order, progress and Ctrl-C over a submit/wait/cancel back end."""

    name = ""

    def __init__(self, workers: int = 1) -> None:
        if workers < 1:
            raise ExecutorError(f"--workers: must be >= 1, got {workers}")
        self.workers = workers

    def run(self, fn: Callable[[Any], Any], tasks: Sequence[Task], *, progress: bool = False,
            desc: str = "tasks", on_result: Callable[[Outcome], None] | None = None
            ) -> list[Outcome]:
        """Run every task (module doc); outcomes in task order. ``on_result`` sees each
        final outcome as it arrives (finish order)."""
        from tqdm import tqdm

        ids = [t.id for t in tasks]
        if len(set(ids)) != len(ids):
            raise ValueError("task ids must be unique")
        if not tasks:  # nothing to do: no pool, no Ray start-up
            return []
        done: dict[int, Outcome] = {}
        # no bar object at all without progress: tqdm makes a multiprocessing lock even
        # when disabled, which fixes the process's start method for its caller
        with self._session(fn) as backend, tqdm(
                total=len(tasks), desc=desc, unit="task", file=sys.stderr,
                dynamic_ncols=True) if progress else contextlib.nullcontext(_NoBar()) as bar:
            queue = list(range(len(tasks)))[::-1]
            attempts = [0] * len(tasks)
            first_error: dict[int, str] = {}
            traced = False  # a failed task's traceback shown (SGTOOL_TRACEBACK=1)
            flight: dict[Any, int] = {}
            try:
                while queue or flight:
                    while queue and len(flight) < backend.window:
                        i = queue.pop()
                        attempts[i] += 1
                        flight[backend.submit(tasks[i].args)] = i
                    handle, value, err = backend.wait_one(list(flight))
                    i = flight.pop(handle)
                    if isinstance(err, KeyboardInterrupt):  # a worker was killed or Ctrl-C'd
                        raise err  # stop the run, as in process
                    if err is not None and attempts[i] <= RETRIES:
                        first_error.setdefault(i, error_line(err))
                        queue.append(i)
                        continue
                    node = ""
                    if isinstance(value, _Placed):
                        node, value = value.node, value.value
                    shown = None if err is None or traced else traceback_text(err)
                    if shown is not None:  # SGTOOL_TRACEBACK=1: where the first failed raised
                        print(shown, file=sys.stderr)
                        traced = True
                    out = Outcome(tasks[i].id, value, None if err is None else error_line(err),
                                  attempts[i], node, first_error.get(i))
                    done[i] = out
                    if on_result is not None:
                        on_result(out)
                    bar.update(1)
            except BaseException:
                backend.cancel(list(flight))
                raise
        return [done[i] for i in range(len(tasks))]

    def _session(self, fn: Callable[[Any], Any]) -> Any:
        raise NotImplementedError


class _NoBar:
    """What a run counts its tasks on when no progress bar is shown."""

    def update(self, n: int = 1) -> None:
        pass


class _Inline:
    """One task at a time in this process."""

    window = 1  # tasks in flight

    def __init__(self, fn: Callable[[Any], Any]) -> None:
        self.fn = fn
        self.next = 0
        self.results: dict[int, tuple[Any, BaseException | None]] = {}

    def __enter__(self) -> _Inline:
        return self

    def __exit__(self, *exc: object) -> None:
        return None

    def submit(self, args: Any) -> int:
        self.next += 1
        try:
            self.results[self.next] = (self.fn(args), None)
        except Exception as e:  # reported in the outcome, as a worker's would be
            self.results[self.next] = (None, e)
        return self.next

    def wait_one(self, handles: list[int]) -> tuple[int, Any, BaseException | None]:
        h = handles[0]
        value, err = self.results.pop(h)
        return h, value, err

    def cancel(self, handles: list[int]) -> None:
        return None


class _Pool:
    """A pool of spawned processes."""

    def __init__(self, fn: Callable[[Any], Any], workers: int) -> None:
        self.fn = fn
        self.workers = workers
        self.window = 2 * workers
        self.pool = self._new_pool()

    def _new_pool(self) -> Any:
        import multiprocessing as mp
        from concurrent.futures import ProcessPoolExecutor

        return ProcessPoolExecutor(max_workers=self.workers, mp_context=mp.get_context("spawn"),
                                   initializer=_worker_setup)

    def __enter__(self) -> _Pool:
        return self

    def __exit__(self, *exc: object) -> None:
        if exc[0] is None:
            self.pool.shutdown(wait=True)
            return
        # Ctrl-C, a kill or an error: no new tasks, stop the running ones (they clean up
        # their partial outputs), and wait for the workers before the caller removes
        # anything, so no worker writes into a folder after it is gone
        procs = list((getattr(self.pool, "_processes", None) or {}).values())
        self.pool.shutdown(wait=False, cancel_futures=True)
        for proc in procs:
            if proc.is_alive():
                with contextlib.suppress(ProcessLookupError):
                    os.kill(proc.pid, signal.SIGTERM)
        deadline = time.monotonic() + STOP_GRACE_S
        for proc in procs:
            proc.join(max(0.0, deadline - time.monotonic()))
        for proc in procs:
            if proc.is_alive():
                proc.kill()
                proc.join()

    def submit(self, args: Any) -> Any:
        from concurrent.futures.process import BrokenProcessPool

        try:
            return self.pool.submit(_call_in_worker, self.fn, args)
        except BrokenProcessPool:  # a worker died (killed, crashed): a new pool for the rest
            self.pool.shutdown(wait=False, cancel_futures=True)
            self.pool = self._new_pool()
            return self.pool.submit(_call_in_worker, self.fn, args)

    def wait_one(self, handles: list[Any]) -> tuple[Any, Any, BaseException | None]:
        from concurrent.futures import FIRST_COMPLETED, wait

        finished, _ = wait(handles, return_when=FIRST_COMPLETED)
        f = min(finished, key=handles.index)
        err = f.exception()
        return f, (None if err is not None else f.result()), err

    def cancel(self, handles: list[Any]) -> None:
        for f in handles:
            f.cancel()


_IN_TASK = False  # in a pool worker: a task is running
_STOPPING = False  # in a pool worker: the driver sent SIGTERM; queued tasks do not start


def _worker_setup() -> None:
    """In each pool worker: SIGTERM interrupts a running task as Ctrl-C does (its outputs
    are cleaned up) instead of ending the process mid-write; an idle worker ignores it and
    leaves when the pool shuts down (dying would break the pool, which then kills the
    other workers mid-cleanup). SIGINT is ignored: the driver decides (module doc), so a
    task's clean-up is never cut short by a second signal."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    set_stop_handlers(_worker_sigterm)  # a closed terminal reaches the workers too
    threading.Thread(target=_leave_with_the_driver, args=(os.getppid(),), daemon=True,
                     name="sgtool-driver-watch").start()


ORPHAN_GRACE_S = 30.0  # a running task's clean-up time once the driver is gone


def _leave_with_the_driver(driver: int) -> None:
    """A worker whose driver died without shutting the pool down (SIGKILL, a crash) would
    wait for tasks forever, deaf to SIGTERM while idle: once its parent is another process,
    a running task is stopped as SIGTERM stops it (its outputs cleaned up), and the worker
    leaves."""
    while os.getppid() == driver:
        time.sleep(1.0)
    if _IN_TASK:
        os.kill(os.getpid(), signal.SIGTERM)
        end = time.monotonic() + ORPHAN_GRACE_S
        while _IN_TASK and time.monotonic() < end:
            time.sleep(0.1)
    os._exit(1)


def _worker_sigterm(signum: int, frame: object) -> None:
    global _STOPPING
    _STOPPING = True
    if _IN_TASK:
        raise_terminated(signum, frame)


def _call_in_worker(fn: Callable[[Any], Any], args: Any) -> Any:
    global _IN_TASK
    if _STOPPING:  # a task the pool had queued before the stop: it must not write anything
        raise Terminated
    _IN_TASK = True
    try:
        return fn(args)
    finally:
        _IN_TASK = False


class LocalExecutor(_Executor):
    """This process (``workers == 1``) or a pool of spawned processes."""

    name = "local"

    def _session(self, fn: Callable[[Any], Any]) -> Any:
        return _Inline(fn) if self.workers == 1 else _Pool(fn, self.workers)


@dataclass(frozen=True)
class _Placed:
    """A Ray task's value and the node it ran on (unwrapped into the :class:`Outcome`)."""

    node: str
    value: Any


def _ray_call(fn: Callable[[Any], Any], args: Any) -> _Placed:
    import ray

    return _Placed(ray.get_runtime_context().get_node_id(), fn(args))


def machine_id() -> str:
    """This machine: its host name and, on Linux, its boot id (two containers of one host
    share the boot id but not, in general, their folders: :class:`FolderMark` also compares
    the folder itself). ``SGTOOL_MACHINE_ID``, when set, stands for it: a Ray node started
    with it set to another value acts as a machine of its own (it sends its files back)."""
    if os.environ.get("SGTOOL_MACHINE_ID"):
        return os.environ["SGTOOL_MACHINE_ID"]
    try:
        boot = Path("/proc/sys/kernel/random/boot_id").read_text().strip()
    except OSError:
        boot = ""
    return f"{socket.gethostname()}/{boot}"


@dataclass(frozen=True)
class FolderMark:
    """A folder of the driver, as a task elsewhere can recognise it: the machine and the
    folder's (device, inode). :meth:`here` is True only where the path names that very
    folder: on the driver's machine (any process or Ray node there). On another machine it
    is False even when the folder is shared (NFS): such a task sends its files back."""

    path: str
    machine: str
    device: int
    inode: int

    @classmethod
    def of(cls, path: str | os.PathLike[str]) -> FolderMark:
        st = os.stat(path)
        return cls(os.fspath(Path(path).absolute()), machine_id(), st.st_dev, st.st_ino)

    def here(self) -> bool:
        """Whether this process sees the marked folder at ``path``."""
        if machine_id() != self.machine:
            return False
        try:
            st = os.stat(self.path)
        except OSError:
            return False
        return (st.st_dev, st.st_ino) == (self.device, self.inode)


class _RaySession:
    def __init__(self, fn: Callable[[Any], Any], executor: RayExecutor) -> None:
        self.fn = fn
        self.executor = executor
        self.started = False

    def __enter__(self) -> _RaySession:
        ray = import_ray()
        self.started = self.executor.connect()
        self.window = 2 * self.executor.workers
        self.ray = ray
        self.remote = ray.remote(_ray_call).options(num_cpus=1, max_retries=0)
        self.fn_ref = ray.put(self.fn)
        return self

    def __exit__(self, *exc: object) -> None:
        if self.started:
            self.ray.shutdown()

    def submit(self, args: Any) -> Any:
        return self.remote.remote(self.fn_ref, args)

    def wait_one(self, handles: list[Any]) -> tuple[Any, Any, BaseException | None]:
        ready, _ = self.ray.wait(handles, num_returns=1)
        ref = ready[0]
        try:
            return ref, self.ray.get(ref), None
        except Exception as e:  # the task's exception, or a lost worker
            return ref, None, e

    def cancel(self, handles: list[Any]) -> None:
        for ref in handles:
            try:
                self.ray.cancel(ref, force=True)
            except Exception:  # already finished or gone: nothing to cancel
                pass


def import_ray() -> Any:
    """The ``ray`` module, or one line saying how to install it."""
    # Ray's native handler turns SIGTERM into an abort with stack dumps (exit 134, partial
    # outputs left); without it sgtool's own handler cleans up as for Ctrl-C. Ray reads
    # this when it is first imported.
    os.environ.setdefault("RAY_DISABLE_FAILURE_SIGNAL_HANDLER", "1")
    try:
        import ray
    except ImportError:
        raise ExecutorError(missing_message("--executor ray", "ray")) from None
    return ray


def check_reachable(address: str, timeout_s: float = 3.0, given_as: str = "--ray-address"
                    ) -> None:
    """Refuse an address where nothing listens (one line naming where it was ``given_as``),
    rather than let Ray wait for minutes. ``auto`` and ``local`` are Ray's own and are
    passed on unchecked."""
    if address in ("auto", "local"):
        return
    hostport = address.split("://", 1)[-1].rstrip("/")
    host, sep, port = hostport.rpartition(":")
    if not sep or not port.isdecimal() or not host:
        raise ExecutorError(f"{given_as} {address!r}: give HOST:PORT (the head node's "
                            "GCS address, e.g. 10.0.0.5:6379) or ray://HOST:PORT")
    try:
        with socket.create_connection((host, int(port)), timeout=timeout_s) as s:
            web = _speaks_http1(s, timeout_s)
    except OSError as e:
        raise ExecutorError(f"Ray cluster at {address} is not reachable ({e.strerror or e}); "
                            "start one with `ray start --head` there, or leave out "
                            "--ray-address and RAY_ADDRESS to start a local Ray") from None
    if web:
        raise ExecutorError(f"{given_as} {address}: a web server answers there, not a Ray "
                            "cluster (whose GCS speaks gRPC; Ray's dashboard is the web "
                            "server, port 8265 by default); give the head node's GCS address "
                            "(`ray start --head` prints it, port 6379 by default)")


def _speaks_http1(s: socket.socket, timeout_s: float) -> bool:
    """Whether the server on ``s`` answers a plain HTTP/1.0 request as a web server does
    (a Ray GCS, gRPC over HTTP/2, answers with binary frames or not at all; Ray's
    ``ray.init`` at a web server waited minutes and ignored SIGTERM)."""
    try:
        s.settimeout(min(timeout_s, 2.0))
        s.sendall(b"GET / HTTP/1.0\r\n\r\n")
        return s.recv(5) == b"HTTP/"
    except OSError:
        return False


@contextlib.contextmanager
def _sigterm_kept() -> Iterator[None]:
    """``ray.init`` sets a SIGTERM handler of its own (``sys.exit(15)``, which skips the
    cleanup and the one-line message of sgtool's); the handlers of the stop signals there
    before are put back."""
    before = {sig: signal.getsignal(sig) for sig in STOP_SIGNALS}
    try:
        yield
    finally:
        if threading.current_thread() is threading.main_thread():
            for sig, handler in before.items():
                if handler is not None:
                    signal.signal(sig, handler)


class RayExecutor(_Executor):
    """Tasks as Ray tasks (one CPU each) on a cluster or a local Ray instance."""

    name = "ray"

    def __init__(self, workers: int = 1, address: str | None = None) -> None:
        super().__init__(workers)
        self.address = address or os.environ.get("RAY_ADDRESS") or None
        self.given_as = "--ray-address" if address else "RAY_ADDRESS"
        import_ray()  # fail before any work when Ray is missing

    def connect(self) -> bool:
        """Initialise Ray unless it is; True when this call started it (and so must end
        it)."""
        ray = import_ray()
        if ray.is_initialized():
            return False
        os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
        common = dict(log_to_driver=False, configure_logging=False, include_dashboard=False)
        with _sigterm_kept():
            if self.address:
                check_reachable(self.address, given_as=self.given_as)
                try:
                    ray.init(address=self.address, **common)
                except ConnectionError as e:  # something listens there, but no Ray GCS
                    raise ExecutorError(
                        f"{self.given_as} {self.address}: no Ray cluster answers there "
                        f"({str(e).splitlines()[0]}); give the head node's GCS address "
                        "(`ray start --head` prints it, port 6379 by default)") from None
                self.workers = max(self.workers, int(ray.cluster_resources().get("CPU", 1)))
            else:
                ray.init(address="local", num_cpus=self.workers, **common)
        return True

    def _session(self, fn: Callable[[Any], Any]) -> Any:
        return _RaySession(fn, self)


Executor = LocalExecutor | RayExecutor


def make_executor(name: str, workers: int = 1, address: str | None = None) -> Executor:
    """The executor of ``--executor NAME`` (``--ray-address`` only with ``ray``): "local"
    (``workers`` processes; 1: in this process) or "ray"; the ``executor=`` of
    :func:`~sgtool.pin_logs` and :func:`~sgtool.check_pins`."""
    if name == "local":
        if address:
            raise ExecutorError("--ray-address needs --executor ray")
        return LocalExecutor(workers)
    if name == "ray":
        return RayExecutor(workers, address)
    raise ExecutorError(f"--executor: one of {', '.join(EXECUTORS)}, got {name!r}")


def chunks(items: Sequence[Any], parts: int) -> Iterator[tuple[Any, ...]]:
    """``items`` cut into ``parts`` contiguous runs of near-equal length (none empty)."""
    parts = max(1, min(parts, len(items)))
    size, extra = divmod(len(items), parts)
    start = 0
    for k in range(parts):
        end = start + size + (k < extra)
        yield tuple(items[start:end])
        start = end
