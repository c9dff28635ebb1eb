"""`sgtool bench` never writes an API key given as a planner option."""

from __future__ import annotations

import sys

from click.testing import CliRunner

from sgtool.cli import cli

KEY = "sk-bench-SECRET-987654"


def test_bench_summaries_hold_no_api_key(tmp_path, monkeypatch):
    out = tmp_path / "bench"
    args = ["bench", "--planners", "random", "--houses", "1", "--episodes", "1", "--seeds",
            "1", "-O", f"moma-llm.api_key={KEY}", "-o", str(out)]
    monkeypatch.setattr(sys, "argv", ["sgtool", *args])  # the command line in run.md
    r = CliRunner().invoke(cli, args)
    assert r.exit_code == 0, r.output
    assert KEY not in r.output
    files = sorted(p for p in out.iterdir() if p.suffix in (".md", ".json", ".jsonl"))
    assert {p.name for p in files} >= {"summary.md", "summary.json", "episodes.jsonl",
                                       "run.md", "run.json"}
    for p in files:
        assert KEY not in p.read_text(), p.name
    # an option of a planner not run is no setting of the run (a note said it is unused)
    assert '"moma-llm"' not in (out / "summary.json").read_text()
    assert "moma-llm.api_key=<redacted>" in (out / "run.md").read_text()
    assert "moma-llm.api_key=<redacted>" in (out / "run.json").read_text()
