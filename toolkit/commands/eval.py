
"""``sgtool eval``: metrics from recorded episodes; planners evaluated against logged decisions.

The work is in :mod:`sgtool.analysis.eval_run`; this module checks the options, the output
and the inputs into an :class:`~sgtool.analysis.eval_run.EvalRequest`, writes the -o file
and prints the result."""

from __future__ import annotations

import contextlib
import os
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from sgtool.commands.options import (
    PLANNER_OPTION_HELP,
    PLUGIN_HELP,
    LlmEndpoint,
    PathParam,
    budget_options,
    executor_options,
    list_planners_option,
    llm_endpoint_options,
    reference_planner,
    success_option,
)
from sgtool.errors import SgtoolError

if TYPE_CHECKING:
    from sgtool.analysis.eval_run import EvalRequest


@click.command("eval")
@click.argument("inputs", nargs=-1, required=True, type=PathParam())
@click.option("-p", "--planner", "planners", multiple=True, metavar="NAME[,NAME]",
              is_eager=True,
              help="Also ask these planners at every logged decision point (MCAP logs with "
                   "scene graphs) and compare their choices with what was done (repeatable "
                   "or comma-separated). " + PLUGIN_HELP)
@list_planners_option("--planner")
@click.option("-O", "--planner-option", "planner_option", multiple=True, metavar="P.KEY=VALUE",
              help=PLANNER_OPTION_HELP)
@llm_endpoint_options("LLM planners (-p)")
@click.option("--llm-replay", type=PathParam(dir_okay=False), multiple=True,
              help="moma-llm: answer from this transcript (JSONL, or an MCAP log's "
                   "/sgtool/llm channel; repeatable) instead of an endpoint [default: the "
                   "exchanges of the MCAP inputs, when they have any].")
@success_option(recorded=True)
@budget_options(recorded=True)
@click.option("--reference", default=None, metavar="PLANNER", callback=reference_planner,
              help="Paired comparisons of every other planner against this one on the same "
                   "episodes (house, episode, seed, query, shortest path), pooled over the "
                   "inputs (a run of your planner against a stored run of the baselines) "
                   "and under one noise profile at a time: SPL ratio, SR and SPL "
                   "differences with bootstrap intervals over houses, wins/losses/ties per "
                   "house; all, seen and unseen queries. [default: scout when scored, else "
                   "the first planner]")
@click.option("--all-pairs", is_flag=True,
              help="Paired comparisons of every pair of planners instead of against "
                   "--reference.")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object instead of tables.")
@click.option("-o", "--out", type=PathParam(dir_okay=False), default=None,
              help="Also write the output to this file (JSON if it ends in .json).")
@click.option("--force", is_flag=True, help="Overwrite the -o file.")
@executor_options("file reads (one per input)")
@click.option("--progress/--no-progress", default=None,
              help="Progress bar on stderr (default: when stderr is a terminal).")
def command(inputs: tuple[str, ...], out: str | None, force: bool = False,
            **given: Any) -> None:
    """Recompute the benchmark metrics (SR, SPL, steps, decision time, AUC-E with both
    budgets, seen/unseen, SR and SPL with bootstrap intervals over houses, paired
    comparisons of planners on the same episodes) from recorded episodes: MCAP logs of
    closed-loop runs (their sgtool.Episode and sgtool.Action records) and/or
    episodes.jsonl files written by `sgtool bench`. A folder is read as its episodes.jsonl
    when it holds one (the output of bench or run-bench), else as every MCAP log in it and
    its subfolders (a --log-dir of bench or run-bench). With --planner, replay every logged
    decision point of the MCAP logs: the planner decides on the logged scene graph, its
    choice is compared with the logged action, and it is then told what was really done.

    Only search episodes are scored: logs of recordings and imports are skipped with a note.
    An episode whose figures cannot be true, or contradict each other, is refused: it is
    left out of every metric and a one-line note on stderr names the file, the episode and
    the contradiction (the JSON output lists the notes too). Refused: negative steps or
    counts; a negative or non-finite travelled_m or shortest_m; more opens than steps; more
    steps than the actions it lists, or less travel than they travelled; and
    in symbolic episodes travel without a step (steps 0, travelled_m > 0) and a success
    that travelled less than its shortest path by more than 5.5 m + 10% of it (the path
    ends 1 m from the target, a camera sees it from up to 6 m: a success with 0 m
    travelled towards a target 9.48 m away is refused; a closed-loop robot drives on its
    own between steps and sees over furniture its path goes round). A shortest_m of 0 is
    accepted: the target is seen from the start."""
    from sgtool.analysis.eval_run import evaluate
    from sgtool.files import atomic_write

    request = _request(inputs, out, force, EvalArgs(**given))
    with stdout_to_stderr() if request.as_json else contextlib.nullcontext():
        outcome = evaluate(request, note=lambda m: click.echo(m, err=True))
    if out:
        atomic_write(out, outcome.text)
    click.echo(outcome.text, nl=False)
    if outcome.unread:  # after the output, whose notes name each (one: not again)
        first = "" if len(outcome.unread) == 1 else f"; the first: {outcome.unread[0]}"
        raise SgtoolError(f"{len(outcome.unread)} of {len(request.inputs)} input(s) could not "
                          f"be read and are left out of the metrics (the note above says "
                          f"why){first}")


@dataclass(frozen=True)
class EvalArgs:
    """The options of `sgtool eval` besides the inputs and the output, as given."""

    planners: tuple[str, ...]
    planner_option: tuple[str, ...]
    llm_replay: tuple[str, ...]
    distance_budget: float | None
    step_budget: float | None
    as_json: bool
    success: str | None = None
    executor: str = "local"
    workers: int = 1
    ray_address: str | None = None
    progress: bool | None = None
    llm_base_url: str | None = None
    llm_model: str | None = None
    llm_api_key: str | None = None
    llm_timeout: float | None = None
    reference: str | None = None
    all_pairs: bool = False


def _request(inputs: tuple[str, ...], out: str | None, force: bool, args: EvalArgs
             ) -> EvalRequest:
    """The option, output and input checks: finite budgets, the executor, the inputs (MCAP
    logs found in folders), the -o file (not an input), the planners and their options."""
    from sgtool.analysis.batch_inputs import expand_inputs
    from sgtool.analysis.eval_run import EvalRequest
    from sgtool.analysis.executor import make_executor
    from sgtool.commands.options import check_output, planner_names, planner_options
    from sgtool.planning.registry import check_planner_name

    if args.reference is not None and args.all_pairs:
        raise SgtoolError("--reference and --all-pairs: give one (all pairs compare every "
                          "planner with every other, the reference among them)")
    runner = make_executor(args.executor, args.workers, args.ray_address)
    runs = [str(Path(i) / "episodes.jsonl") if (Path(i) / "episodes.jsonl").is_file()
            else i for i in inputs]  # an output folder: its table, not its logs too
    # a run given twice (a table and its logs) is scored once: eval_run.once_each
    files = tuple(map(str, expand_inputs(runs, (".mcap",), "MCAP logs", recursive=True)))
    if out:
        check_output(out, force=force)
        if any(Path(out).resolve() == Path(i).resolve() for i in files):
            raise SgtoolError(f"-o {out}: the output must not be an input")
    names = [n for item in args.planners for n in planner_names(item)]
    for n in names:
        check_planner_name(n)
    options = planner_options(args.planner_option, names)
    LlmEndpoint(args.llm_base_url, args.llm_model, args.llm_api_key,
                args.llm_timeout).fill(options, names)
    dist, steps = _budgets(args, files)
    return EvalRequest(inputs=files, runner=runner, planners=tuple(names),
                       planner_options=options, llm_replay=args.llm_replay,
                       success=args.success, distance_budget=dist, step_budget=steps,
                       reference=args.reference,
                       all_pairs=args.all_pairs,
                       as_json=args.as_json or bool(out and out.endswith(".json")),
                       progress=args.progress if args.progress is not None
                       else sys.stderr.isatty())


def _budgets(args: EvalArgs, files: Sequence[str]) -> tuple[float, float]:
    """The AUC-E budgets: as given, else as the runs read were made (bench records them),
    else the defaults (MoMa-LLM's)."""
    from sgtool.analysis.eval_settings import recorded_budgets
    from sgtool.analysis.search_metrics import DISTANCE_BUDGET, STEP_BUDGET

    dist, steps = recorded_budgets(files)
    return (args.distance_budget or dist or DISTANCE_BUDGET,
            args.step_budget or steps or STEP_BUDGET)


@contextlib.contextmanager
def stdout_to_stderr() -> Any:
    """Whatever a plug-in planner prints while eval runs goes to stderr, so that the JSON
    printed on stdout stays one JSON object: ``sys.stdout`` and, where it is a real file,
    file descriptor 1 (the worker processes started meanwhile inherit it)."""
    try:
        out_fd, err_fd = sys.stdout.fileno(), sys.stderr.fileno()
    except (AttributeError, OSError, ValueError):  # (a test runner's buffers)
        out_fd = err_fd = -1
    sys.stdout.flush()
    saved = os.dup(out_fd) if out_fd >= 0 else -1
    try:
        if saved >= 0:
            os.dup2(err_fd, out_fd)
        with contextlib.redirect_stdout(sys.stderr):
            yield
    finally:
        if saved >= 0:
            os.dup2(saved, out_fd)
            os.close(saved)
