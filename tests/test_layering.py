"""The package layers of DESIGN.md ("Layers"): imports flow one way.

Every ``import``/``from`` of an ``sgtool`` module anywhere in a module (top level or inside a
function) is checked against the ranks below: a module may import its own layer and the
layers of lower rank, never a layer of its own rank or above. ``recorders`` and
``replayers`` share a rank, so neither imports the other.

The package ``sgtool`` itself (``toolkit/__init__.py``) is the public facade: it re-exports
names of every layer (lazily), so it is a top layer beside the CLI, and no module of the
package may import from it (``from sgtool import __version__`` in the core would be an
import upwards; the version lives in ``sgtool.version``). The facade and the CLI share a
rank: neither imports the other.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
FOLDERS = {"toolkit": "sgtool", "recorders": "sgtool.recorders",
           "replayers": "sgtool.replayers", "datasets": "sgtool.datasets",
           "analysis": "sgtool.analysis"}
RANK = {"core": 0, "datasets": 1, "recorders": 2, "replayers": 2, "analysis": 3, "commands": 4,
        "facade": 4}


def layer(module: str) -> str:
    """The layer of a dotted module name under ``sgtool``."""
    if module == "sgtool":
        return "facade"
    parts = module.split(".")
    if len(parts) > 1 and parts[1] in ("recorders", "replayers", "datasets", "analysis"):
        return parts[1]
    if len(parts) > 1 and parts[1] in ("commands", "cli", "__main__"):
        return "commands"  # __main__: `python -m sgtool`, the command line
    return "core"


def module_name(path: Path) -> str:
    rel = path.relative_to(REPO).with_suffix("")
    parts = [p for p in rel.parts[1:] if p != "__init__"]
    return ".".join([FOLDERS[rel.parts[0]], *parts])


def sgtool_imports(source: str) -> list[tuple[int, str]]:
    """(line, imported module) of every absolute sgtool import in ``source``."""
    out = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            if node.module.startswith("sgtool"):
                out.append((node.lineno, node.module))
        elif isinstance(node, ast.Import):
            out.extend((node.lineno, a.name) for a in node.names if a.name.startswith("sgtool"))
    return out


def violations(module: str, source: str, where: str) -> list[str]:
    """One line per import of ``source`` (the text of ``module``) against the ranks."""
    own = layer(module)
    bad = []
    for line, target in sgtool_imports(source):
        other = layer(target)
        if other != own and RANK[other] >= RANK[own]:
            bad.append(f"{where}:{line}: {own} imports {other} ({target})")
    return bad


def package_files() -> list[Path]:
    return sorted(p for f in FOLDERS for p in (REPO / f).rglob("*.py"))


def test_layer_of_module_names() -> None:
    assert layer("sgtool.log.reader") == "core"
    assert layer("sgtool.datasets.generator") == "datasets"
    assert layer("sgtool.commands.replay") == "commands"
    assert layer("sgtool.cli") == "commands"
    assert layer("sgtool.__main__") == "commands"
    assert layer("sgtool") == "facade"
    assert layer("sgtool.version") == "core"
    assert module_name(REPO / "toolkit" / "__init__.py") == "sgtool"


def test_every_import_flows_down_the_layers() -> None:
    files = package_files()
    assert len(files) > 100  # the whole package was looked at
    bad = [v for p in files
           for v in violations(module_name(p), p.read_text(), str(p.relative_to(REPO)))]
    assert not bad, "imports against the layering of DESIGN.md:\n" + "\n".join(bad)


@pytest.mark.parametrize("module, source, message", [
    ("sgtool.scenegraph.x", "from sgtool.datasets.generator import generate_house\n",
     "core imports datasets"),
    ("sgtool.recorders.x", "def f():\n    from sgtool.replayers import golden\n",
     "recorders imports replayers"),
    ("sgtool.datasets.x", "import sgtool.analysis.bench\n", "datasets imports analysis"),
    ("sgtool.analysis.x", "from sgtool.commands.options import parse_rooms\n",
     "analysis imports commands"),
    ("sgtool.log.writer", "from sgtool import __version__\n", "core imports facade"),
    ("sgtool.analysis.bench", "def f():\n    from sgtool import SceneGraph\n",
     "analysis imports facade"),
    ("sgtool.commands.run", "import sgtool\n", "commands imports facade"),
    ("sgtool", "from sgtool.commands.run import command\n", "facade imports commands"),
])
def test_a_broken_layer_is_reported(module: str, source: str, message: str) -> None:
    bad = violations(module, source, "probe.py")
    assert len(bad) == 1 and message in bad[0], bad


def test_imports_down_the_layers_are_fine() -> None:
    src = ("from sgtool.log.reader import LogReader\nfrom sgtool.datasets.house import x\n"
           "from sgtool.recorders.sim import y\nfrom sgtool.analysis.z import w\n")
    assert violations("sgtool.commands.run", src, "probe.py") == []
    assert violations("sgtool.analysis.bench", src, "probe.py") == []
    assert len(violations("sgtool.datasets.generator", src, "probe.py")) == 2
    # the facade re-exports every layer below the CLI
    assert violations("sgtool", src, "probe.py") == []
    assert violations("sgtool", "from sgtool.version import __version__\n", "x") == []
