"""The house spec: the versioned ``house.json`` every log carries (rooms, walls, doors,
passages, furniture, small objects, start pose).

Modules: :mod:`~sgtool.house.spec` (the records and their canonical JSON),
:mod:`~sgtool.house.parse` (validation of a parsed JSON document),
:mod:`~sgtool.house.io` (``load_house`` / ``save_house``), :mod:`~sgtool.house.geometry`
(polygon and box helpers)."""
