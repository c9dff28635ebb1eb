"""A golden check as text, Markdown and JUnit XML (pure functions of a
:class:`~sgtool.analysis.golden_check.CheckReport`).

The text and Markdown reports give, per log, :meth:`LogCheck.report
<sgtool.analysis.golden_check.LogCheck.report>` and then one summary table over all logs:
status, refreshes pinned and now, the first refresh that differs, the number of
differences per layer in it, the merged purity before and after and the first decision
that differs. The JUnit report has one test case per log (a failure for a changed log, an
error for a log that could not be checked) for CI systems.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any
from xml.sax.saxutils import escape, quoteattr

from sgtool.analysis.golden_check import CheckReport, LogCheck
from sgtool.analysis.report import pipe_table

LAYERS = ("rooms", "objects", "doors", "edges", "regions", "frontiers", "voronoi")
HEADER = ("log", "status", "refreshes", "first difference", *LAYERS, "purity (merged)",
          "decisions")


def _purity(q: tuple[dict[str, Any] | None, dict[str, Any] | None]) -> str:
    b, a = q
    if b is None or a is None or "merged" not in b or "merged" not in a:
        return "-"
    x, y = b["merged"].get("purity"), a["merged"].get("purity")
    if x is None or y is None:
        return "-"
    return f"{x:.3f}" if x == y else f"{x:.3f} -> {y:.3f}"


def summary_rows(logs: Sequence[LogCheck]) -> list[list[str]]:
    rows = []
    for c in logs:
        pinned, now = c.refreshes
        if c.status == "error":
            rows.append([c.name, "error", "-", c.error or "", *("-" for _ in LAYERS), "-", "-"])
            continue
        rows.append([c.name, c.status, str(now) if pinned == now else f"{pinned} -> {now}",
                     c.first or "-", *(str(c.layers.get(k, 0)) for k in LAYERS),
                     _purity(c.quality), "changed" if c.decision else "-"])
    return rows


def summary_line(report: CheckReport) -> str:
    n = report.counts()
    return (f"{len(report.logs)} pinned log(s): {n['unchanged']} unchanged, {n['changed']} "
            f"changed, {n['error']} error(s)")


def text_report(report: CheckReport) -> list[str]:
    """What ``sgtool golden check`` prints."""
    out: list[str] = []
    for c in report.logs:
        out += c.report()
    out += ["", pipe_table(HEADER, summary_rows(report.logs)), summary_line(report)]
    return out


def markdown_report(report: CheckReport, accepted: Sequence[str] = ()) -> str:
    """``--report FILE.md``: the per-log reports as sections, then the summary table;
    ``accepted``: what ``--update`` accepted (one line per log), as its last section."""
    parts = [f"# Golden check of {report.pins.folder}", "", summary_line(report), ""]
    for c in report.logs:
        lines = c.report()
        parts += [f"## {c.name}: {c.status}", "", "```", *lines, "```", ""]
    parts += ["## Summary", "", pipe_table(HEADER, summary_rows(report.logs)), ""]
    if accepted:
        parts += ["## Accepted (--update)", "", *(f"- {x}" for x in accepted), ""]
    return "\n".join(parts)


def junit_report(report: CheckReport, accepted: Sequence[str] = ()) -> str:
    """``--junit FILE.xml``: one ``testcase`` per log (JUnit XML as CI systems read it); a
    changed log whose change ``--update`` accepted (its name in ``accepted``) passes, with
    its report as its output."""
    done = set(accepted)
    cases = []
    failures = errors = 0
    for c in report.logs:
        body = ""
        text = escape("\n".join(c.report()))
        if c.status == "changed" and c.name in done:
            body = f"<system-out>{text}</system-out>"
        elif c.status == "changed":
            failures += 1
            body = f"<failure message={quoteattr(c.first or 'changed')}>{text}</failure>"
        elif c.status == "error":
            errors += 1
            body = f"<error message={quoteattr(c.error or 'error')}>{text}</error>"
        cases.append(f'  <testcase classname="sgtool.golden" name={quoteattr(c.name)}>'
                     f"{body}</testcase>")
    return ("<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"
            f"<testsuite name=\"sgtool golden\" tests=\"{len(report.logs)}\" "
            f"failures=\"{failures}\" errors=\"{errors}\">\n"
            + "\n".join(cases) + "\n</testsuite>\n")


def error_reports(folder: str, error: str) -> tuple[str, str]:
    """(Markdown, JUnit XML) of a check that could not start (a damaged or missing pin
    folder): one error, so a report left by an earlier check is never taken for this
    one."""
    md = f"# Golden check of {folder}\n\nerror: {error}\n"
    xml = ("<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"
           "<testsuite name=\"sgtool golden\" tests=\"1\" failures=\"0\" errors=\"1\">\n"
           f'  <testcase classname="sgtool.golden" name={quoteattr(folder)}>'
           f"<error message={quoteattr(error)}>{escape(error)}</error></testcase>\n"
           "</testsuite>\n")
    return md, xml
