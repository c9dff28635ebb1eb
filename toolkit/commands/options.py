"""Option parsing shared by the commands (one wording everywhere); the one output check
(:func:`check_output`, :func:`check_log_output`) is :mod:`sgtool.output_check`, named here
too."""

from __future__ import annotations

import difflib
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TypeVar

import click

from sgtool.errors import SgtoolError
from sgtool.output_check import check_log_output as check_log_output
from sgtool.output_check import check_output as check_output

F = TypeVar("F", bound=Callable[..., Any])


class FiniteFloatRange(click.FloatRange):
    """:class:`click.FloatRange` that refuses ``nan`` and ``inf`` (a NaN passes every
    bound check, so ``--tolerance nan`` would read as no tolerance at all); the type of
    the commands' float options (:data:`FINITE_FLOAT` without bounds), but for the import
    commands', which check theirs with messages that say what to give."""

    def convert(self, value: Any, param: click.Parameter | None,
                ctx: click.Context | None) -> Any:
        rv = super().convert(value, param, ctx)
        if not math.isfinite(rv):
            self.fail(f"{value!r} is not a finite number.", param, ctx)
        return rv

    def _describe_range(self) -> str:
        return super()._describe_range() if (self.min, self.max) != (None, None) else ""

    def get_metavar(self, param: click.Parameter, ctx: click.Context | None = None) -> str:
        return "FLOAT" if (self.min, self.max) == (None, None) else "FLOAT RANGE"


FINITE_FLOAT = FiniteFloatRange()
# the type of every seed option: a house seed and its offsets stay within numpy's int64
SEED = click.IntRange(min=0, max=2**62)


class PathParam(click.Path):
    """:class:`click.Path` that refuses an empty value (``Path("")`` is the working folder,
    so ``-o ''`` would write there and ``info ''`` would read it); the type of every path
    option and argument of the commands."""

    def convert(self, value: Any, param: click.Parameter | None,
                ctx: click.Context | None) -> Any:
        if isinstance(value, str) and value == "":
            self.fail("an empty path.", param, ctx)
        return super().convert(value, param, ctx)


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
    """A planner option value without a known field: int, float, true/false, else the text
    (:func:`sgtool.planning.option_fields.parse_text`)."""
    from sgtool.planning.option_fields import parse_text

    return parse_text(text)


DEFAULT_ROOMS_TEXT = "4-12"  # --rooms of a house generated with --seed


def house_from_options(path: str | None, seed: int | None, rooms: str,
                       preset: str = "default") -> tuple[Any, str]:
    """(HouseSpec, house id) of ``--house``, ``--seed`` (with ``--rooms`` and ``--preset``)
    or the demo house shipped with sgtool; both given is an error."""
    if path is not None and seed is not None:
        raise SgtoolError("give either --house or --seed, not both")
    parsed = parse_rooms(rooms)  # a bad range is an error, with or without --seed
    for flag, value, default in (("--rooms", rooms, DEFAULT_ROOMS_TEXT),
                                 ("--preset", preset, "default")):
        if seed is None and value != default:
            raise SgtoolError(f"{flag} {value}: for a house generated with --seed; give "
                              "--seed N as well")
    if path is not None:
        from sgtool.house.io import house_file_id, load_house

        # a path, even one starting with "{"; named as bench names it (its "id", else stem)
        return load_house(Path(path)), house_file_id(path)
    if seed is not None:
        from sgtool.datasets.generator import generate_house

        return generate_house(seed, rooms=parsed, preset=preset), f"house-{seed}"
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
    """``--house``, ``--seed``, ``--rooms`` and ``--preset`` (for :func:`house_from_options`);
    the help of ``--seed`` and ``--rooms`` says what the command does with the house."""
    from sgtool.datasets.presets import PRESET_NAMES

    return option_group([
        click.option("--house", "house_path", type=PathParam(dir_okay=False),
                     help="House spec (JSON, see `sgtool scenes`). Default: the demo house "
                     "shipped with sgtool, unless --seed is given."),
        click.option("--seed", type=SEED, default=None,
                     help=seed_help),
        click.option("--rooms", default=DEFAULT_ROOMS_TEXT, show_default=True,
                     metavar="MIN-MAX",
                     help=rooms_help),
        click.option("--preset", type=click.Choice(list(PRESET_NAMES)),
                     default="default", show_default=True,
                     help="Generator preset of a house generated with --seed: 'symsearch' "
                     "for houses as dense as SymSearch's scenes (`sgtool scenes generate`)."),
    ])


def llm_log_options(transcript_help: str, many: bool = False) -> Callable[[F], F]:
    """moma-llm's ``--llm-replay``/``--llm-transcript``; ``many``: replay from many, folders too."""
    replay = click.option(
        "--llm-replay", type=PathParam(), multiple=True,
        help="moma-llm: serve answers from these transcripts (JSONL, or MCAP logs' "
        "/sgtool/llm; repeatable; a folder: its *.mcap logs and *.jsonl transcripts, as "
        "`--log-dir` writes them) instead of an endpoint.") if many else click.option(
        "--llm-replay", type=PathParam(dir_okay=False), default=None,
        help="moma-llm: serve answers from this transcript (JSONL, or an MCAP log's "
        "/sgtool/llm) instead of an endpoint.")
    return option_group([
        replay,
        click.option("--llm-transcript", type=PathParam(dir_okay=False), default=None,
                     help=transcript_help),
    ])


@dataclass(frozen=True)
class LlmEndpoint:
    """The LLM option group of a command (:func:`llm_endpoint_options`): what the user
    gave; unset values come from the ``SGTOOL_LLM_*`` environment variables when the client
    is made (:meth:`sgtool.llm.client.LlmSettings.resolve`)."""

    base_url: str | None = None
    model: str | None = None
    api_key: str | None = None
    timeout_s: float | None = None

    def given(self) -> dict[str, Any]:
        """The options given, as LLM planner options (``base_url``, ``model``, ``api_key``,
        ``timeout_s``)."""
        return {k: v for k, v in (("base_url", self.base_url), ("model", self.model),
                                  ("api_key", self.api_key), ("timeout_s", self.timeout_s))
                if v is not None}

    def fill(self, options: dict[str, dict[str, Any]], planners: Sequence[str]) -> None:
        """Give the LLM planners among ``planners`` these endpoint options, unless ``-O``
        set them (``-O moma-llm.base_url=...`` wins); a note when none of them talks to an
        endpoint."""
        given = self.given()
        if not given:
            return
        from sgtool.planning.registry import is_llm_planner

        llm = [p for p in planners if is_llm_planner(p)]
        if not llm:
            click.echo("sgtool: note: no LLM planner is run; the --llm-* endpoint options "
                       "are unused", err=True)
        for p in llm:
            mine = options.setdefault(p, {})
            for k, v in given.items():
                mine.setdefault(k, v)


def llm_endpoint_options(what: str, timeout: float | None = None,
                         timeout_help: str | None = None) -> Callable[[F], F]:
    """The LLM option group: ``--llm-base-url``, ``--llm-model``, ``--llm-api-key``,
    ``--llm-timeout`` (the same flags on every command that talks to an endpoint; read
    with :func:`llm_endpoint`); ``what`` says what they are for, ``timeout`` is the
    command's default (None: the planner's own), ``timeout_help`` replaces the help of
    ``--llm-timeout`` (a command whose timeout means something else)."""
    return option_group([
        click.option("--llm-base-url", default=None, metavar="URL",
                     help=f"{what}: OpenAI-compatible endpoint (`sgtool llm serve` prints "
                     "one) [env SGTOOL_LLM_BASE_URL]."),
        click.option("--llm-model", default=None, help=f"{what}: model name "
                     "[env SGTOOL_LLM_MODEL]."),
        click.option("--llm-api-key", default=None, help=f"{what}: API key, never written "
                     "to an output [env SGTOOL_LLM_API_KEY]."),
        click.option("--llm-timeout", type=FiniteFloatRange(1.0, 3600.0), default=timeout,
                     show_default=timeout is not None,
                     help=timeout_help or (
                         f"{what}: wall-clock seconds per request (connecting, headers and "
                         "body together, a trickled reply included); an LLM planner's "
                         "decision has its own deadline over all its attempts "
                         "(-O moma-llm.decision_timeout_s, 60)"
                         + ("." if timeout is not None else " [default: the planner's, 30]."))),
    ])


def shown_command(argv: Sequence[str]) -> list[str]:
    """``argv`` with the value of ``--llm-api-key`` replaced (a command line written to an
    output never holds the key)."""
    from sgtool.redact import REDACTED

    out = list(argv)
    for i, a in enumerate(out):
        if a == "--llm-api-key" and i + 1 < len(out):
            out[i + 1] = REDACTED
        elif a.startswith("--llm-api-key="):
            out[i] = f"--llm-api-key={REDACTED}"
    return out


def list_planners_option(named_by: str = "--planners") -> Callable[[F], F]:
    """``--list-planners``: print every planner with its summary and options (from their
    dataclasses) and the installed plug-ins, then exit; ``named_by``: the command's option
    that names planners (for the help's example)."""
    def show(ctx: click.Context, param: click.Parameter, value: bool) -> None:
        if not value or ctx.resilient_parsing:
            return
        from sgtool.planning.registry import (
            check_planner_name,
            describe_planners,
            plugin_problem,
        )

        given: list[str] = []  # the planners named (eager options: before, or as given)
        for key in ("planners", "planner"):
            v = ctx.params.get(key)
            for text in (v,) if isinstance(v, str) else (v or ()):
                given += planner_names(text)
        if not given:  # named after --list-planners: not processed yet, so read as given
            for text in _option_values(ctx, ("planners", "planner")):
                given += planner_names(text)
        for name in given:  # a misspelt name is said, as without --list-planners
            check_planner_name(name)
        click.echo(describe_planners(given))
        problem = plugin_problem(given)
        if problem is not None:  # listed with the rest, and the exit says it
            raise SgtoolError(problem)
        ctx.exit(0)

    return click.option("--list-planners", is_flag=True, expose_value=False, is_eager=True,
                        callback=show,
                        help="List the planners, their options (name, type, default, help) "
                        "and the installed plug-ins, then exit; a module:Name plug-in named "
                        f"with it ({named_by} mymod:My --list-planners) with its options.")


# ctx.meta key of the words given to the subcommand (sgtool.cli.LazyGroup)
COMMAND_ARGS = "sgtool.command_args"


def _option_values(ctx: click.Context, names: Sequence[str]) -> list[str]:
    """The values given on the command line to the options of ``ctx``'s command named
    ``names`` (``--opt V``, ``--opt=V``, ``-oV``), from the words the group kept."""
    words = list(ctx.meta.get(COMMAND_ARGS, ()))
    flags = [o for p in ctx.command.params if p.name in names for o in p.opts]
    out = []
    for i, word in enumerate(words):
        if word == "--":
            break
        for flag in flags:
            if word == flag and i + 1 < len(words):
                out.append(words[i + 1])
            elif word.startswith(flag + "="):
                out.append(word[len(flag) + 1:])
            elif len(flag) == 2 and word.startswith(flag) and len(word) > 2:  # -pNAME
                out.append(word[2:])
    return out


PLANNER_OPTION_HELP = ("Planner option PLANNER.KEY=VALUE, e.g. scout.delta=0.2 or "
                       "moma-llm.model=gpt-4o-mini (repeatable; --list-planners lists them; "
                       "a plug-in's: mymod:MyPlanner.k=v; an empty VALUE sets an optional "
                       "number or choice to none).")
# the default of --planners, spelled out for --help (a test keeps it equal to the bench's)
DEFAULT_PLANNERS_HELP = ("random, greedy, sbert-noroom, sbert, scout-noroom, scout-delta0, "
                         "scout, godhs, esc, bayes-search")
PLANNERS_HELP = ("Comma-separated planners to compare; --list-planners shows every one with "
                 f"its options. Default: {DEFAULT_PLANNERS_HELP} (the papers' planners and "
                 "their ablations); bayes-rooms, voi and the LLM planners (moma-llm, "
                 "unstructured-llm, godhs-llm) run when named. ")
PLUGIN_HELP_ONE = ("A planner may be a plug-in: module:Name (a class or factory importable "
                   "from PYTHONPATH, called with its -O options) or a name an installed "
                   "package registers in the entry-point group sgtool.planners.")
PLUGIN_HELP = PLUGIN_HELP_ONE + (" With --executor ray a plug-in's module must be importable "
                                 "on every machine.")


def planner_names(text: str) -> tuple[str, ...]:
    """``--planners A,B,...``: the names, a built-in in any case (``Scout``), a plug-in
    (``module:Name``) as written."""
    from sgtool.planning.registry import PLANNER_NAMES

    names = (p.strip() for p in text.split(",") if p.strip())
    return tuple(p.lower() if p.lower() in PLANNER_NAMES else p for p in names)


def _canonical_planner(name: str) -> str:
    """A planner name as :func:`planner_names` spells it (a built-in in lower case)."""
    return planner_names(name)[0] if name.strip() else name


def reference_planner(ctx: click.Context, param: click.Parameter, value: str | None
                      ) -> str | None:
    """``--reference PLANNER`` spelt as :func:`planner_names` spells ``--planners`` (a
    built-in in any case), so ``--planners SCOUT --reference Scout`` agree."""
    return None if value is None else _canonical_planner(value)


def split_planner_key(key: str, planners: Sequence[str] = ()) -> tuple[str, str]:
    """(planner, option) of ``PLANNER.KEY``: the longest planner of ``planners`` the key
    starts with (``mypkg.mod:Cls.k``), else split at the last '.' when the planner is
    ``module:Name``, else at the first '.'; ("", "") when it is not of that form."""
    key = key.strip()
    hits = [p for p in planners if key.startswith(p + ".") and len(key) > len(p) + 1]
    if hits:
        name = max(hits, key=len)
        return name, key[len(name) + 1:]
    name, dot, opt = key.rpartition(".") if ":" in key else key.partition(".")
    if not dot:
        return "", ""
    return name.strip(), opt.strip()


def planner_options(items: tuple[str, ...], planners: Sequence[str] | None = None,
                    *, typed: bool = True) -> dict[str, dict[str, Any]]:
    """``-O PLANNER.KEY=VALUE`` values (bench, run, run-bench, eval) as {planner: {key:
    value}}, each value checked and converted against the planner's options dataclass (a
    plug-in without one: int, float, true/false or text). With ``planners`` (the run's), an
    option for a name that is no planner is an error (a typo such as ``sout.delta`` would
    otherwise run everything with the defaults), and so is one for a planner not run whose
    name is close to one run (``lab:Labplanner`` for ``lab:LabPlanner``); one for another
    planner not run is a note. ``typed=False`` (a report: plug-ins need not import): a
    plug-in's values as :func:`parse_value` reads them, the plug-in not asked."""
    from sgtool.planning.registry import REGISTRY, check_planner_name, parse_option

    out: dict[str, dict[str, Any]] = {}
    if planners is not None:  # "-p Scout -O SCOUT.delta=..." is one planner
        planners = [_canonical_planner(p) for p in planners]
    for item in items:
        key, eq, value = item.partition("=")
        name, opt = split_planner_key(key, planners or ())
        name = _canonical_planner(name)
        if not eq or not name or not opt.isidentifier():
            raise SgtoolError(f"--planner-option: expected PLANNER.KEY=VALUE, got {item!r}")
        run = planners is None or name in planners
        if not run:
            try:
                check_planner_name(name)
            except SgtoolError:
                raise SgtoolError(f"--planner-option {item!r}: {name!r} is no planner "
                                  f"(those run: {', '.join(planners or ())})") from None
            close = difflib.get_close_matches(name, planners or (), n=1, cutoff=0.8)
            if close:
                raise SgtoolError(f"--planner-option {item!r}: {name!r} is not run; did you "
                                  f"mean {close[0]!r}?")
            click.echo(f"sgtool: note: --planner-option {key.strip()}: {name!r} is not "
                       "run; the option is unused", err=True)
        out.setdefault(name, {})[opt] = parse_option(name, opt, value.strip()) \
            if run and (typed or name in REGISTRY) else parse_value(value.strip())
    return out


def run_planner_options(items: tuple[str, ...], planner: str) -> dict[str, Any]:
    """``-O`` of ``sgtool run`` (one planner): ``PLANNER.KEY=VALUE`` as everywhere; the
    bare ``KEY=VALUE`` of before still works for the planner run, with a note that it is
    deprecated."""
    full = []
    for item in items:
        key, eq, value = item.partition("=")
        if eq and key.strip() and "." not in key and ":" not in key:
            click.echo(f"sgtool: note: -O {key.strip()}=...: write -O "
                       f"{planner}.{key.strip()}=VALUE (the bare KEY=VALUE form is "
                       "deprecated)", err=True)
            item = f"{planner}.{key.strip()}={value}"
        full.append(item)
    return planner_options(tuple(full), (planner,)).get(planner, {})


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


def budget_options(recorded: bool = False) -> Callable[[F], F]:
    """``--distance-budget`` and ``--step-budget``: the budget maxima of the two AUC-E
    variants (MoMa-LLM's; :func:`sgtool.analysis.search_metrics.cost_models`); with
    ``recorded`` (eval) their default is None: the budgets the runs read recorded."""
    tail = " [default: as the runs read were made (bench records it), else {}]" * recorded
    distance = click.option(
        "--distance-budget", type=FiniteFloatRange(min=0, min_open=True),
        default=None if recorded else 5000.0, show_default=not recorded,
        help="AUC-E distance variant budget max, in low-level steps (0.1 m of travel = 1, "
        "an open = 30; MoMa-LLM)." + tail.format(5000))
    steps = click.option(
        "--step-budget", type=FiniteFloatRange(min=0, min_open=True),
        default=None if recorded else 50.0, show_default=not recorded,
        help="AUC-E step variant budget max, in high-level steps." + tail.format(50))
    return lambda f: distance(steps(f))


def explore_on_option() -> Callable[[F], F]:
    """``--explore-on N`` of the closed-loop commands
    (:attr:`sgtool.recorders.sim.closed_loop.ClosedLoopOptions.explore_on`)."""
    return click.option(
        "--explore-on", type=click.IntRange(min=0), default=0, show_default=True,
        metavar="N",
        help="live navigation: after an explore that showed no new object, door or room, "
             "the planner picks among the frontiers only and the robot goes on there, up "
             "to N times, no step each (0: never; a step is then one planner decision, as "
             "in the papers).")


def look_in_option() -> Callable[[F], F]:
    """``--look-in M`` of the closed-loop commands
    (:attr:`sgtool.recorders.sim.live_skills.LiveNavConfig.look_in`)."""
    return click.option(
        "--look-in", type=FiniteFloatRange(0.0, 3.0), default=1.4, show_default=True,
        metavar="M",
        help="live navigation: after opening a container the robot drives to M metres "
             "from it, in front of its opening as its map shows it, and faces it, so the "
             "camera sees what the opening revealed (0: it stays where it opened it; "
             "--look-in-beyond says after which opens).")


def look_in_beyond_option() -> Callable[[F], F]:
    """``--look-in-beyond DEG`` of the closed-loop commands
    (:attr:`sgtool.recorders.sim.live_skills.LiveNavConfig.look_in_beyond`)."""
    return click.option(
        "--look-in-beyond", type=FiniteFloatRange(0.0, 180.0), default=45.0,
        show_default=True, metavar="DEG",
        help="live navigation: look in (--look-in) only after an open made from more "
             "than DEG degrees off the container's front as the robot's map shows it (the "
             "side board hides the inside from there; 0: after every open).")


def peek_option() -> Callable[[F], F]:
    """``--peek/--no-peek`` of the closed-loop commands
    (:attr:`sgtool.recorders.sim.live_skills.LiveNavConfig.peek`)."""
    return click.option(
        "--peek/--no-peek", default=True, show_default=True,
        help="live navigation: after opening a container, or walking up to one that "
             "stands open, the robot tilts its camera down into it and back (a pan-tilt "
             "head; no metres), so the frames show its lower shelves, which the mast's "
             "fixed tilt leaves out of view within reach.")


def sight_lines_option() -> Callable[[F], F]:
    """``--sight-lines/--no-sight-lines`` of the closed-loop commands
    (:attr:`sgtool.recorders.sim.live_skills.LiveNavConfig.sight_lines`)."""
    return click.option(
        "--sight-lines/--no-sight-lines", default=False, show_default=True,
        help="live navigation: a look-around turns only toward unknown space the camera "
             "can see from where the robot stands, past what its own map shows lower "
             "than the camera (a table, a bed) but not past what reaches above it (a "
             "wall, a wardrobe); fewer frames turning, less seen on the way.")


def explore_through_option() -> Callable[[F], F]:
    """``--explore-through M`` of the closed-loop commands
    (:attr:`sgtool.recorders.sim.live_skills.LiveNavConfig.explore_through`)."""
    return click.option(
        "--explore-through", type=FiniteFloatRange(0.0, 5.0), default=0.0,
        show_default=True, metavar="M",
        help="live navigation: an explore that reached its frontier drives M metres on, "
             "straight on from where it set out (through a doorway into the room behind), "
             "before it looks around (0: it looks around at the frontier).")


def render_turn_option() -> Callable[[F], F]:
    """``--render-turn DEG`` of the closed-loop commands
    (:attr:`sgtool.recorders.sim.closed_loop_options.ClosedLoopOptions.turn_render_deg`)."""
    return click.option(
        "--render-turn", "render_turn", type=FiniteFloatRange(0.0, 90.0), default=20.0,
        show_default=True, metavar="DEG",
        help="A tick is rendered, mapped and logged once the camera turned DEG degrees "
             "(or drove 0.25 m, or a share of both) since the last frame; a larger angle "
             "gives fewer frames on the spot, each still overlapping the last (0: every "
             "tick that turns).")


def live_max_depth_option() -> Callable[[F], F]:
    """``--max-depth M`` of the closed-loop commands
    (:attr:`sgtool.recorders.sim.closed_loop_options.ClosedLoopOptions.max_depth`)."""
    return click.option(
        "--max-depth", "max_depth", type=FiniteFloatRange(0.5, 20.0), default=None,
        metavar="M",
        help="Depth farther than this (m) is not mapped by the live map (recorded in the "
             "log: replay maps the same); more than the depth of the nearest floor the camera "
             "sees (1.2 m at its default mounting). Default: 5 (MoMa-LLM's), lowered to where the "
             "sensor's depth noise (--noise depth_sigma, known to the robot like a "
             "datasheet figure) would read far floor as obstacles, as replay does.")


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
