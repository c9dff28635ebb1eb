"""Print the "Every public name" section of docs/api.md: the topics of ``help(sgtool)``,
each public name under its topic with the first sentence of its docstring.

    .venv/bin/python tools/api_reference.py            # print the section
    .venv/bin/python tools/api_reference.py --write    # replace it in docs/api.md

tests/test_public_api.py checks that docs/api.md holds what this prints, so the section
changes with the API (run ``--write`` after adding a public name).
"""

from __future__ import annotations

import argparse
import inspect
import re
import sys
from pathlib import Path

import sgtool

DOC = Path(__file__).resolve().parents[1] / "docs" / "api.md"
BEGIN = "<!-- every public name: tools/api_reference.py --write -->"
END = "<!-- end of every public name -->"


def topics() -> list[tuple[str, list[str]]]:
    """(topic, its names in table order) of the topic table in sgtool's docstring."""
    lines = (sgtool.__doc__ or "").splitlines()
    rules = [i for i, line in enumerate(lines) if line.startswith("=====")]
    table = lines[rules[1] + 1:rules[2]]  # the rows between the header rule and the last
    out: list[tuple[str, list[str]]] = []
    for line in table:
        if not line.strip():
            continue
        if not line.startswith(" "):
            out.append((line[:21].strip(), []))
        out[-1][1].extend(n for n in re.findall(r":(?:func|class):`([A-Za-z_]+)`", line)
                          if n not in out[-1][1])
    return out


def first_sentence(name: str) -> str:
    """The first sentence of the docstring of ``sgtool.NAME``, on one line."""
    text = " ".join((inspect.getdoc(getattr(sgtool, name)) or "").split())
    # a full stop outside a code span (a name wrapped after its dot is no sentence's end)
    cut = next((m for m in re.finditer(r"(?<!e\.g)(?<!i\.e)\.(\s|$)", text)
                if text[:m.start()].count("`") % 2 == 0), None)
    return (text[:cut.start() + 1] if cut else text).replace("|", "\\|")


def section() -> str:
    """The section's Markdown, between its markers."""
    lines = [BEGIN, "", "## Every public name", "",
             "Each name of `sgtool.__all__` by the topic `help(sgtool)` gives it, with the "
             "first sentence of its docstring (the docstring states the whole contract).", ""]
    for topic, names in topics():
        lines += [f"**{topic}**", ""]
        lines += [f"- `{n}`: {first_sentence(n)}" for n in names]
        lines.append("")
    return "\n".join([*lines, END]) + "\n"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--write", action="store_true", help="replace the section in docs/api.md")
    args = ap.parse_args()
    text = section()
    if not args.write:
        sys.stdout.write(text)
        return 0
    doc = DOC.read_text(encoding="utf-8")
    if BEGIN in doc:
        doc = doc[:doc.index(BEGIN)] + text + doc[doc.index(END) + len(END) + 1:]
    else:
        doc = doc.rstrip("\n") + "\n\n" + text
    DOC.write_text(doc, encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
