"""Checks of a benchmark's planners (symbolic or closed loop) and of the options given
to them, before any episode runs: one :class:`BenchError` line each.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from sgtool.arg_checks import number, whole
from sgtool.errors import SgtoolError


class BenchError(SgtoolError):
    """A benchmark option that cannot work (unknown planner, bad range, missing transcript)."""


def config_names(value: Any, field: str, paths: bool = False) -> tuple[Any, ...]:
    """A config's list field as a tuple: one name (a string, a path) is a list of one, not
    of letters; a set is refused (no order: tables and digests would vary); ``paths``:
    each item as text in one spelling (:func:`sgtool.files.path_text`)."""
    import os

    from sgtool.files import path_text

    if isinstance(value, set | frozenset):
        raise BenchError(f"{field}: give a list or tuple (a set has no order)")
    items = (value,) if isinstance(value, str | os.PathLike) else tuple(value)
    if not paths:
        return items
    for x in items:
        if not isinstance(x, str | os.PathLike):
            hint = " (save it with sgtool.save_house and give the file)" \
                if type(x).__name__ == "HouseSpec" else ""
            raise BenchError(f"{field}: give paths of house files or folders, got a "
                             f"{type(x).__name__}{hint}")
    return tuple(path_text(x) for x in items)


def config_planner_options(value: Any) -> dict[str, dict[str, Any]]:
    """A config's ``planner_options`` copied, with the containers in values (a caller's
    dict changed for the next run must not change this one's): planner name -> {option:
    value}; anything else one line."""
    if not isinstance(value, Mapping):
        raise BenchError(f"planner_options: give {{planner: {{option: value}}}}, got a "
                         f"{type(value).__name__}")
    out: dict[str, dict[str, Any]] = {}
    for k, v in value.items():
        if not isinstance(v, Mapping):
            raise BenchError(f"planner_options[{k!r}]: give {{option: value}}, got "
                             f"{v!r}")
        out[str(k)] = {name: _own_copy(x) for name, x in v.items()}
    return out


def recorded_planner_options(planner_options: Mapping[str, Mapping[str, Any]]
                             ) -> dict[str, dict[str, str]]:
    """A run's planner options as its settings record them: each value as the planner
    takes it (:func:`sgtool.planning.registry.typed_options`: ``-O`` text and Python give
    the same record), redacted and as text (:func:`sgtool.redact.options_as_text`)."""
    from sgtool.planning.registry import typed_options
    from sgtool.redact import options_as_text

    return options_as_text({p: typed_options(p, o) for p, o in planner_options.items()})


def _own_copy(value: Any) -> Any:
    """An option's value with its containers copied (a dict or list of a Python-only option
    changed by the caller afterwards must not change the run); anything else in it as
    given: a client, an encoder or a callback is the caller's object, to be used as such."""
    if isinstance(value, dict):
        return {k: _own_copy(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_own_copy(v) for v in value]
    if isinstance(value, tuple):
        return tuple(_own_copy(v) for v in value)
    if isinstance(value, set):
        return {_own_copy(v) for v in value}
    return value


def check_reference(reference: str | None, all_pairs: bool, planners: Sequence[str]) -> None:
    """``--reference`` and ``--all-pairs`` of a benchmark: one of them, and a reference
    that is one of ``planners``."""
    if reference is not None and all_pairs:
        raise BenchError("--reference and --all-pairs: give one (all pairs compare every "
                         "planner with every other, the reference among them)")
    if reference is not None and reference not in planners:
        raise BenchError(f"--reference: {reference!r} is not one of --planners "
                         f"({', '.join(planners)})")


def config_rooms(value: Any) -> tuple[int, int]:
    """A config's ``rooms``: (MIN, MAX), a list from a JSON file taken as a pair."""
    if isinstance(value, str | int) or len(tuple(value)) != 2:
        raise BenchError(f"rooms: give (MIN, MAX), got {value!r}")
    lo, hi = tuple(value)
    return lo, hi


def check_planner_list(planners: Sequence[str]) -> None:
    """``--planners`` of a benchmark (symbolic or closed loop): at least one, each a
    built-in planner, a registered plug-in or ``module:Name``
    (:func:`sgtool.planning.registry.check_planner_name`), no two writing their logs into
    one folder (:func:`~sgtool.planning.registry.planner_file_name`)."""
    from sgtool.planning.registry import check_planner_name, planner_file_name

    if not planners:
        raise BenchError("--planners: name at least one planner")
    folders: dict[str, str] = {}
    for p in planners:
        if not isinstance(p, str):  # a planner object, from Python: runs need its name
            raise BenchError(f"--planners: a {type(p).__name__} object, not a name; a run "
                             "builds its planners in each worker by name: give yours as "
                             "module:Name (a class on sys.path), with its options in "
                             "planner_options")
        try:
            check_planner_name(p)
        except SgtoolError as e:
            raise BenchError(f"--planners: {e}") from None
        other = folders.setdefault(planner_file_name(p), p)
        if other != p:
            raise BenchError(f"--planners: {other!r} and {p!r} would share the log folder "
                             f"{planner_file_name(p)!r}")


def check_planner_options(planners: Sequence[str], options: Mapping[str, Mapping[str, Any]],
                          one_writer: bool) -> None:
    """Options only for planners run (a typo from Python is otherwise silent), and
    moma-llm's transcripts: a replayed one that exists, a written one with one writer
    (``one_writer``: one worker on the local executor)."""
    llm_files = {"replay", "transcript"} & set(options.get("moma-llm", {}))
    if llm_files and "moma-llm" not in planners:
        raise BenchError("--llm-replay and --llm-transcript are for moma-llm: add it to "
                         "--planners")
    for name in sorted(set(options) - set(planners)):  # a typo
        raise BenchError(f"planner_options: {name!r} is not one of the planners run "
                         f"({', '.join(planners)})")
    if "moma-llm" in planners:
        opts = options.get("moma-llm", {})
        replay = opts.get("replay")
        read = [replay] if isinstance(replay, str | Path) else list(replay or ())
        for r in read:
            if not Path(r).is_file():
                raise BenchError(f"--llm-replay: no such transcript {r}")
        written = opts.get("transcript")
        if written and any(Path(r).resolve() == Path(written).resolve() for r in read):
            raise BenchError(f"--llm-transcript {written}: it is the --llm-replay transcript "
                             "(a run's transcript is emptied when it starts)")
        if opts.get("transcript") and not one_writer:
            raise BenchError("--llm-transcript needs --workers 1 and the local executor "
                             "(one file, one writer)")


def check_plugins_build(planners: Sequence[str], options: Mapping[str, Mapping[str, Any]]
                        ) -> None:
    """Build each plug-in planner once with its options, so one that cannot be imported
    or built is one line before any episode runs (the built-ins' options are checked by
    their fields, and built where they run)."""
    from sgtool.planning.registry import PLANNER_NAMES, make_planner

    for name in planners:
        if name.strip().lower() not in PLANNER_NAMES:
            make_planner(name, **options.get(name, {}))


MAX_SEED = 2**62  # the largest seed `sgtool run --seed` and `scenes generate --seed` take


def check_house_seeds(house_seed: int, houses: int) -> None:
    """Generated houses take seeds ``house_seed`` .. ``house_seed + houses - 1``: each must
    be one `sgtool run --seed` takes again (one line otherwise)."""
    whole("house_seed", house_seed)
    if houses > 0 and not 0 <= house_seed <= MAX_SEED - houses + 1:
        raise BenchError(f"--house-seed {house_seed} with --houses {houses}: the houses' seeds "
                         f"must lie in 0..{MAX_SEED} (the seeds `sgtool run --seed` takes)")


def check_budgets(distance_budget: Any, step_budget: Any) -> None:
    """The AUC-E budgets: finite numbers above 0 (one line naming the flag)."""
    for flag, name, value in (("--distance-budget", "distance_budget", distance_budget),
                              ("--step-budget", "step_budget", step_budget)):
        checked = number(name, value)  # (a wrong type or NaN: number's line)
        if checked is None or checked <= 0:
            raise BenchError(f"{flag} ({name}=): must be > 0, got {value:g}")
