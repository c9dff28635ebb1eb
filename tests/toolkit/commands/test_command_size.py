"""No function in the CLI layer (``toolkit/commands/``) is over 40 lines, counted from its
``def`` line to its last line (decorators and the click options above it not counted): a
command parses its options, checks its outputs and inputs and hands a request to a library
function; the work lives in the library."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

COMMANDS = Path(__file__).resolve().parents[3] / "toolkit" / "commands"
MAX_LINES = 40


def long_functions(source: str, limit: int = MAX_LINES) -> list[tuple[str, int]]:
    """(qualified name, lines) of every function or method of ``source`` longer than
    ``limit`` lines, nested ones included."""
    found: list[tuple[str, int]] = []

    def visit(node: ast.AST, prefix: str) -> None:
        for child in ast.iter_child_nodes(node):
            name = prefix
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                name = f"{prefix}{child.name}."
                if not isinstance(child, ast.ClassDef):
                    lines = (child.end_lineno or child.lineno) - child.lineno + 1
                    if lines > limit:
                        found.append((name[:-1], lines))
            visit(child, name)

    visit(ast.parse(source), "")
    return found


def _lines(n: int, indent: int) -> str:
    return "".join(" " * indent + f"x{i} = {i}\n" for i in range(n))


def test_the_count_sees_a_long_function_and_its_nested_ones() -> None:
    source = ("def short():\n" + _lines(39, 4)  # 40 lines with its def: allowed
              + "class C:\n    def long(self):\n" + _lines(40, 8)
              + "        def inner():\n" + _lines(40, 12))
    assert long_functions(source) == [("C.long", 82), ("C.long.inner", 41)]


@pytest.mark.parametrize("module", sorted(p.name for p in COMMANDS.glob("*.py")))
def test_no_command_function_is_over_40_lines(module: str) -> None:
    assert long_functions((COMMANDS / module).read_text()) == []
