"""Room categories from room contents with the distilled containment model.

SCOUT infers room categories "from the objects they contain" (sec. IV-A); MoMa-LLM asks an
LLM. Offline we combine the containment model's p_contains(r, o) over the objects seen in a
room, naive-Bayes style: each object votes with its distribution over room types
p(r | o) = p_contains(r, o) / sum_r' p_contains(r', o), and the room's posterior with a
uniform prior is proportional to the product of the votes (a sum of logs). An object found
everywhere (a chair) has a flat distribution and barely votes; a toilet votes hard for the
bathroom. The label set is the room types of the training knowledge (stored with the
weights), so classification needs no data at run time.

Same interface as the frequency classifier of :mod:`sgtool.scenegraph.categories`:
``classify(object_categories) -> [(room type, probability), ...]`` best first.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from sgtool.semantics.priors import LearnedPriors, default_priors
from sgtool.semantics.text import category_text

EPS = 1e-3  # floor of p_contains so that one unusual object cannot veto a room


class ContainmentRoomClassifier:
    """Room type posterior from contained object categories (module doc)."""

    name = "containment"

    def __init__(self, priors: LearnedPriors | None = None,
                 room_types: Sequence[str] | None = None, temperature: float = 1.0) -> None:
        self.priors = priors or default_priors()
        types = tuple(room_types) if room_types is not None else self.priors.room_types
        if not types:
            raise ValueError("no room types: the weights' metadata lists none and none given")
        # keep the spelling of the knowledge ("living_room"), embed the words
        self.room_types = tuple(sorted(set(types)))
        self.temperature = float(temperature)
        self._votes: dict[str, np.ndarray] = {}
        enc = self.priors.encoder
        self._room_vecs = enc.encode([category_text(t) for t in self.room_types])

    def votes(self, category: str) -> np.ndarray:
        """log p(r | o) over :attr:`room_types` for one object category (memoised)."""
        key = category_text(category)
        v = self._votes.get(key)
        if v is None:
            q = self.priors.encoder.encode([key])[0]
            p = np.maximum(self.priors.containment(self._room_vecs, q), EPS)
            v = np.log(p / p.sum())
            self._votes[key] = v
        return v

    def classify(self, object_categories: list[str]) -> list[tuple[str, float]]:
        """[(room type, probability)] best first; [] for an empty room (unknown)."""
        cats = [c for c in object_categories if category_text(c)]
        if not cats:
            return []
        total = np.zeros(len(self.room_types))
        for c in cats:
            total += self.votes(c)
        z = total / self.temperature
        z -= z.max()
        p = np.exp(z)
        p /= p.sum()
        order = sorted(range(len(p)), key=lambda i: (-p[i], self.room_types[i]))
        return [(self.room_types[i], float(p[i])) for i in order]
