"""``sgtool distill``: train the relational priors, or report how well they separate.

The work is in :mod:`sgtool.analysis.priors_training` (training writes into a temporary
folder inside the output and moves the three files in only when both models are done, so
an interrupted run never leaves a mixed set); this module parses the options into a
:class:`~sgtool.analysis.priors_training.DistillRequest` and prints the report.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from sgtool.canonical import json_text
from sgtool.commands.options import SEED, FiniteFloatRange, PathParam, llm_endpoint_options
from sgtool.errors import SgtoolError

if TYPE_CHECKING:
    from sgtool.analysis.priors_training import LlmSource


# the options of training, which --report (no training) does not take
_TRAINING = ("seed", "holdout", "epochs_containment", "epochs_cooccurrence", "keep", "threads",
             "room_blend", "source", "force")


def _check_modes(out_dir: Path | None, report_only: bool, source: str,
                 llm_slice: str | None, weights_dir: Path | None = None) -> None:
    """Options that do not go together, one line each: training options with --report,
    --weights (what --report reads) without it."""
    from click.core import ParameterSource

    if llm_slice is not None and source != "llm":
        raise SgtoolError("--llm-slice is for --source llm")
    if report_only and out_dir is not None:
        raise SgtoolError(f"--report trains nothing, so --out {out_dir} has nothing to go "
                          "there; to report on weights give --weights DIR")
    ctx = click.get_current_context(silent=True)
    if ctx is None:
        return
    llm_given = [f"--{n.replace('_', '-')}" for n in ctx.params if n.startswith("llm_")
                 and ctx.get_parameter_source(n) is ParameterSource.COMMANDLINE]
    if llm_given and (source != "llm" or report_only):
        raise SgtoolError(f"{', '.join(llm_given)}: for --source llm (training from an "
                          "LLM's answers), which this run does not use")
    given = [f"--{n.replace('_', '-')}" for n in _TRAINING
             if ctx.get_parameter_source(n) is ParameterSource.COMMANDLINE]
    if report_only and given:
        raise SgtoolError(f"--report trains nothing: {', '.join(given)} would do nothing "
                          "(the report uses the seed the weights were trained with)")
    if not report_only and weights_dir is not None:
        raise SgtoolError(f"--weights {weights_dir} is the folder --report reads; training "
                          "starts afresh and writes --out")


def _weights_dir() -> Path:
    from sgtool.semantics.priors import WEIGHTS_DIR

    return WEIGHTS_DIR


@click.command(
    "distill",
    context_settings={"help_option_names": ["-h", "--help"], "max_content_width": 100},
)
@click.option("--out", "out_dir", type=PathParam(file_okay=False, path_type=Path),
              default=None,
              help="Folder for the trained weights [default: the weights shipped in the "
                   "package, sgtool/semantics/weights]. A folder that holds weights already "
                   "is replaced only with --force.")
@click.option("--force", is_flag=True,
              help="Replace the weights the --out folder (or the package) holds.")
@click.option("--report", "report_only", is_flag=True,
              help="Do not train: print the quality report of the weights in --weights: on "
                   "query categories held out of training, ROC-AUC of the learned scores vs "
                   "raw SBERT cosine similarity, for containment and co-occurrence.")
@click.option("--weights", "weights_dir", type=PathParam(file_okay=False, exists=True,
                                                          path_type=Path),
              default=None, help="Weights to report on [default: the shipped ones].")
@click.option("--json", "as_json", is_flag=True, help="Print the report as JSON.")
@click.option("--seed", type=SEED, default=0, show_default=True,
              help="Seed of negative sampling, held-out choice, initialisation, shuffling.")
@click.option("--holdout", type=FiniteFloatRange(0.0, 0.9), default=0.0, show_default=True,
              help="Share of training query categories held out of training, reported as "
                   "a second group (the main report group is always the categories unseen "
                   "in training, from the evaluation part).")
@click.option("--epochs-containment", type=click.IntRange(1, 1000), default=30,
              show_default=True, help="Epochs of the containment model (MSE).")
@click.option("--epochs-cooccurrence", type=click.IntRange(1, 1000), default=5,
              show_default=True, help="Epochs of the co-occurrence model (BCE).")
@click.option("--keep", type=click.Choice(["last", "best"]), default="last",
              show_default=True,
              help="Keep the final weights, or those of the epoch with the lowest "
                   "validation loss.")
@click.option("--threads", type=click.IntRange(1, 64), default=1, show_default=True,
              help="Torch CPU threads (1 gives bit-identical weights run after run on one "
                   "machine; processors of other kinds may round differently).")
@click.option("--room-blend", is_flag=True,
              help="Train on the widened room knowledge (room types a house lacks folded "
                   "into the most alike household type; ProcTHOR's room annotations) and "
                   "write room_blend.json: distilled room scores blended with the nearest "
                   "known names by query novelty, fitted on names held out of a second "
                   "training (about twice the time). Not for the shipped default weights.")
@click.option("--source", type=click.Choice(["knowledge", "llm"]), default="knowledge",
              show_default=True,
              help="knowledge: the training split of the BEHAVIOR-1K knowledge (offline). "
                   "llm: SCOUT's procedural generation and labelling by an LLM.")
@llm_endpoint_options("--source llm", timeout=30.0)
@click.option("--llm-cache", type=PathParam(file_okay=False, path_type=Path), default=None,
              help="Folder caching every LLM answer (resumable; a complete cache replays the "
                   "generation offline) [default: $SGTOOL_CACHE/llm-knowledge].")
@click.option("--llm-runs", type=click.IntRange(1, 20), default=1, show_default=True,
              help="Repetitions of each generation prompt, for diversity.")
@click.option("--llm-max-queries", type=click.IntRange(min=1), default=None,
              help="Label at most this many generated objects (cost cap).")
@click.option("--llm-max-tokens", type=click.IntRange(16, 8192), default=512,
              show_default=True, help="Longest LLM answer, in tokens (a small model that does "
              "not stop would otherwise fill the context).")
@click.option("--llm-slice", default=None, metavar="ROOMS,CATEGORIES,OBJECTS",
              help="A small generation: at most ROOMS room types, CATEGORIES object "
                   "categories per room, OBJECTS objects per category [default: 12,8,10].")
def command(out_dir: Path | None, report_only: bool, weights_dir: Path | None, as_json: bool,
            source: str, llm_slice: str | None = None, force: bool = False,
            **given: Any) -> None:
    """Train the containment and co-occurrence MLPs (SCOUT sec. IV-C) or report on them.

    By default the training data come from the training split of the household knowledge
    only, the encoder is the bundled all-MiniLM-L6-v2, and the run is deterministic: the
    same seed writes byte-identical files. Takes about a minute on 2 CPU cores.
    """
    from sgtool.analysis.priors_training import (
        DistillRequest,
        train_priors,
        training_lines,
        weights_report,
    )
    from sgtool.semantics.distill import format_report

    _check_modes(out_dir, report_only, source, llm_slice, weights_dir)
    if report_only:
        rep = weights_report(weights_dir or _weights_dir())
        click.echo(json_text(rep, indent=1, sort_keys=True) if as_json else format_report(rep))
        return
    llm = {k: given.pop(k) for k in list(given) if k.startswith("llm_")}
    target = out_dir or _weights_dir()
    request = DistillRequest(target=target, **given,
                             llm=_llm_source(llm, llm_slice) if source == "llm" else None)
    if (target / "metadata.json").exists() and not force:  # after the options' own checks
        which = "the weights shipped in the package, every planner's default priors" \
            if out_dir is None else "trained weights"
        raise SgtoolError(f"{target} holds {which}; give --out DIR for new ones, or --force "
                          "to replace them")
    meta = train_priors(request, note=lambda m: click.echo(m, err=True))
    if as_json:
        click.echo(json_text(meta, indent=1, sort_keys=True))
        return
    for line in training_lines(meta):
        click.echo(line)
    click.echo(format_report(meta["report"]))
    click.echo(f"wrote {target}")


def _llm_source(llm: dict[str, Any], llm_slice: str | None) -> LlmSource:
    """The ``--llm-*`` options (without the ``llm_`` prefix) as a checked LLM source."""
    from sgtool.analysis.priors_training import LlmSource

    return LlmSource(base_url=llm["llm_base_url"], model=llm["llm_model"],
                     api_key=llm["llm_api_key"], cache=llm["llm_cache"], runs=llm["llm_runs"],
                     max_queries=llm["llm_max_queries"], slice=parse_llm_slice(llm_slice),
                     timeout_s=llm["llm_timeout"], max_tokens=llm["llm_max_tokens"])


def parse_llm_slice(text: str | None) -> dict[str, int]:
    """The ``--llm-slice ROOMS,CATEGORIES,OBJECTS`` value as the LLM source's generation
    limits (``max_rooms``, ``max_categories``, ``max_objects``; empty for None: the
    defaults); anything but three integers >= 1 is a one-line :class:`SgtoolError`."""
    if text is None:
        return {}
    try:
        rooms, cats, objs = (int(x) for x in text.split(","))
        if min(rooms, cats, objs) < 1:
            raise ValueError
    except ValueError:
        raise SgtoolError(f"--llm-slice {text!r}: give ROOMS,CATEGORIES,OBJECTS, three "
                          "integers >= 1, e.g. 3,2,3") from None
    return {"max_rooms": rooms, "max_categories": cats, "max_objects": objs}
