"""The work of `sgtool distill`: train the relational priors (containment and
co-occurrence MLPs) from the household knowledge or from an LLM, or report on trained
weights.

Training writes into a temporary folder inside the target and moves the three files
(containment.safetensors, cooccurrence.safetensors, metadata.json) in only when both models
are done, so an interrupted run never leaves a mixed set. ``note`` receives the progress
notes meant for stderr.
"""

from __future__ import annotations

import contextlib
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
    source (``llm`` None: the training split of the household knowledge). ``room_blend``:
    train on the widened room knowledge and write a held-out-fitted room blend
    (:func:`blend_training`)."""

    target: Path
    seed: int = 0
    holdout: float = 0.0
    epochs_containment: int = 30
    epochs_cooccurrence: int = 5
    keep: str = "last"
    threads: int = 1
    llm: LlmSource | None = None
    room_blend: bool = False


def weights_report(weights: Path) -> dict[str, Any]:
    """The quality report of the distilled weights in ``weights`` (on the categories held
    out of training with the seed their metadata records)."""
    from sgtool.datasets.relational import evaluation_sets, training_sets
    from sgtool.semantics.distill import quality_report
    from sgtool.semantics.priors import LearnedPriors

    if not (weights / "metadata.json").is_file():
        raise SgtoolError(f"{weights}: no metadata.json; not a folder of distilled weights")
    try:
        meta = json.loads((weights / "metadata.json").read_text())
        seed = int(meta["config"]["seed"])
        if not isinstance(meta["heldout_queries"], list):
            raise TypeError("heldout_queries is not a list")
    except (ValueError, KeyError, TypeError, UnicodeDecodeError) as e:  # (JSON errors too)
        raise SgtoolError(f"{weights / 'metadata.json'}: not the metadata `sgtool distill` "
                          f"writes ({type(e).__name__}: {e})") from e
    LearnedPriors(weights_dir=weights)  # the planners' own checks: files, sizes, encoder
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
        if request.room_blend:
            raise SgtoolError("--room-blend needs --source knowledge")
        sets, room_types, fingerprint = _llm_sets(request.llm, note)
        _report_agreement(sets, training_sets(seed=request.seed), note)
    else:
        built = training_sets(seed=request.seed)
        sets = (built.containment, built.cooccurrence)
        room_types, fingerprint = built.room_types, built.split_fingerprint
        eval_sets = evaluation_sets(seed=request.seed)
        if request.room_blend:
            sets = (widened_containment(built.containment, room_types), built.cooccurrence)
    # the folders this run creates (the target and missing parents) go again on failure
    made = [d for d in (request.target, *request.target.parents) if not d.exists()]
    tmp = _stage(request.target)
    done = False
    try:
        meta: dict[str, Any] = distill(tmp, cfg, sets=sets, split_fingerprint=fingerprint,
                                       room_types=room_types, progress=sys.stderr.isatty(),
                                       eval_sets=eval_sets)
        files: tuple[str, ...] = WEIGHT_FILES
        if request.room_blend:
            from sgtool.semantics.room_blend import BLEND_FILE, VECTORS_FILE, save_room_blend

            blend, fit = blend_training(sets, cfg, room_types, fingerprint, meta, tmp, note)
            save_room_blend(tmp, blend, {"fit": fit})
            meta["room_blend"] = fit
            files = (*WEIGHT_FILES, BLEND_FILE, VECTORS_FILE)
        for name in files:
            os.replace(tmp / name, request.target / name)
        if not request.room_blend:
            from sgtool.semantics.room_blend import BLEND_FILE, VECTORS_FILE

            for name in (BLEND_FILE, VECTORS_FILE):  # no stale blend
                (request.target / name).unlink(missing_ok=True)
        done = True
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
        for d in made if not done else ():
            with contextlib.suppress(OSError):  # empty unless the moves had begun
                d.rmdir()
    for stale in sorted(request.target.glob(".distill-*")):  # a run killed outright
        if stale.is_dir():
            note(f"sgtool: note: {stale} is the unfinished output of a distill that was "
                 "killed (or one still running); remove it when none is")
    return meta


BLEND_HOLDOUT = 0.2  # share of the training names held out to fit the room blend on


def widened_containment(containment: Any, room_types: Sequence[str]) -> Any:
    """The containment set with the room knowledge widened
    (:mod:`sgtool.semantics.room_knowledge`): room types a house does not have folded into
    the household type of most alike contents, then ProcTHOR's room annotations
    (:mod:`sgtool.datasets.room_annotations`, the shipped table) added: a name both sources
    know gets the mean of their targets per annotated room type, a new name its
    annotations (:func:`sgtool.semantics.room_knowledge.add_room_targets`)."""
    from sgtool.datasets.room_annotations import load_levels, room_targets
    from sgtool.semantics.room_knowledge import add_room_targets, fold_room_types

    return add_room_targets(fold_room_types(containment, room_types),
                            room_targets(load_levels()))


def blend_training(sets: Any, cfg: Any, room_types: Sequence[str], fingerprint: str | None,
                   meta: dict[str, Any], work: Path, note: Echo) -> tuple[Any, dict[str, Any]]:
    """The room blend of a training and its fit report: a second model is
    trained without :data:`BLEND_HOLDOUT` of the query names (into ``work/heldout``), the
    blend's parameters are fitted on those names
    (:func:`sgtool.semantics.room_blend.fit_room_blend`), and the document holds them with
    the room table and training names of the full training (``meta``) and, under
    ``fit``, the held-out top-1 accuracy of the learned model, the cosine and the blend."""
    from dataclasses import replace

    from sgtool.semantics.distill import distill
    from sgtool.semantics.encoder import default_encoder
    from sgtool.semantics.everyday_rooms import scoreable_room_types
    from sgtool.semantics.priors import CosinePriors, LearnedPriors
    from sgtool.semantics.room_blend import (
        RoomBlend,
        fit_room_blend,
    )
    from sgtool.semantics.room_knowledge import room_table

    cont = sets[0]
    note(f"room blend: training without {BLEND_HOLDOUT:.0%} of the names to fit on")
    ho_cfg = replace(cfg, holdout=BLEND_HOLDOUT, epochs_cooccurrence=1)
    ho_meta = distill(work / "heldout", ho_cfg, sets=sets, split_fingerprint=fingerprint,
                      room_types=tuple(room_types))
    enc = default_encoder()
    learned = LearnedPriors(enc, work / "heldout")
    rooms = scoreable_room_types(learned)
    train_q = set(ho_meta["training_queries"])
    held = heldout_names(cont, set(ho_meta["heldout_queries"]), rooms)
    params, acc = fit_room_blend(room_table(cont.subset_queries(train_q), room_types),
                                 sorted(train_q), held, rooms, learned.rooms, enc)
    cosine = CosinePriors(enc)
    fit = {"heldout_names": len(held), "rooms": list(rooms), "blend_top1": acc,
           "learned_top1": top1(held, rooms, learned.rooms),
           "cosine_top1": top1(held, rooms, cosine.rooms),
           "holdout": BLEND_HOLDOUT, "seed": cfg.seed}
    note(f"room blend: held-out top-1 learned {fit['learned_top1']:.3f}, cosine "
         f"{fit['cosine_top1']:.3f}, blend {acc:.3f} ({len(held)} names)")
    full = set(meta["training_queries"])
    return RoomBlend(room_table(cont.subset_queries(full), room_types), sorted(full), params,
                     enc), fit


def heldout_names(containment: Any, held: set[str], rooms: Sequence[str]) -> list[Any]:
    """The held-out names with a target of 1 in one of ``rooms`` (their best rooms),
    sorted."""
    from sgtool.semantics.room_blend import HeldOutName
    from sgtool.semantics.text import category_text

    keep = {category_text(r) for r in rooms}
    best: dict[str, set[str]] = {}
    for (n, q), y in zip(containment.pairs, containment.targets, strict=True):
        name, room = containment.queries[int(q)], category_text(containment.nodes[int(n)])
        if name in held and room in keep and y >= 0.999:
            best.setdefault(name, set()).add(room)
    return [HeldOutName(n, frozenset(r)) for n, r in sorted(best.items())]


def top1(held: Sequence[Any], rooms: Sequence[str],
         score: Callable[[Sequence[str], str], Any]) -> float:
    """Share of ``held`` whose top-scored room (first on ties) is one of its best rooms."""
    from sgtool.semantics.text import category_text

    if not held:
        return 0.0
    hits = 0
    for h in held:
        s = list(score(rooms, h.name))
        hits += category_text(rooms[s.index(max(s))]) in h.best_rooms
    return hits / len(held)


def training_lines(meta: dict[str, Any]) -> list[str]:
    """One line per model of a training's metadata: pairs, queries, the epoch kept and
    its validation loss; with queries held out of training, the pairs trained on (and
    validated on) of all, and the queries held out."""
    lines = []
    held = len(meta.get("heldout_queries", ()))
    for rel in ("containment", "cooccurrence"):
        m = meta["models"][rel]
        d = m["data"]
        data = f"{d['pairs']} pairs ({d['positives']} positive), {d['queries']} queries"
        if held:
            data = (f"{m['train_pairs'] + m['val_pairs']} of {d['pairs']} pairs trained "
                    f"on ({held} {'query' if held == 1 else 'queries'} held out of training)")
        lines.append(f"{rel}: {data}, kept epoch {m['best_epoch']}, "
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
