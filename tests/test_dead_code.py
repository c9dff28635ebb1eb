"""The package holds no dead code: vulture finds nothing in the package folders.

Names that are used without vulture seeing it (framework hooks, click commands, result
fields, the module protocol) are listed, each with its reason, in
``tests/support/vulture_whitelist.py``. Tests, benchmarks and examples are not scanned: a
package function that only they call is reported by this test unless whitelisted.
vulture is a dev dependency (``bash setup.sh`` installs it): without it this test fails.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGE_FOLDERS = ("toolkit", "recorders", "replayers", "datasets", "analysis")
WHITELIST = ROOT / "tests" / "support" / "vulture_whitelist.py"
MIN_CONFIDENCE = 60  # vulture's 60 %: every unused function, method, attribute, variable


def test_vulture_finds_no_dead_code_in_the_package() -> None:
    folders = [str(ROOT / f) for f in PACKAGE_FOLDERS]
    run = subprocess.run(
        [sys.executable, "-m", "vulture", *folders, str(WHITELIST),
         "--min-confidence", str(MIN_CONFIDENCE)],
        capture_output=True, text=True, cwd=ROOT, check=False,
    )
    findings = run.stdout.strip()
    assert run.returncode == 0 and not findings, (
        "vulture found dead code (delete it, or whitelist a name used dynamically in "
        f"{WHITELIST.relative_to(ROOT)} with the reason):\n{findings}\n{run.stderr}"
    )


def test_the_whitelist_names_only_what_the_package_defines() -> None:
    """A whitelisted name that the package no longer defines is a stale line."""
    names = []
    for line in WHITELIST.read_text("utf8").splitlines():
        if line.startswith("_."):
            names.append(line[2:].split()[0])
    assert names, "the whitelist parses to no names"
    sources = "\n".join(
        p.read_text("utf8") for f in PACKAGE_FOLDERS for p in (ROOT / f).rglob("*.py")
    )
    stale = sorted(n for n in names if n not in sources)
    assert not stale, f"whitelisted but not in the package: {stale}"
