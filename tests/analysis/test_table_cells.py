"""Markdown tables keep one row per line and one cell per column whatever the names hold:
'|' is escaped as '\\|', a line break shown as '\\n' (sgtool.analysis.report.table_cell),
in every table the bench and run-bench write (all go through pipe_table)."""

from __future__ import annotations

import re
from pathlib import Path

from support.foreign_house import cottage, write_cottage

from sgtool.analysis.bench import BenchConfig, run_benchmark, write_outputs
from sgtool.analysis.report import pipe_table, table_cell


def _cells(line: str) -> list[str]:
    return re.split(r"(?<!\\)\|", line)[1:-1]


def test_cells_escape_pipes_and_line_breaks() -> None:
    assert table_cell("salt | pepper\nmill") == "salt \\| pepper\\nmill"
    assert table_cell("a\r\nb\rc\u2028d") == "a\\nb\\nc\\nd"
    assert table_cell("plain name") == "plain name"
    text = pipe_table(["Query", "SR"], [["salt | pepper\nmill", "1.000"], ["mug", "0.5"]])
    lines = text.splitlines()
    assert len(lines) == 4 and all(len(_cells(s)) == 2 for s in lines)
    assert lines[2] == "| salt \\| pepper\\nmill | 1.000 |"


def test_bench_tables_keep_a_name_with_a_pipe_in_its_cell(tmp_path: Path) -> None:
    d = cottage()
    d["objects"][1]["category"] = "salt | pepper"  # the mug on the counter
    house = write_cottage(tmp_path / "h", "cottage.json", objects=d["objects"])
    res = run_benchmark(BenchConfig(planners=("greedy",), houses=0, episodes=5, seeds=1,
                                    house_files=(str(house),)), progress=False)
    write_outputs(res, tmp_path / "out")
    per_query = (tmp_path / "out/per_query.md").read_text()
    assert "| salt \\| pepper " in per_query
    for name in ("per_query.md", "per_house.md", "summary.md", "run.md"):
        widths = {len(_cells(s)) for s in (tmp_path / "out" / name).read_text().splitlines()
                  if s.startswith("| ") and "salt" in s}
        assert widths in (set(), {4}), name  # Query, Seen, Episodes, greedy SR / SPL
