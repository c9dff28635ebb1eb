"""Option parsing and output checks shared by the commands (one wording everywhere)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, TypeVar

import click

from sgtool.errors import SgtoolError

F = TypeVar("F", bound=Callable[..., Any])


def parse_rooms(text: str, option: str = "--rooms", lo_limit: int = 4,
                hi_limit: int | None = None) -> tuple[int, int]:
    """A room-count range: ``N``, ``MIN-MAX`` or ``MIN,MAX`` (at most the generator's
    :data:`~sgtool.datasets.generator.MAX_ROOMS` unless ``hi_limit`` says otherwise)."""
    if hi_limit is None:
        from sgtool.datasets.generator import MAX_ROOMS

        hi_limit = MAX_ROOMS
    parts = text.replace(",", "-").split("-")
    try:
        if len(parts) == 1:
            lo = hi = int(parts[0])
        elif len(parts) == 2:
            lo, hi = int(parts[0]), int(parts[1])
        else:
            raise ValueError
    except ValueError:
        raise SgtoolError(f"{option} {text!r}: give N or MIN-MAX, e.g. 4-12") from None
    if not lo_limit <= lo <= hi <= hi_limit:
        raise SgtoolError(f"{option} {text!r}: need {lo_limit} <= MIN <= MAX <= {hi_limit}")
    return lo, hi


def check_output(path: str | Path, *, force: bool = False, option: str = "-o",
                 suffixes: Sequence[str] = (), what: str = "output") -> Path:
    """An output file name a command may write: its folder exists, it is not a folder, it
    has one of ``suffixes`` (when given), and it does not exist unless ``force``."""
    p = Path(path)
    if p.is_dir():
        raise SgtoolError(f"{option} {p} is a folder; give a file name")
    if suffixes and p.suffix.lower() not in suffixes:
        raise SgtoolError(f"{option} {p}: the {what} must end in {' or '.join(suffixes)}")
    if not p.parent.exists():
        raise SgtoolError(f"{option} {p}: folder {p.parent} does not exist")
    if p.exists() and not force:
        raise SgtoolError(f"{p} exists; not overwriting it (use --force)")
    return p


def parse_resolution(text: str, option: str = "--resolution") -> tuple[int, int]:
    """``WIDTHxHEIGHT``."""
    w, sep, h = text.lower().partition("x")
    try:
        if not sep:
            raise ValueError
        return int(w), int(h)
    except ValueError:
        raise SgtoolError(f"{option} {text!r}: give WIDTHxHEIGHT, e.g. 320x240") from None


def parse_value(text: str) -> Any:
    """A planner option value: int, float, true/false, else the text."""
    for cast in (int, float):
        try:
            return cast(text)
        except ValueError:
            pass
    if text.lower() in ("true", "false"):
        return text.lower() == "true"
    return text


def house_from_options(path: str | None, seed: int | None, rooms: str) -> tuple[Any, str]:
    """(HouseSpec, house id) of ``--house``, ``--seed`` (with ``--rooms``) or the demo
    house shipped with sgtool; both given is an error."""
    if path is not None and seed is not None:
        raise SgtoolError("give either --house or --seed, not both")
    if path is not None:
        from sgtool.house.io import load_house

        return load_house(Path(path)), Path(path).stem  # a path, even one starting with "{"
    if seed is not None:
        from sgtool.datasets.generator import generate_house

        return generate_house(seed, rooms=parse_rooms(rooms)), f"house-{seed}"
    from sgtool.datasets import demo_house

    return demo_house(), "demo"


def with_starts(house: Any, label: str) -> Any:
    """``house`` with start poses: a hand-made house without ``starts`` gets one per
    reachable room, as `sgtool bench` gives it; none possible is an error naming
    ``label`` (the house file)."""
    if house.starts:
        return house
    from sgtool.datasets.start_poses import with_start_poses

    house = with_start_poses(house, house.seed)
    if not house.starts:
        raise SgtoolError(f"{label}: starts: none given, and none can be made (no free floor "
                          "reachable from the first room); add a \"starts\" entry")
    return house


def option_group(options: Sequence[Callable[[F], F]]) -> Callable[[F], F]:
    """One decorator of several click options, listed in ``--help`` in the order given."""
    def decorate(f: F) -> F:
        for opt in reversed(options):
            f = opt(f)
        return f
    return decorate


def house_options(seed_help: str, rooms_help: str) -> Callable[[F], F]:
    """``--house``, ``--seed`` and ``--rooms`` (for :func:`house_from_options`); the help of
    ``--seed`` and ``--rooms`` says what the command does with the house."""
    return option_group([
        click.option("--house", "house_path", type=click.Path(dir_okay=False),
                     help="House spec (JSON, see `sgtool scenes`). Default: the demo house "
                     "shipped with sgtool, unless --seed is given."),
        click.option("--seed", type=int, default=None, help=seed_help),
        click.option("--rooms", default="4-12", show_default=True, metavar="MIN-MAX",
                     help=rooms_help),
    ])


def llm_log_options(transcript_help: str) -> Callable[[F], F]:
    """``--llm-replay`` and ``--llm-transcript`` of the moma-llm planner."""
    return option_group([
        click.option("--llm-replay", type=click.Path(dir_okay=False), default=None,
                     help="moma-llm: serve answers from this JSONL transcript instead of an "
                     "endpoint."),
        click.option("--llm-transcript", type=click.Path(dir_okay=False), default=None,
                     help=transcript_help),
    ])


def planner_options(items: tuple[str, ...], planners: Sequence[str] | None = None
                    ) -> dict[str, dict[str, Any]]:
    """``-O PLANNER.KEY=VALUE`` values (bench, run-bench, eval) as {planner: {key: value}};
    with ``planners`` (the run's), an option for a name that is no planner is an error (a
    typo such as ``sout.delta`` would otherwise run everything with the defaults), one for
    a planner not run a note."""
    out: dict[str, dict[str, Any]] = {}
    for item in items:
        key, eq, value = item.partition("=")
        name, dot, opt = key.partition(".")
        if not eq or not dot or not name or not opt:
            raise SgtoolError(f"--planner-option: expected PLANNER.KEY=VALUE, got {item!r}")
        if planners is not None and name.strip() not in planners:
            from sgtool.planning.registry import PLANNER_NAMES

            if name.strip() not in PLANNER_NAMES:
                raise SgtoolError(f"--planner-option {item!r}: {name.strip()!r} is no planner "
                                  f"(those run: {', '.join(planners)})")
            click.echo(f"sgtool: note: --planner-option {key.strip()}: {name.strip()!r} is not "
                       "run; the option is unused", err=True)
        out.setdefault(name.strip(), {})[opt.strip()] = parse_value(value.strip())
    return out


def key_value_options(items: tuple[str, ...]) -> dict[str, Any]:
    """``-O KEY=VALUE`` values of one planner (run) as {key: value}."""
    out: dict[str, Any] = {}
    for item in items:
        key, eq, value = item.partition("=")
        if not eq or not key.strip():
            raise SgtoolError(f"-O {item!r}: expected KEY=VALUE, e.g. -O delta=0.2")
        out[key.strip()] = parse_value(value.strip())
    return out


def success_option(recorded: bool = False) -> Callable[[F], F]:
    """``--success observed|done``: the success rule of an episode
    (:func:`sgtool.planning.episode.search_success`); ``recorded``: no default (judge
    recorded episodes as they were recorded)."""
    return click.option(
        "--success", type=click.Choice(["observed", "done"]),
        default=None if recorded else "observed", show_default=not recorded,
        help="Success rule: 'observed' (SymSearch: the target comes into view) or 'done' "
             "(MoMa-LLM: the planner must then call done() on it; a wrong done() fails)"
             + (" [default: as recorded]." if recorded else "."))


def executor_options(what: str) -> Callable[[F], F]:
    """``--executor local|ray``, ``--workers/-w N`` and ``--ray-address`` of the batch
    commands (:func:`sgtool.analysis.executor.make_executor`); ``what`` names the tasks."""
    return option_group([
        click.option("--executor", type=click.Choice(["local", "ray"]), default="local",
                     show_default=True,
                     help=f"Where the {what} run: 'local' (this machine: -w worker "
                     "processes) or 'ray' (a Ray cluster at --ray-address or RAY_ADDRESS, "
                     "else a local Ray instance with -w CPUs; needs "
                     "pip install 'sgtool[ray]'). The results do not depend on it."),
        click.option("--workers", "-w", type=click.IntRange(min=1), default=1,
                     show_default=True,
                     help="Worker processes (local), or CPUs of a local Ray instance "
                     "(results do not depend on it)."),
        click.option("--ray-address", default=None, metavar="HOST:PORT",
                     help="Ray cluster to use with --executor ray (the head's address, "
                     "as `ray start --head` prints it) [default: RAY_ADDRESS, else a local "
                     "Ray instance]."),
    ])
