"""Evaluate planners against the decisions recorded in episode logs.

Run::

    sgtool bench --planners greedy --houses 1 --episodes 3 --seeds 1 -o bench/ \\
        --log-dir bench/logs
    python examples/evaluate_logged.py bench/logs/*/*/*.mcap --planner greedy --planner scout

First the metrics of the logged episodes (SR, SPL, steps, AUC-E: what ``sgtool eval LOGS``
prints), then, per ``--planner``, how its choices compare with what was done: at every
logged decision point the planner decides on the logged scene graph, its action is
compared with the logged one (same action, same target, same room, not a node of the
graph), and it is then told the logged outcome (teacher forcing), as ``sgtool eval LOGS
-p NAME`` does. A planner is a built-in name or a plug-in ``module:Name`` on ``sys.path``
(``my_planner:MyPlanner`` with this folder on ``PYTHONPATH``).

Logs with decisions and scene graphs come from ``sgtool bench --log-dir``, ``sgtool run``
and ``sgtool run-bench``.
"""

from __future__ import annotations

import argparse

import sgtool


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("logs", nargs="+", help="episode logs (MCAP) or episodes.jsonl files")
    parser.add_argument("-p", "--planner", action="append", default=[],
                        help="a planner to ask at every logged decision (repeatable)")
    args = parser.parse_args()

    notes: list[str] = []
    results, logged = sgtool.load_results(args.logs, notes)
    for note in notes:  # episodes left out (not a search, impossible figures)
        print(f"note: {note}")
    if not results:
        raise sgtool.SgtoolError("no search episodes in " + ", ".join(args.logs))
    models = sgtool.cost_models()
    print(sgtool.format_table(sgtool.summarize(results, models), models=models,
                              title=f"Metrics of {len(results)} logged episode(s)"))
    if args.planner:
        if not any(d.graph is not None for e in logged for d in e.decisions):
            raise sgtool.SgtoolError("--planner needs logs with scene graphs (MCAP)")
        reports = [sgtool.replay_decisions(sgtool.make_planner(name), logged, name=name)
                   for name in args.planner]
        print(sgtool.format_offline(reports))


if __name__ == "__main__":
    try:
        main()
    except sgtool.SgtoolError as e:
        raise SystemExit(f"evaluate_logged: {e}") from None
