"""Planners: scene graph + query -> action.

The contract is :mod:`sgtool.planning.base`; planners are made by name with
:func:`sgtool.planning.registry.make_planner` (random, greedy, sbert, sbert-noroom, scout,
scout-noroom, scout-delta0, moma-llm).
"""
