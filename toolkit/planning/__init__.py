"""Planners: scene graph + query -> action.

The contract is :mod:`sgtool.planning.base`; planners are made by name with
:func:`sgtool.planning.registry.make_planner` from the registry's table
(:data:`sgtool.planning.registry.REGISTRY`, ``sgtool bench --list-planners``) or a plug-in
(``module:Name``, the entry-point group ``sgtool.planners``: :mod:`sgtool.planning.plugins`).
"""
