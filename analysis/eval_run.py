"""The work of `sgtool eval`: read recorded episodes, recompute the metrics, replay the
logged decisions to other planners, and render the result as text tables or one JSON
document.

The command checks the options, the output and the planners and builds an
:class:`EvalRequest`; :func:`evaluate` reads and scores, and returns the text with the
inputs that could not be read (the command writes the text, then refuses those in one
line). ``note`` receives the notes meant for stderr, one per skipped or refused episode.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Collection, Mapping, Sequence
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from sgtool.canonical import strict_json
from sgtool.errors import SgtoolError
from sgtool.log.records import given
from sgtool.semantics.text import category_text

if TYPE_CHECKING:
    from sgtool.analysis.executor import Executor
    from sgtool.analysis.interval_report import IntervalReport
    from sgtool.results import EpisodeResult

Echo = Callable[[str], None]


@dataclass(frozen=True)
class EvalRequest:
    """A checked `sgtool eval`: the input files (MCAP logs, episodes.jsonl), the planners to
    replay with their checked options, transcripts answering moma-llm (empty: the logs'
    own exchanges), the success rule (None: as recorded), the AUC-E budgets (distance in
    low-level steps, high-level steps), JSON or tables, the executor of the reads and
    whether to show progress (stderr), and the paired comparisons' reference (None: scout when
    scored, else the first planner) or every pair."""

    inputs: tuple[str, ...]
    runner: Executor
    planners: tuple[str, ...] = ()
    planner_options: dict[str, dict[str, Any]] = field(default_factory=dict)
    llm_replay: tuple[str, ...] = ()
    success: str | None = None
    distance_budget: float = 5000.0
    step_budget: float = 50.0
    as_json: bool = False
    progress: bool = False
    reference: str | None = None  # paired comparisons against it (None: scout, else first)
    all_pairs: bool = False  # paired comparisons of every pair of planners instead


@dataclass(frozen=True)
class EvalOutcome:
    """The rendered result and the inputs left out because they could not be read."""

    text: str
    unread: list[str]


def evaluate(request: EvalRequest, note: Echo) -> EvalOutcome:
    """Score the request's episodes and replay its planners on the logged decisions."""
    from sgtool.analysis.batch_eval import load_many, unread_path
    from sgtool.analysis.eval_settings import settings_notes
    from sgtool.analysis.offline import log_exchanges, with_seen, with_success_rule
    from sgtool.analysis.search_metrics import cost_models, summarize

    results, logged, notes, unread = load_many([Path(i) for i in request.inputs], request.runner,
                                               progress=request.progress)
    judged = [with_seen(with_success_rule(r, request.success)) for r in results]
    unconfirmed = sorted({r.planner for r, j in zip(results, judged, strict=True)
                          if r.success and not j.success})
    symbolic = {lg.source for lg in logged if lg.episode.source == "symbolic"}
    results, profiles = per_noise(judged, symbolic)  # (fills the noise a row's folder names)
    results, split = per_options(results, bool(profiles))
    results, twice = once_each(results)
    notes = [*notes, *split, *twice]
    if unconfirmed:  # runs made under "observed": their planners never had to call done
        notes = [*notes, f"--success {request.success}: successes of {', '.join(unconfirmed)} "
                 "that end without done() naming an object count as failures (a run made "
                 "under the observed rule never asked its planners for done)"]
    if profiles:
        notes = [*notes, f"the episodes ran under {len(profiles)} sensor noise profiles "
                 f"({', '.join(profiles)}"
                 + ("; symbolic: the symbolic bench, no sensor" if "symbolic" in profiles
                    else "") + "): each planner is scored per profile, as PLANNER [NOISE]"]
    if (other := _unlike_episodes(results)) is not None:
        notes = [*notes, other]
    if (other := _unpaired_shortest(results)) is not None:
        notes = [*notes, other]
    notes = [*notes, *settings_notes(request.inputs), *_logged_step_notes(logged),
             *_default_option_notes(request, logged)]
    if unknown := sum(1 for r in results if r.shortest_m is None
                      or not math.isfinite(r.shortest_m)):
        notes = [*notes, f"{unknown} episode(s) have no shortest path (none was logged, or "
                 "the target cannot be reached on the house's geometry): SPL leaves them "
                 "out, SR counts them"]
    for text in notes:
        note(f"sgtool: note: {text}")
    if not results:
        why = f" ({len(notes)} skipped or refused, see the notes)" if notes else ""
        raise SgtoolError("no search episodes to score in "
                          + ", ".join(request.inputs) + why)
    bases = list(dict.fromkeys(base for _, base in _profile_names(results).values()))
    if request.reference is not None and request.reference not in bases:
        raise SgtoolError(f"--reference {request.reference}: no episode of that planner in "
                          f"the inputs (planners: {', '.join(bases)})")
    models = cost_models(request.distance_budget, request.step_budget)
    # a file that could not be read (a note said so) is left out of the rest too
    bad = {unread_path(u) for u in unread}
    exchanges = log_exchanges([i for i in request.inputs if i not in bad])
    reports = _replays(request, logged, exchanges)
    render = _as_json if request.as_json else _as_tables
    text = render(request, results, notes, models, summarize(results, models), reports,
                  exchanges)
    return EvalOutcome(text=text, unread=list(unread))


def _default_option_notes(request: EvalRequest, logged: Sequence[Any]) -> list[str]:
    """A note for each planner asked (``-p``) without ``-O`` whose own logged episodes ran
    it with options: it is asked with its defaults, and disagrees where they matter."""
    out = []
    for name in request.planners:
        if request.planner_options.get(name):
            continue
        ran = {json.dumps(opts, sort_keys=True) for e in logged
               if given(e.episode.planner) == name
               and isinstance(opts := e.episode.extras.get("planner_options"), dict) and opts}
        if ran:
            shown = "; ".join(sorted(ran))
            out.append(f"-p {name} asks it with its default options; its logs ran it with "
                       f"{shown} (give them with -O {name}.KEY=VALUE to ask it as it ran)")
    return out


def _logged_step_notes(logged: Sequence[Any]) -> list[str]:
    """A note when the episode logs given ran with different step budgets (their
    ``max_steps``), as :func:`~sgtool.analysis.eval_settings.settings_notes` says of
    bench runs: their rows would mix them silently."""
    budgets: dict[int, int] = {}
    for lg in logged:
        v = lg.episode.extras.get("max_steps")
        if isinstance(v, int) and not isinstance(v, bool):
            budgets[v] = budgets.get(v, 0) + 1
    if len(budgets) < 2:
        return []
    shown = ", ".join(f"{k} ({n} episode(s))" for k, n in sorted(budgets.items()))
    return [f"the logs given ran with different max_steps ({shown}): their rows and paired "
            "comparisons mix them"]


def per_noise(results: Sequence[EpisodeResult], symbolic_logs: Collection[str] = ()
              ) -> tuple[list[EpisodeResult], list[str]]:
    """``results`` with each planner named ``PLANNER [NOISE]`` when they ran under more
    than one sensor noise profile (:attr:`EpisodeResult.noise`, or the run-bench folder
    an older row's log lies in; ``symbolic`` for a symbolic bench's rows and the rows of
    its logs (``symbolic_logs``: their sources), which had no sensor; ``unknown`` when none
    of these says), and those profiles in order of appearance (empty: one profile, names
    kept): episodes of different sensors are not pooled."""
    results = [r if r.noise else replace(r, noise=_run_bench_noise(r) or (
        "symbolic" if r.source == "symbolic" or r.source in symbolic_logs else ""))
        for r in results]
    profiles = list(dict.fromkeys(r.noise or "unknown" for r in results))
    if len(profiles) < 2:
        return list(results), []
    return [replace(r, planner=f"{r.planner} [{r.noise or 'unknown'}]") for r in results], \
        profiles


def per_options(results: Sequence[EpisodeResult], noisy: bool = False
                ) -> tuple[list[EpisodeResult], list[str]]:
    """``results`` with each planner named ``PLANNER(KEY=VALUE,...)`` when one planner
    ran with more than one set of options (:attr:`EpisodeResult.options` as the planner
    takes them, an option at its default being none:
    :func:`sgtool.planning.registry.effective_options`; ``PLANNER()``: its defaults), and a
    note naming those sets (none: names kept): runs of other options are not pooled.
    ``noisy``: the names end in the `` [NOISE]`` of :func:`per_noise`, kept last."""
    tails = [f" [{r.noise or 'unknown'}]" if noisy else "" for r in results]
    bases = [r.planner.removesuffix(t) for r, t in zip(results, tails, strict=True)]
    labels = [_options_label(b, r.options) for b, r in zip(bases, results, strict=True)]
    sets: dict[str, list[str]] = {}
    for b, lab in zip(bases, labels, strict=True):
        if lab not in sets.setdefault(b, []):
            sets[b].append(lab)
    split = {b for b, labs in sets.items() if len(labs) > 1}
    if not split:
        return list(results), []
    out = [replace(r, planner=f"{b}({lab}){t}") if b in split else r
           for r, b, lab, t in zip(results, bases, labels, tails, strict=True)]
    shown = "; ".join(f"{b}: " + ", ".join(f"{b}({lab})" for lab in sets[b])
                      for b in sorted(split))
    return out, [f"planners ran with more than one set of options ({shown}): each set is "
                 "scored as a planner of its own"]


def _options_label(planner: str, options: Mapping[str, Any]) -> str:
    """``KEY=VALUE,...`` of the options ``planner`` takes from ``options`` (sorted;
    those at their defaults left out; as recorded when the planner cannot be asked)."""
    from sgtool.planning.registry import effective_options
    from sgtool.redact import options_as_text

    try:
        taken = effective_options(planner, options) if options else {}
    except Exception:  # noqa: BLE001 - a plug-in not importable here, a value it refuses now
        taken = dict(options)
    text = options_as_text({planner: taken}).get(planner, {})
    return ",".join(f"{k}={v}" for k, v in sorted(text.items()))


def _episode_key(r: EpisodeResult) -> tuple[str, str, int, int, str, str]:
    """What names one run of a planner: planner (with its options when
    :func:`per_options` told them apart), house, episode, seed, query (generated houses
    of other sizes share their names, house-0, but not their queries) and noise."""
    return (r.planner, r.house, r.episode, r.seed, category_text(r.query), r.noise or "")


def once_each(results: Sequence[EpisodeResult]) -> tuple[list[EpisodeResult], list[str]]:
    """``results`` with each run read once: a run given twice (a copy of a log, a log and
    the table that lists it) keeps its first reading; and notes saying how many were left
    out, and when one name (:func:`_episode_key`) holds runs that ended otherwise (the
    same house name for other houses): those are kept, pooled, and named."""
    seen: dict[tuple[str, str, int, int, str, str], EpisodeResult] = {}
    out, dropped, clash = [], 0, set()
    for r in results:
        key = _episode_key(r)
        first = seen.get(key)
        if first is None:
            seen[key] = r
            out.append(r)
        elif _outcome(first) == _outcome(r):
            dropped += 1
        else:
            clash.add(key)
            out.append(r)
    notes = []
    if dropped:
        notes.append(f"{dropped} episode(s) were given twice (a copy of a log, or a log and "
                     "a table that lists it): each is scored once")
    if clash:
        names = sorted({f"{k[0]} on {k[1]}" for k in clash})
        notes.append(f"{len(clash)} run(s) of one name (planner, house, episode, seed, "
                     f"query) ended differently in two inputs ({', '.join(names[:3])}): "
                     "runs of other houses or settings under one name are pooled; score "
                     "them separately")
    return out, notes


def _outcome(r: EpisodeResult) -> tuple[object, ...]:
    return (r.success, r.steps, round(r.travelled_m, 3), r.end)


def _unlike_episodes(results: Sequence[EpisodeResult]) -> str | None:
    """A note when the planners were not run on the same episodes (house, episode, seed,
    query): their rows are then not comparable as they stand (the paired tables are)."""
    sets: dict[str, set[tuple[str, int, int, str]]] = {}
    for r in results:  # (the noise profile is in the planner's name when there are several)
        sets.setdefault(r.planner, set()).add(_episode_key(r)[1:5])
    if len(sets) < 2 or len({frozenset(s) for s in sets.values()}) == 1:
        return None
    common = set.intersection(*sets.values())
    counts = ", ".join(f"{p} {len(s)}" for p, s in sorted(sets.items()))
    return (f"the planners ran on different episodes ({counts}; {len(common)} in common): "
            "their rows are not comparable as they stand; compare them on the same episodes "
            "(give the runs' logs of one episode list)")


def _unpaired_shortest(results: Sequence[EpisodeResult]) -> str | None:
    """A note when runs of one (house, episode, seed, query) disagree on its shortest path
    (to 1 cm): the paired tables keep them apart."""
    from sgtool.analysis.intervals import pair_key

    paths: dict[tuple[object, ...], set[float]] = {}
    for r in results:  # per noise profile, as pairs are made (the symbolic bench's is its own)
        *episode, short = pair_key(r)  # (rounded as the pairing rounds it)
        if short is not None:
            paths.setdefault((*episode, r.noise or ""), set()).add(short)
    odd = sorted(k for k, v in paths.items() if len(v) > 1)
    if not odd:
        return None
    h, e, _, q, _ = odd[0]  # house, episode, seed, query, noise
    return (f"{len(odd)} episode(s) have other shortest paths in the inputs (first: {h} "
            f"episode {e}, {q}: {', '.join(f'{v:g}' for v in sorted(paths[odd[0]]))} m) and "
            "are not paired: other houses under one name, or closed-loop logs written "
            "before SPL's shortest path was the robot's string-pulled route (run them again)")


def _run_bench_noise(r: EpisodeResult) -> str:
    """The noise profile of a row written before rows named it, from its log's place in a
    run-bench folder (``.../logs/NOISE/PLANNER/HOUSE/ep-K.mcap``); "" when it is not."""
    from sgtool.planning.registry import planner_file_name

    parts = Path(r.source).parts
    if len(parts) >= 5 and parts[-5] == "logs" and parts[-3] == planner_file_name(r.planner) \
            and parts[-2] == r.house and parts[-1].startswith("ep-"):
        return parts[-4]
    return ""


def _replays(request: EvalRequest, logged: Sequence[Any], exchanges: Sequence[Any]
             ) -> list[Any]:
    """One offline report per planner of the request, on the logged decision points."""
    from sgtool.analysis.offline import replay_decisions
    from sgtool.planning.registry import make_planner

    names, options = request.planners, {k: dict(v) for k, v in
                                        request.planner_options.items()}
    replay = list(request.llm_replay) or sorted({src for src, _ in exchanges})
    moma = options.get("moma-llm", {})
    # the logs' own exchanges answer, unless an endpoint is named (flag or -O)
    if replay and "moma-llm" in names and (request.llm_replay or not moma.get("base_url")):
        options.setdefault("moma-llm", {}).setdefault("replay", replay)
    if names and not any(d.graph is not None for e in logged for d in e.decisions):
        decisions = sum(len(e.decisions) for e in logged)
        tables = [Path(i).parent for i in request.inputs if Path(i).name == "episodes.jsonl"
                  and (Path(i).parent / "logs").is_dir()]
        raise SgtoolError(
            "--planner needs logged decisions made on a scene graph (sgtool.Action records "
            "of MCAP logs, each after an sgtool.SceneGraph record); " + (
                f"a folder is read as its table: give {tables[0] / 'logs'} for its logs"
                if tables and not decisions else
                "the inputs' logs hold no decision" if not decisions else
                f"none of the inputs' {decisions} decisions has a SceneGraph record at or "
                "before its graph_time_ns (or, without the field, before it)"))
    return [replay_decisions(make_planner(n, **options.get(n, {})), logged, name=n)
            for n in names]


def _as_json(request: EvalRequest, results: Sequence[Any], notes: Sequence[str],
             models: Sequence[Any], sums: Any, reports: Sequence[Any],
             exchanges: Sequence[Any]) -> str:
    from sgtool.analysis.report import summary_dict
    from sgtool.analysis.search_metrics import seen_unseen
    from sgtool.llm.stats import answer_stats

    doc: dict[str, Any] = {
        "episodes": len(results),
        "notes": list(notes),
        "budgets": {m.name: {"max": m.max_cost, "cost": m.label} for m in models},
        "planners": summary_dict(sums),
        "seen_unseen": [{k: round(v, 6) if isinstance(v, float) else v  # as "planners"
                         for k, v in asdict(s).items()} for s in seen_unseen(results)],
        "intervals": _intervals(request, results).to_dict(),
        "offline": {r.planner: {"decisions": r.decisions, "same_action": r.rate("agree"),
                                "same_target": r.rate("target"), "same_room": r.rate("room"),
                                "not_in_graph": r.rate("invalid"), "skipped": r.skipped,
                                "decision_s": r.mean_decision_s()}
                    for r in reports},
    }
    if exchanges:
        doc["llm_answers"] = answer_stats(exchanges).as_dict()
    return json.dumps(strict_json(doc), indent=1, sort_keys=True, allow_nan=False) + "\n"


def _as_tables(request: EvalRequest, results: Sequence[Any], notes: Sequence[str],
               models: Sequence[Any], sums: Any, reports: Sequence[Any],
               exchanges: Sequence[Any]) -> str:
    from sgtool.analysis.offline import format_offline
    from sgtool.analysis.report import format_seen_unseen, format_table
    from sgtool.analysis.search_metrics import seen_unseen
    from sgtool.llm.stats import answer_stats, format_stats

    parts = [format_table(sums, models=models,
                          title=f"Metrics recomputed from {len(results)} episode(s) in "
                                f"{len(request.inputs)} file(s)")]
    if any(r.seen is not None for r in results):
        parts.append(format_seen_unseen(seen_unseen(results), title="Seen vs unseen queries"))
    parts.append(_intervals(request, results).text())
    if reports:
        parts.append(format_offline(reports))
    if exchanges:
        parts.append(format_stats(answer_stats(exchanges), "the logs") + "\n")
    else:  # episodes.jsonl of bench / run-bench: the rows' own answer counts
        from sgtool.analysis.report import llm_answer_lines
        lines = llm_answer_lines(results, list(dict.fromkeys(r.planner for r in results)))
        if lines:
            parts.append("\n".join(lines) + "\n")
    return "\n".join(parts)


def _intervals(request: EvalRequest, results: Sequence[EpisodeResult]) -> IntervalReport:
    """SR and SPL with intervals over houses and the paired comparisons of the request:
    planners compared under one sensor noise profile at a time (their names PLANNER
    [NOISE] when there are several), the reference named without the profile."""
    from sgtool.analysis.interval_report import interval_report
    from sgtool.analysis.intervals import comparison_pairs

    names = _profile_names(results)
    groups: dict[str, list[str]] = {}
    for planner, (noise, _) in names.items():
        groups.setdefault(noise, []).append(planner)
    pairs: list[tuple[str, str]] = []
    for planners in groups.values():
        base = {names[p][1]: p for p in planners}
        ref = base.get(request.reference or "scout") if not request.all_pairs else None
        if request.reference is not None and ref is None:
            continue  # the reference did not run under this profile: nothing to pair
        pairs += comparison_pairs(planners, ref, request.all_pairs)
    return interval_report(results, list(names), pairs=pairs)


def _profile_names(results: Sequence[EpisodeResult]) -> dict[str, tuple[str, str]]:
    """Each planner name in order of appearance: (its noise profile, its name without the
    `` [NOISE]`` that :func:`per_noise` adds when there are several profiles)."""
    out: dict[str, tuple[str, str]] = {}
    for r in results:
        if r.planner not in out:
            noise = r.noise or "unknown"
            tail = f" [{noise}]"
            out[r.planner] = (noise, r.planner.removesuffix(tail))
    return out
