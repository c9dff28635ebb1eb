"""``sgtool distill``: train the relational priors, or report how well they separate.

Training writes into a temporary folder beside the output and moves the three files
(containment.safetensors, cooccurrence.safetensors, metadata.json) in only when both models
are done, so an interrupted run never leaves a mixed set.
"""

from __future__ import annotations

import json
import os
import shutil
import sys
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import click

from sgtool.commands.options import llm_endpoint_options
from sgtool.errors import SgtoolError
from sgtool.extras import require


def _weights_dir() -> Path:
    from sgtool.semantics.priors import WEIGHTS_DIR

    return WEIGHTS_DIR


@click.command(
    "distill",
    context_settings={"help_option_names": ["-h", "--help"], "max_content_width": 100},
)
@click.option("--out", "out_dir", type=click.Path(file_okay=False, path_type=Path),
              default=None,
              help="Folder for the trained weights [default: the weights shipped in the "
                   "package, sgtool/semantics/weights].")
@click.option("--report", "report_only", is_flag=True,
              help="Do not train: print the quality report of the weights in --weights: on "
                   "query categories held out of training, ROC-AUC of the learned scores vs "
                   "raw SBERT cosine similarity, for containment and co-occurrence.")
@click.option("--weights", "weights_dir", type=click.Path(file_okay=False, exists=True,
                                                          path_type=Path),
              default=None, help="Weights to report on [default: the shipped ones].")
@click.option("--json", "as_json", is_flag=True, help="Print the report as JSON.")
@click.option("--seed", type=int, default=0, show_default=True,
              help="Seed of negative sampling, held-out choice, initialisation, shuffling.")
@click.option("--holdout", type=click.FloatRange(0.0, 0.9), default=0.0, show_default=True,
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
              help="Torch CPU threads (1 keeps the weights bit-identical across machines "
                   "with the same libraries).")
@click.option("--source", type=click.Choice(["knowledge", "llm"]), default="knowledge",
              show_default=True,
              help="knowledge: the training split of the BEHAVIOR-1K knowledge (offline). "
                   "llm: SCOUT's procedural generation and labelling by an LLM.")
@llm_endpoint_options("--source llm", timeout=30.0)
@click.option("--llm-cache", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="Folder caching every LLM answer (resumable; a complete cache replays the "
                   "generation offline) [default: $SGTOOL_CACHE/llm-knowledge].")
@click.option("--llm-runs", type=click.IntRange(1, 20), default=1, show_default=True,
              help="Repetitions of each generation prompt, for diversity.")
@click.option("--llm-max-queries", type=int, default=None,
              help="Label at most this many generated objects (cost cap).")
@click.option("--llm-max-tokens", type=click.IntRange(16, 8192), default=512,
              show_default=True, help="Longest LLM answer, in tokens (a small model that does "
              "not stop would otherwise fill the context).")
@click.option("--llm-slice", default=None, metavar="ROOMS,CATEGORIES,OBJECTS",
              help="A small generation: at most ROOMS room types, CATEGORIES object "
                   "categories per room, OBJECTS objects per category [default: 12,8,10].")
def command(out_dir: Path | None, report_only: bool, weights_dir: Path | None, as_json: bool,
            seed: int, holdout: float, epochs_containment: int, epochs_cooccurrence: int,
            keep: str, threads: int, source: str, llm_base_url: str | None, llm_model: str | None,
            llm_api_key: str | None, llm_cache: Path | None, llm_runs: int,
            llm_max_queries: int | None, llm_slice: str | None = None,
            llm_timeout: float = 30.0, llm_max_tokens: int = 512) -> None:
    """Train the containment and co-occurrence MLPs (SCOUT sec. IV-C) or report on them.

    By default the training data come from the training split of the household knowledge
    only, the encoder is the bundled all-MiniLM-L6-v2, and the run is deterministic: the
    same seed writes byte-identical files. Takes about a minute on 2 CPU cores.
    """
    from sgtool.datasets.relational import evaluation_sets, training_sets
    from sgtool.semantics.distill import DistillConfig, distill, format_report, quality_report

    if llm_slice is not None and source != "llm":
        raise SgtoolError("--llm-slice is for --source llm")
    if report_only:
        wd = weights_dir or _weights_dir()
        if not (wd / "metadata.json").is_file():
            raise SgtoolError(f"{wd}: no metadata.json; not a folder of distilled weights")
        try:
            seed = int(json.loads((wd / "metadata.json").read_text())["config"]["seed"])
        except (ValueError, KeyError, TypeError) as e:  # (JSONDecodeError is a ValueError)
            raise SgtoolError(f"{wd / 'metadata.json'}: not the metadata `sgtool distill` "
                              f"writes ({type(e).__name__}: {e})") from e
        built = training_sets(seed=seed)
        rep = quality_report(wd, (built.containment, built.cooccurrence),
                             eval_sets=evaluation_sets(seed=seed))
        click.echo(json.dumps(rep, indent=1, sort_keys=True) if as_json else format_report(rep))
        return

    require("torch")  # training needs the `learn` extra (before minutes of data building)
    cfg = DistillConfig(seed=seed, holdout=holdout, epochs_containment=epochs_containment,
                        epochs_cooccurrence=epochs_cooccurrence, keep=keep, threads=threads)
    eval_sets = None
    if source == "llm":
        sets, room_types, fingerprint = _llm_sets(llm_base_url, llm_model, llm_api_key,
                                                  llm_cache, llm_runs, llm_max_queries,
                                                  _slice(llm_slice), llm_timeout,
                                                  llm_max_tokens)
        _report_agreement(sets, training_sets(seed=seed))
    else:
        built = training_sets(seed=seed)
        sets = (built.containment, built.cooccurrence)
        room_types, fingerprint = built.room_types, built.split_fingerprint
        eval_sets = evaluation_sets(seed=seed)
    target = out_dir or _weights_dir()
    try:
        target.mkdir(parents=True, exist_ok=True)
        tmp = Path(tempfile.mkdtemp(prefix=".distill-", dir=target))
    except OSError as e:
        raise SgtoolError(f"cannot write weights to {target} ({e.strerror}); "
                          "choose a folder with --out") from e
    try:
        meta = distill(tmp, cfg, sets=sets, split_fingerprint=fingerprint,
                       room_types=room_types, progress=sys.stderr.isatty(),
                       eval_sets=eval_sets)
        for name in ("containment.safetensors", "cooccurrence.safetensors", "metadata.json"):
            os.replace(tmp / name, target / name)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    rep = meta["report"]
    if as_json:
        click.echo(json.dumps(meta, indent=1, sort_keys=True))
    else:
        for rel in ("containment", "cooccurrence"):
            m = meta["models"][rel]
            click.echo(f"{rel}: {m['data']['pairs']} pairs ({m['data']['positives']} positive), "
                       f"{m['data']['queries']} queries, kept epoch {m['best_epoch']}, "
                       f"val loss {m['history'][m['best_epoch'] - 1]['val_loss']:.4f}")
        click.echo(format_report(rep))
        click.echo(f"wrote {target}")


def _slice(text: str | None) -> dict[str, int]:
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


def _report_agreement(sets: Sequence[Any], reference: Any) -> None:
    """How the LLM's labels agree with the BEHAVIOR-1K knowledge (stderr)."""
    from sgtool.semantics.llm_knowledge import agreement

    for llm, ref in zip(sets, (reference.containment, reference.cooccurrence), strict=True):
        a = agreement(llm, ref)
        rate = "-" if a.common == 0 else f"{100 * a.rate:.1f}%"
        click.echo(f"LLM {a.relation} labels vs BEHAVIOR-1K: {a.common} of {a.llm_pairs} "
                   f"pairs in both, agreement {rate} ({a.agree}/{a.common})", err=True)


def _llm_sets(base_url: str | None, model: str | None, api_key: str | None,
              cache: Path | None, runs: int, max_queries: int | None,
              slice_kw: dict[str, int] | None = None, timeout_s: float = 30.0,
              max_tokens: int = 512) -> tuple[tuple[Any, Any], Any, str]:
    from sgtool.llm.client import LlmSettings, OpenAIChatClient
    from sgtool.semantics.cache import cache_root
    from sgtool.semantics.llm_knowledge import (
        CachedAsker,
        GenerationConfig,
        generate_sets,
    )

    cache = cache or (cache_root() / "llm-knowledge")
    try:
        client = OpenAIChatClient(LlmSettings.resolve(base_url, model, api_key,
                                                      timeout_s=timeout_s,
                                                      max_tokens=max_tokens))
    except SgtoolError:
        if not (cache / "exchanges.jsonl").is_file():
            raise
        client = None  # a complete cache replays the generation offline
    asker = CachedAsker(client, cache)
    cont, cooc, rooms = generate_sets(
        asker, GenerationConfig(runs=runs, max_queries=max_queries, **(slice_kw or {})),
        progress=sys.stderr.isatty())
    st = asker.stats
    click.echo(f"LLM knowledge: {len(rooms)} rooms, {len(cont.queries)} objects labelled; "
               f"{st.prompts} prompts ({st.cached} cached, {st.requested} asked, "
               f"{st.skipped} skipped)", err=True)
    import hashlib

    fp = hashlib.sha256((cont.fingerprint() + cooc.fingerprint()).encode()).hexdigest()
    return (cont, cooc), rooms, f"llm:{fp}"
