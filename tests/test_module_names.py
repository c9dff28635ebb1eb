"""Module names are unique across the package: one basename, one meaning.

A module is found by its name (``grep``, an editor's file search, a traceback's last line);
two ``metrics.py`` that mean different things send a reader to the wrong one. A basename may
repeat only when listed below with the reason the modules mean the same thing.
"""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGE_FOLDERS = ("toolkit", "recorders", "replayers", "datasets", "analysis")

# basename -> why every module of that name means the same thing
SAME_MEANING: dict[str, str] = {
    "__init__.py": "the package marker of every sub-package",
    "bench.py": "commands/bench.py is the `sgtool bench` front of analysis/bench.py",
    "demo.py": "commands/demo.py is the `sgtool demo` front of datasets/demo.py",
    "distill.py": "commands/distill.py is the `sgtool distill` front of semantics/distill.py",
    "golden.py": "commands/golden.py is the `sgtool golden` front of replayers/golden.py",
}

# basename -> the rename still to make (the modules mean different things; their folders were
# being edited by other engineers when this test was written). Remove a line with the rename.
RENAME_PENDING: dict[str, str] = {}


def _modules_by_basename() -> dict[str, list[str]]:
    found: dict[str, list[str]] = defaultdict(list)
    for folder in PACKAGE_FOLDERS:
        for path in sorted((ROOT / folder).rglob("*.py")):
            found[path.name].append(str(path.relative_to(ROOT)))
    return found


def test_no_module_basename_repeats_across_the_package() -> None:
    allowed = SAME_MEANING.keys() | RENAME_PENDING.keys()
    repeated = {
        name: paths for name, paths in _modules_by_basename().items()
        if len(paths) > 1 and name not in allowed
    }
    assert not repeated, (
        "module names repeat (rename the one that means something else, or list the name in "
        f"SAME_MEANING with the reason): {repeated}"
    )


def test_every_allowed_name_still_repeats() -> None:
    """An allow-list line whose modules no longer repeat is stale: remove it."""
    found = _modules_by_basename()
    stale = sorted(
        name for name in SAME_MEANING.keys() | RENAME_PENDING.keys() if len(found[name]) < 2
    )
    assert not stale, f"listed but no longer repeated: {stale}"


def test_the_check_sees_a_repeat() -> None:
    """The walk finds the package's modules, so the first test is not vacuous."""
    found = _modules_by_basename()
    assert len(found["__init__.py"]) > 5
    assert found["cli.py"] == ["toolkit/cli.py"]
