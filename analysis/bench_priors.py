"""Which planners of a benchmark load the learned priors, and which priors: the
``--priors`` folder reaches every planner whose options name one (``weights_dir``), the
priors' training vocabulary decides what counts as a seen query, and a fingerprint of the
weights traces a table to the priors behind it."""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from sgtool.analysis.bench import BenchConfig


def _priors_planners() -> tuple[str, ...]:
    """The built-in planners whose options name a folder of distilled priors
    (``weights_dir``): read off the registry, so a new one cannot be forgotten here."""
    from dataclasses import fields

    from sgtool.planning.registry import REGISTRY

    return tuple(name for name, entry in REGISTRY.items()
                 if any(f.name == "weights_dir" for f in fields(entry.options)))


PRIORS_PLANNERS = _priors_planners()


def takes_priors(name: str) -> bool:
    """Whether planner ``name`` loads a folder of priors: a built-in of
    :data:`PRIORS_PLANNERS`, or a plug-in whose options have a ``weights_dir`` field (one
    that cannot be imported here: no)."""
    from sgtool.planning.option_fields import option_infos
    from sgtool.planning.registry import REGISTRY, options_of

    if name in PRIORS_PLANNERS or name.strip().lower() in REGISTRY:
        return name in PRIORS_PLANNERS
    try:
        cls = options_of(name)
    except Exception:  # noqa: BLE001 - its own build says why, where it runs
        return False
    return cls is not None and any(i.name == "weights_dir" for i in option_infos(cls))


def planner_options_for(cfg: BenchConfig, name: str) -> dict[str, Any]:
    """The options ``name`` is built with: the configured ones, and for the planners that
    load priors (:func:`takes_priors`, a plug-in's ``weights_dir`` too) the weights of
    ``cfg.priors_dir`` unless an option names other weights."""
    opts = dict(cfg.planner_options.get(name, {}))
    if cfg.priors_dir is not None and takes_priors(name):
        opts.setdefault("weights_dir", cfg.priors_dir)
    return opts


def training_vocabulary(priors_dir: str | None) -> frozenset[str]:
    """The training queries of the priors in ``priors_dir`` (the shipped ones by default):
    the names a bench counts as seen."""
    from sgtool.semantics.priors import training_queries

    return training_queries(priors_dir)


def priors_fingerprint(weights_dir: str | os.PathLike[str] | None = None) -> str:
    """SHA-256 (first 16 hex digits) of the relational-prior weights the scout planners load
    (the shipped ones by default): the models, their metadata and the room blend when the
    folder has one (:mod:`sgtool.semantics.room_blend`), so a table can be traced to the
    priors behind it."""
    import hashlib

    from sgtool.semantics.priors import weights_folder
    from sgtool.semantics.room_blend import BLEND_FILE, VECTORS_FILE

    h = hashlib.sha256()
    for p in sorted(weights_folder(weights_dir).glob("*")):
        if p.is_file() and (p.suffix == ".safetensors"
                            or p.name in ("metadata.json", BLEND_FILE, VECTORS_FILE)):
            h.update(p.name.encode())
            h.update(p.read_bytes())
    return h.hexdigest()[:16]
