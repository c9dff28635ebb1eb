
"""``sgtool eval``: metrics from recorded episodes; planners evaluated against logged decisions."""

from __future__ import annotations

import json
import math
import sys
from dataclasses import asdict
from pathlib import Path
from typing import Any

import click

from sgtool.canonical import strict_json
from sgtool.commands.options import (
    PLANNER_OPTION_HELP,
    PLUGIN_HELP,
    LlmEndpoint,
    executor_options,
    list_planners_option,
    llm_endpoint_options,
    success_option,
)
from sgtool.errors import SgtoolError


@click.command("eval")
@click.argument("inputs", nargs=-1, required=True, type=click.Path())
@click.option("-p", "--planner", "planners", multiple=True, metavar="NAME[,NAME]",
              help="Also ask these planners at every logged decision point (MCAP logs with "
                   "scene graphs) and compare their choices with what was done (repeatable "
                   "or comma-separated). " + PLUGIN_HELP)
@list_planners_option()
@click.option("-O", "--planner-option", "planner_option", multiple=True, metavar="P.KEY=VALUE",
              help=PLANNER_OPTION_HELP)
@llm_endpoint_options("LLM planners (-p)")
@click.option("--llm-replay", type=click.Path(dir_okay=False), multiple=True,
              help="moma-llm: answer from this transcript (JSONL, or an MCAP log's "
                   "/sgtool/llm channel; repeatable) instead of an endpoint [default: the "
                   "exchanges of the MCAP inputs, when they have any].")
@success_option(recorded=True)
@click.option("--distance-budget", type=click.FloatRange(min=0, min_open=True), default=5000.0,
              show_default=True,
              help="AUC-E distance variant budget max (low-level steps: 0.1 m = 1, open = 30).")
@click.option("--step-budget", type=click.FloatRange(min=0, min_open=True), default=50.0,
              show_default=True, help="AUC-E step variant budget max (high-level steps).")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object instead of tables.")
@click.option("-o", "--out", type=click.Path(dir_okay=False), default=None,
              help="Also write the output to this file (JSON if it ends in .json).")
@click.option("--force", is_flag=True, help="Overwrite the -o file.")
@executor_options("file reads (one per input)")
@click.option("--progress/--no-progress", default=None,
              help="Progress bar on stderr (default: when stderr is a terminal).")
def command(inputs: tuple[str, ...], planners: tuple[str, ...], planner_option: tuple[str, ...],
            llm_replay: tuple[str, ...], distance_budget: float, step_budget: float,
            as_json: bool, out: str | None, force: bool = False, success: str | None = None,
            executor: str = "local", workers: int = 1, ray_address: str | None = None,
            progress: bool | None = None, llm_base_url: str | None = None,
            llm_model: str | None = None, llm_api_key: str | None = None,
            llm_timeout: float | None = None) -> None:
    """Recompute the benchmark metrics (SR, SPL, steps, decision time, AUC-E with both
    budgets, seen/unseen) from recorded episodes: MCAP logs of closed-loop runs (their
    sgtool.Episode and sgtool.Action records) and/or episodes.jsonl files written by
    `sgtool bench`. With --planner, replay every logged decision point of the MCAP logs:
    the planner decides on the logged scene graph, its choice is compared with the logged
    action, and it is then told what was really done.

    Only search episodes are scored: logs of recordings and imports are skipped with a note.
    An episode whose figures cannot be true, or contradict each other, is refused: it is
    left out of every metric and a one-line note on stderr names the file, the episode and
    the contradiction (the JSON output lists the notes too). Refused: negative steps or
    counts; a negative or non-finite travelled_m or shortest_m; travel without a step
    (steps 0, travelled_m > 0); more opens than steps; a success that travelled less than
    its shortest path by more than 5.5 m + 10% of it (the path ends 1 m from the target, a
    camera sees it from up to 6 m: a success with 0 m travelled towards a target 9.48 m
    away is refused). A shortest_m of 0 is accepted: the target is seen from the start."""
    from sgtool.analysis.batch_eval import load_many
    from sgtool.analysis.batch_inputs import expand_inputs
    from sgtool.analysis.executor import make_executor
    from sgtool.analysis.metrics import cost_models, seen_unseen, summarize
    from sgtool.analysis.offline import (
        format_offline,
        log_exchanges,
        replay_decisions,
        with_success_rule,
    )
    from sgtool.analysis.report import format_seen_unseen, format_table, summary_dict
    from sgtool.commands.options import check_output, planner_names, planner_options
    from sgtool.files import atomic_write
    from sgtool.llm.stats import answer_stats, format_stats
    from sgtool.planning.registry import check_planner_name, make_planner

    for name, value in (("--distance-budget", distance_budget), ("--step-budget", step_budget)):
        if not math.isfinite(value):
            raise SgtoolError(f"{name} {value}: must be a finite number > 0")
    runner = make_executor(executor, workers, ray_address)
    inputs = tuple(map(str, expand_inputs(inputs, (".mcap",), "MCAP logs")))
    if out:
        check_output(out, force=force)
        if any(Path(out).resolve() == Path(i).resolve() for i in inputs):
            raise SgtoolError(f"-o {out}: the output must not be an input")
    show = progress if progress is not None else sys.stderr.isatty()
    results, logged, notes, unread = load_many([Path(i) for i in inputs], runner,
                                               progress=show)
    results = [with_success_rule(r, success) for r in results]
    for note in notes:
        click.echo(f"sgtool: note: {note}", err=True)
    if not results:
        why = f" ({len(notes)} skipped or refused, see the notes)" if notes else ""
        raise SgtoolError("no search episodes to score in " + ", ".join(inputs) + why)
    models = cost_models(distance_budget, step_budget)
    sums = summarize(results, models)
    names = [n for item in planners for n in planner_names(item)]
    for n in names:
        check_planner_name(n)
    options = planner_options(planner_option, names)
    endpoint = LlmEndpoint(llm_base_url, llm_model, llm_api_key, llm_timeout)
    endpoint.fill(options, names)
    exchanges = log_exchanges(inputs)
    replay = list(llm_replay) or sorted({src for src, _ in exchanges})
    moma = options.get("moma-llm", {})
    # the logs' own exchanges answer, unless an endpoint is named (flag or -O)
    if replay and "moma-llm" in names and (llm_replay or not moma.get("base_url")):
        options.setdefault("moma-llm", {}).setdefault("replay", replay)
    if names and not any(d.graph is not None for e in logged for d in e.decisions):
        raise SgtoolError("--planner needs MCAP logs with sgtool.SceneGraph records; "
                          "the inputs have none")
    reports = [replay_decisions(make_planner(n, **options.get(n, {})), logged, name=n)
               for n in names]
    if as_json or (out and out.endswith(".json")):
        doc: dict[str, Any] = {
            "episodes": len(results),
            "notes": notes,
            "budgets": {m.name: {"max": m.max_cost, "cost": m.label} for m in models},
            "planners": summary_dict(sums),
            "seen_unseen": [asdict(s) for s in seen_unseen(results)],
            "offline": {r.planner: {"decisions": r.decisions, "same_action": r.rate("agree"),
                                    "same_target": r.rate("target"),
                                    "same_room": r.rate("room"),
                                    "not_in_graph": r.rate("invalid"), "skipped": r.skipped,
                                    "decision_s": r.mean_decision_s()}
                        for r in reports},
        }
        if exchanges:
            doc["llm_answers"] = answer_stats(exchanges).as_dict()
        text = json.dumps(strict_json(doc), indent=1, sort_keys=True, allow_nan=False) + "\n"
    else:
        parts = [format_table(sums, models=models,
                              title=f"Metrics recomputed from {len(results)} episode(s) in "
                                    f"{len(inputs)} file(s)")]
        if any(r.seen is not None for r in results):
            parts.append(format_seen_unseen(seen_unseen(results), title="Seen vs unseen queries"))
        if reports:
            parts.append(format_offline(reports))
        if exchanges:
            parts.append(format_stats(answer_stats(exchanges), "the logs") + "\n")
        text = "\n".join(parts)
    if out:
        atomic_write(out, text)
    click.echo(text, nl=False)
    if unread:  # after the output, whose notes name each
        raise SgtoolError(f"{len(unread)} of {len(inputs)} input(s) could not be read and are "
                          f"left out of the metrics; the first: {unread[0]}")
