"""Metrics, reports and exports of object-search runs.

Modules (import them directly; this package imports nothing on its own):

- :mod:`sgtool.results`: the per-episode record (:class:`EpisodeResult`), its JSONL
  file, the digest without wall-clock figures, the mapping from log records;
- :mod:`sgtool.analysis.search_metrics`: SR, SPL, steps, decision time, MoMa-LLM's AUC-E (distance
  plus open cost, and step budget), mean ± std over seeds, seen/unseen breakdown;
- :mod:`sgtool.analysis.report`: tables in the shape of SCOUT's Tables VII and IX;
- :mod:`sgtool.analysis.curves`: efficiency curves as PNG;
- :mod:`sgtool.analysis.intervals`: cluster-bootstrap intervals over houses, paired planner
  comparisons (SPL ratio, SR difference, wins per house), Kendall's tau of two orders;
- :mod:`sgtool.analysis.bench`: the symbolic benchmark run (``sgtool bench``, ``run_bench``);
- :mod:`sgtool.analysis.closed_loop_tables`: the closed-loop tables that separate planners;
- :mod:`sgtool.analysis.offline`: metrics from logs and planners against logged decisions
  (``sgtool eval``);
- :mod:`sgtool.analysis.rerun_view`: Rerun export of logs.
"""
