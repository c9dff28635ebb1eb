"""Tests, benchmarks, tools and examples import only sgtool's public names.

A test that imports ``sgtool.x._name`` pins an implementation detail: a rename inside the
module breaks the test though nothing a user sees changed, and a reader cannot tell the
module's contract from its helpers. What a test needs is public (a name without the
underscore, documented as the contract it is) or lives in ``tests/support`` (a reference
implementation or a test helper).

:data:`PENDING` lists the files that still import private names, each with how many; it only
shrinks: a file with fewer than its entry fails until the entry is lowered (or removed at 0).
"""

from __future__ import annotations

import ast
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
FOLDERS = ("tests", "benchmarks", "tools", "examples")

PENDING: dict[str, int] = {}


def private_imports(source: str) -> list[str]:
    """``module.name`` of every ``from sgtool... import _name`` of ``source`` (dunder names
    aside), nested imports included."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[0] == "sgtool":
            found += [f"{node.module}.{a.name}" for a in node.names
                      if a.name.startswith("_") and not a.name.startswith("__")]
    return found


def _files() -> list[Path]:
    return sorted(p for f in FOLDERS if (REPO / f).is_dir() for p in (REPO / f).rglob("*.py"))


def test_the_scan_sees_a_private_import() -> None:
    source = ("from sgtool.mapping import voronoi\n"
              "def f():\n    from sgtool.mapping.voronoi import _x, thin, __all__\n")
    assert private_imports(source) == ["sgtool.mapping.voronoi._x"]


def test_no_private_name_of_sgtool_is_imported() -> None:
    found = {p.relative_to(REPO).as_posix(): private_imports(p.read_text("utf8"))
             for p in _files()}
    report = [f"{name}: {', '.join(names)}" for name, names in found.items()
              if names and name not in PENDING]
    assert not report, "private sgtool names imported (make them public or move the " \
        "helper to tests/support):\n" + "\n".join(report)


def test_pending_files_only_shrink() -> None:
    for name, allowed in PENDING.items():
        path = REPO / name
        count = len(private_imports(path.read_text("utf8"))) if path.exists() else 0
        assert count <= allowed, f"{name}: {count} private imports, pending allows {allowed}"
        assert count == allowed, (f"{name}: {count} private imports now, lower its PENDING "
                                  f"entry from {allowed} (to remove it at 0)")
