"""Semantic reasoning: the sentence encoder and SCOUT's distilled relational priors.

- :mod:`~sgtool.semantics.encoder`: all-MiniLM-L6-v2 (bundled weights, numpy forward pass,
  one text at a time), with an on-disk cache (:mod:`~sgtool.semantics.cache`);
- :mod:`~sgtool.semantics.priors`: ``LearnedPriors`` (containment and co-occurrence MLPs,
  SCOUT Eqs. 10-11) and ``CosinePriors`` (SBERT similarity, Eqs. 14-15);
- :mod:`~sgtool.semantics.distill`, :mod:`~sgtool.semantics.training`: training them
  (``sgtool distill``), :mod:`~sgtool.semantics.llm_knowledge`: SCOUT's optional LLM
  knowledge generation;
- :mod:`~sgtool.semantics.room_classification`: room categories from contents with the
  containment model;
- :mod:`~sgtool.semantics.relational_set`: the training-set type of a relation;
  :mod:`~sgtool.semantics.everyday_rooms`: 74 everyday objects outside BEHAVIOR-1K's names
  with the room a person searches first, to check any prior's top-1 room accuracy
  (``benchmarks/priors_check.py``).

Importing this package is cheap; submodules load numpy, torch or the model only when used.
"""
