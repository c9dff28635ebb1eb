"""Canonical text of a category name, shared by training data, planners and the encoder.

Category names arrive in several spellings: BEHAVIOR-1K synsets (``frying_pan.n.01``),
OmniGibson categories (``bottom_cabinet``), AI2-THOR types (``CounterTop``, ``TVStand``), free
text from a user (``Frying Pan``). The relational models are trained on one spelling and
queried with another, so every path into the encoder goes through :func:`category_text`:
CamelCase split into words, lowercase, underscores and hyphens to spaces, the WordNet sense
suffix dropped, whitespace collapsed. The function is pure and idempotent
(and memoised: planners call it for every node at every decision).
"""

from __future__ import annotations

import functools
import re
import unicodedata

_SENSE = re.compile(r"\.[a-zA-Z]\.\d+$")  # WordNet sense suffix: ".n.01"
_SPACES = re.compile(r"\s+")
# a word boundary inside CamelCase: "CounterTop" (lower, upper), "TVStand" (acronym, word)
_CAMEL = re.compile(r"(?<=[a-z0-9])(?=[A-Z])|(?<=[A-Z])(?=[A-Z][a-z])")


@functools.lru_cache(maxsize=65536)
def category_text(name: str) -> str:
    """``"Frying_Pan.n.01"`` -> ``"frying pan"``; ``"bottom-cabinet"`` -> ``"bottom cabinet"``;
    ``"TVStand"`` -> ``"tv stand"``; Unicode in its composed form (NFC)."""
    s = _SENSE.sub("", unicodedata.normalize("NFC", name).strip())
    s = _CAMEL.sub(" ", s).lower()
    s = s.replace("_", " ").replace("-", " ")
    return _SPACES.sub(" ", s).strip()


def same_category(a: str, b: str) -> bool:
    """Exact match of two category names after :func:`category_text` (no embeddings): the
    test that an object is of the query's category (a ``done`` that names one confirms
    the search: :func:`sgtool.planning.episode.confirms`)."""
    return category_text(a) == category_text(b)
