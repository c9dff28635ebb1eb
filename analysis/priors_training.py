"""The work of `sgtool distill`: train the relational priors (containment and
co-occurrence MLPs) from the household knowledge or from an LLM, or report on trained
weights.

Training writes into a temporary folder inside the target and moves the three files
(containment.safetensors, cooccurrence.safetensors, metadata.json) in only when both models
are done, so an interrupted run never leaves a mixed set. ``note`` receives the progress
notes meant for stderr.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import sys
import tempfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from sgtool.errors import SgtoolError

Echo = Callable[[str], None]
WEIGHT_FILES = ("containment.safetensors", "cooccurrence.safetensors", "metadata.json")


@dataclass(frozen=True)
class LlmSource:
    """Where `--source llm` gets its labels: the endpoint (unset values from the
    environment), the answer cache folder (None: ``$SGTOOL_CACHE/llm-knowledge``), prompt
    repetitions, a cap on labelled objects, the generation slice (``max_rooms``,
    ``max_categories``, ``max_objects``; empty: the defaults), the request timeout (s) and
    the longest answer (tokens)."""

    base_url: str | None = None
    model: str | None = None
    api_key: str | None = None
    cache: Path | None = None
    runs: int = 1
    max_queries: int | None = None
    slice: dict[str, int] = field(default_factory=dict)
    timeout_s: float = 30.0
    max_tokens: int = 512


@dataclass(frozen=True)
class DistillRequest:
    """A checked `sgtool distill` training run: the weights folder to write, the training
    configuration (:class:`sgtool.semantics.distill.DistillConfig` fields) and the data
    source (``llm`` None: the training split of the household knowledge)."""

    target: Path
    seed: int = 0
    holdout: float = 0.0
    epochs_containment: int = 30
    epochs_cooccurrence: int = 5
    keep: str = "last"
    threads: int = 1
    llm: LlmSource | None = None


def weights_report(weights: Path) -> dict[str, Any]:
    """The quality report of the distilled weights in ``weights`` (on the categories held
    out of training with the seed their metadata records)."""
    from sgtool.datasets.relational import evaluation_sets, training_sets
    from sgtool.semantics.distill import quality_report

    if not (weights / "metadata.json").is_file():
        raise SgtoolError(f"{weights}: no metadata.json; not a folder of distilled weights")
    try:
        seed = int(json.loads((weights / "metadata.json").read_text())["config"]["seed"])
    except (ValueError, KeyError, TypeError) as e:  # (JSONDecodeError is a ValueError)
        raise SgtoolError(f"{weights / 'metadata.json'}: not the metadata `sgtool distill` "
                          f"writes ({type(e).__name__}: {e})") from e
    built = training_sets(seed=seed)
    return quality_report(weights, (built.containment, built.cooccurrence),
                          eval_sets=evaluation_sets(seed=seed))


def train_priors(request: DistillRequest, note: Echo) -> dict[str, Any]:
    """Train both models and move their files into ``request.target`` (created); returns
    the metadata written (with its ``report``)."""
    from sgtool.datasets.relational import evaluation_sets, training_sets
    from sgtool.extras import require
    from sgtool.semantics.distill import DistillConfig, distill

    require("torch")  # training needs the `learn` extra (before minutes of data building)
    cfg = DistillConfig(seed=request.seed, holdout=request.holdout,
                        epochs_containment=request.epochs_containment,
                        epochs_cooccurrence=request.epochs_cooccurrence, keep=request.keep,
                        threads=request.threads)
    eval_sets = None
    if request.llm is not None:
        sets, room_types, fingerprint = _llm_sets(request.llm, note)
        _report_agreement(sets, training_sets(seed=request.seed), note)
    else:
        built = training_sets(seed=request.seed)
        sets = (built.containment, built.cooccurrence)
        room_types, fingerprint = built.room_types, built.split_fingerprint
        eval_sets = evaluation_sets(seed=request.seed)
    tmp = _stage(request.target)
    try:
        meta: dict[str, Any] = distill(tmp, cfg, sets=sets, split_fingerprint=fingerprint,
                                       room_types=room_types, progress=sys.stderr.isatty(),
                                       eval_sets=eval_sets)
        for name in WEIGHT_FILES:
            os.replace(tmp / name, request.target / name)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return meta


def training_lines(meta: dict[str, Any]) -> list[str]:
    """One line per model of a training's metadata: pairs, queries, the epoch kept and
    its validation loss."""
    lines = []
    for rel in ("containment", "cooccurrence"):
        m = meta["models"][rel]
        lines.append(f"{rel}: {m['data']['pairs']} pairs ({m['data']['positives']} positive), "
                     f"{m['data']['queries']} queries, kept epoch {m['best_epoch']}, "
                     f"val loss {m['history'][m['best_epoch'] - 1]['val_loss']:.4f}")
    return lines


def _stage(target: Path) -> Path:
    """A new temporary folder inside ``target`` (created); one line when it cannot be."""
    try:
        target.mkdir(parents=True, exist_ok=True)
        return Path(tempfile.mkdtemp(prefix=".distill-", dir=target))
    except OSError as e:
        raise SgtoolError(f"cannot write weights to {target} ({e.strerror}); "
                          "choose a folder with --out") from e


def _report_agreement(sets: Sequence[Any], reference: Any, note: Echo) -> None:
    """How the LLM's labels agree with the BEHAVIOR-1K knowledge."""
    from sgtool.semantics.llm_knowledge import agreement

    for llm, ref in zip(sets, (reference.containment, reference.cooccurrence), strict=True):
        a = agreement(llm, ref)
        rate = "-" if a.common == 0 else f"{100 * a.rate:.1f}%"
        note(f"LLM {a.relation} labels vs BEHAVIOR-1K: {a.common} of {a.llm_pairs} "
             f"pairs in both, agreement {rate} ({a.agree}/{a.common})")


def _llm_sets(source: LlmSource, note: Echo) -> tuple[tuple[Any, Any], Any, str]:
    """(containment set, co-occurrence set), room types and the data fingerprint of an
    LLM generation (a complete cache replays it without an endpoint)."""
    from sgtool.llm.client import LlmSettings, OpenAIChatClient
    from sgtool.semantics.cache import cache_root
    from sgtool.semantics.llm_knowledge import CachedAsker, GenerationConfig, generate_sets

    cache = source.cache or (cache_root() / "llm-knowledge")
    try:
        client = OpenAIChatClient(LlmSettings.resolve(source.base_url, source.model,
                                                      source.api_key,
                                                      timeout_s=source.timeout_s,
                                                      max_tokens=source.max_tokens))
    except SgtoolError:
        if not (cache / "exchanges.jsonl").is_file():
            raise
        client = None  # a complete cache replays the generation offline
    asker = CachedAsker(client, cache)
    cont, cooc, rooms = generate_sets(
        asker, GenerationConfig(runs=source.runs, max_queries=source.max_queries,
                                **source.slice),
        progress=sys.stderr.isatty())
    st = asker.stats
    note(f"LLM knowledge: {len(rooms)} rooms, {len(cont.queries)} objects labelled; "
         f"{st.prompts} prompts ({st.cached} cached, {st.requested} asked, "
         f"{st.skipped} skipped)")
    fp = hashlib.sha256((cont.fingerprint() + cooc.fingerprint()).encode()).hexdigest()
    return (cont, cooc), rooms, f"llm:{fp}"
