"""The options a `sgtool run-bench` run was made with, kept in its output folder
(:data:`~sgtool.analysis.closed_loop_bench_run.RUN_OPTIONS_FILE`), so ``--report-only``
tables the run as it was made without the user giving its options again.

Recorded: every option that decides which episodes run and how (planners, houses,
episodes, noise, the closed loop's settings, -O). Not recorded: the report settings
(``REPORT``, taken from the command line each time), how the run is executed
(``EXECUTION``) and the LLM API key (a secret)."""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import fields, replace
from pathlib import Path
from types import UnionType
from typing import Any, TypeVar, Union, get_args, get_origin, get_type_hints

import click
from click.core import ParameterSource

from sgtool.errors import SgtoolError

REPORT = frozenset({"reference", "all_pairs", "budgets", "distance_budget", "step_budget",
                    "symbolic_dir", "with_symbolic"})
EXECUTION = frozenset({"out_dir", "report_only", "progress", "force", "executor", "workers",
                       "ray_address", "llm_api_key"})
FORMAT = 1

A = TypeVar("A")


def recorded_options(args: Any) -> dict[str, Any]:
    """The run-defining options of ``args`` (a dataclass of the command's parameters), as
    JSON values; house files as absolute paths (a report may run from another folder)."""
    out = {f.name: _json(getattr(args, f.name)) for f in fields(args)
           if f.name not in REPORT | EXECUTION}
    if isinstance(out.get("house_files"), list):
        out["house_files"] = [str(Path(p).resolve()) for p in out["house_files"]]
    return out


def options_text(args: Any) -> str:
    """The file's text for ``args``."""
    return json.dumps({"format": FORMAT, "options": recorded_options(args)}, indent=1,
                      sort_keys=True) + "\n"


def as_recorded(args: A, path: Path) -> A:
    """``args`` with the run-defining options the run in ``path`` was made with, except
    those given on the command line (a selection such as ``--planners random``; a setting
    the logs were not run with is refused by the resume check). ``path`` absent: ``args``
    as given (a folder of an older sgtool)."""
    if not path.is_file():
        return args
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
        saved = data["options"]
        if data.get("format") != FORMAT or not isinstance(saved, Mapping):
            raise ValueError
    except (OSError, ValueError, KeyError, TypeError):
        raise SgtoolError(f"{path}: not the run options sgtool writes; delete it and give "
                          "the options the run was made with") from None
    _check_types(type(args), saved, path)
    ctx = click.get_current_context(silent=True)
    now = {f.name: getattr(args, f.name) for f in fields(args)}  # type: ignore[arg-type]
    recorded = recorded_options(args).keys()
    changes = {n: tuple(v) if isinstance(now[n], tuple) and isinstance(v, list) else v
               for n, v in saved.items() if n in recorded
               and (ctx is None or ctx.get_parameter_source(n) is not
                    ParameterSource.COMMANDLINE)}
    return replace(args, **changes)  # type: ignore[type-var]


def _check_types(kind: type, saved: Mapping[str, Any], path: Path) -> None:
    """Each recorded value is of its option's type (a file edited by hand: one line)."""
    hints = get_type_hints(kind)
    for name, value in saved.items():
        if name not in hints:
            continue
        allowed = get_args(hints[name]) if get_origin(hints[name]) in (Union, UnionType) \
            else (hints[name],)
        kinds = tuple(list if get_origin(t) is tuple else (get_origin(t) or t)
                      for t in allowed)
        kinds += (int,) if float in kinds else ()
        ok = isinstance(value, kinds) and not (isinstance(value, bool) and bool not in kinds)
        if not ok:
            raise SgtoolError(f"{path}: {name} is {json.dumps(value)}, not a value of that "
                              "option; delete the file and give the options the run was "
                              "made with")


def _json(value: Any) -> Any:
    return list(value) if isinstance(value, tuple) else value
