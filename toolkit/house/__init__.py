"""The house spec: the versioned ``house.json`` every log carries (rooms, walls, doors,
passages, furniture, small objects, start pose).

Modules: :mod:`~sgtool.house.spec` (the records, their canonical JSON, the limits),
:mod:`~sgtool.house.parse` (validation of a parsed JSON document),
:mod:`~sgtool.house.migrate` (version 1 -> 2), :mod:`~sgtool.house.nesting` (the
containment tree of small objects), :mod:`~sgtool.house.consistency` (rooms, doors and
furniture against each other), :mod:`~sgtool.house.io` (``load_house`` / ``save_house``),
:mod:`~sgtool.house.geometry` (polygon and box helpers), :mod:`~sgtool.house.names` (rules
for ids and names, the number an id ends with)."""
