"""The pytest plug-in of golden logs (entry point ``pytest11``: loaded by any pytest run in
an environment where sgtool is installed; it does nothing unless asked).

- ``pytest --sgtool-golden=DIR DIR`` (the option repeatable) adds one test case per log
  pinned in ``DIR`` (by ``sgtool golden pin``), named ``DIR::NAME``: it replays the log
  with the current code and fails with the layer-by-layer report when anything changed, or
  with the one-line error when the log cannot be checked. ``--sgtool-golden-tolerance X``
  lets differences up to X pass (as ``sgtool golden check --tolerance``);
  ``--sgtool-golden-update`` re-pins changed logs instead of failing.
- The fixture ``sgtool_golden`` checks logs from a lab's own tests, snapshot style:
  ``sgtool_golden.check(log, folder, **replay_options)`` pins the log into ``folder`` on
  first use (the test then fails once, saying so: commit the pin), and afterwards fails
  with the report when its replay changed (re-pins under ``--sgtool-golden-update``), or
  when the log given is not the one pinned under its name; options given override the
  pinned ones for the check (as ``sgtool golden check --voxel-size``), the others are as
  pinned.

The module imports only pytest and the standard library at load time: sgtool's replay
code is imported when a golden test runs.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest


def _tolerance(text: str) -> float:
    """``--sgtool-golden-tolerance X``: a finite number >= 0, as ``golden check`` takes."""
    import argparse
    import math

    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value >= 0):
        raise argparse.ArgumentTypeError(f"{text!r}: give a finite number >= 0")
    return value


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("sgtool-golden", "sgtool golden logs")
    group.addoption("--sgtool-golden", action="append", default=[], metavar="DIR",
                    help="Add one test per log pinned in DIR (`sgtool golden pin`); "
                    "repeatable.")
    group.addoption("--sgtool-golden-tolerance", type=_tolerance, default=0.0, metavar="X",
                    help="Golden logs: let differences up to X pass (m, m², scores).")
    group.addoption("--sgtool-golden-update", action="store_true",
                    help="Golden logs: re-pin changed logs instead of failing.")


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line("markers", "sgtool_golden: a golden-log check (sgtool)")
    folders = [str(Path(d)) for d in config.getoption("sgtool_golden", default=[]) or []]
    for d in folders:  # collect each pin folder's index even outside the test paths
        index = str(Path(d) / "expected.json")
        if index not in config.args:
            config.args.append(index)


def pytest_collect_file(file_path: Path, parent: pytest.Collector) -> pytest.Collector | None:
    if file_path.name != "expected.json":
        return None
    wanted = {Path(d).resolve() for d in parent.config.getoption("sgtool_golden") or []}
    if file_path.parent.resolve() not in wanted:
        return None
    return GoldenFolder.from_parent(parent, path=file_path)


class GoldenFolder(pytest.File):
    """A pin folder's index: one :class:`GoldenLog` per pinned log."""

    def collect(self) -> Iterator[pytest.Item]:
        from sgtool.errors import SgtoolError
        from sgtool.replayers.golden_pins import read_pins

        try:
            pins = read_pins(self.path.parent)
        except SgtoolError as e:
            raise self.CollectError(str(e)) from None
        if not pins.logs:  # a run of no checks would pass a CI job whose pins were lost
            raise self.CollectError(f"{pins.folder}: its index pins no log")
        for name in sorted(pins.logs):
            item = GoldenLog.from_parent(self, name=name)
            item.add_marker("sgtool_golden")
            yield item


class GoldenFailure(Exception):
    """A changed or unusable golden log: the report is the failure message; ``changed``:
    its replay changed (what ``--sgtool-golden-update`` accepts), else it could not be
    checked."""

    def __init__(self, report: str, changed: bool) -> None:
        super().__init__(report)
        self.changed = changed


class GoldenLog(pytest.Item):
    """One pinned log, checked with the current code."""

    def runtest(self) -> None:
        from sgtool.analysis.golden_check import check_pins, update_pins

        cfg = self.config
        update = bool(cfg.getoption("sgtool_golden_update"))
        report = check_pins(self.path.parent, tolerance=cfg.getoption("sgtool_golden_tolerance"),
                            names=[self.name], keep=update)
        c = report.logs[0]
        if c.status == "changed" and update:
            update_pins(report)
            return
        if c.status != "unchanged":
            raise GoldenFailure("\n".join(c.report()), changed=c.status == "changed")

    def repr_failure(self, excinfo: pytest.ExceptionInfo[BaseException],
                     style: Any = None) -> str:
        if isinstance(excinfo.value, GoldenFailure) and not excinfo.value.changed:
            return str(excinfo.value)  # the one line of a log that could not be checked
        if isinstance(excinfo.value, GoldenFailure):
            from sgtool.files import quoted

            return str(excinfo.value) + ("\n(deliberate? `sgtool golden check --dir "
                                         f"{quoted(self.path.parent)} --log "
                                         f"{quoted(self.name)} --update`, or pytest "
                                         "--sgtool-golden-update)")
        return str(super().repr_failure(excinfo))

    def reportinfo(self) -> tuple[Path, int | None, str]:
        return self.path, None, f"sgtool golden: {self.name}"


class GoldenFixture:
    """What the ``sgtool_golden`` fixture gives a test (module doc)."""

    def __init__(self, update: bool, tolerance: float) -> None:
        self.update = update
        self.tolerance = tolerance

    def check(self, log: str | Path, folder: str | Path, **options: Any) -> None:
        """Pin ``log`` into ``folder`` on first use (with the replay ``options``: ``every``,
        ``voxel_size``, ...), else check it: options given override the pinned ones for
        this check, as ``sgtool golden check --voxel-size`` does, the others are as pinned;
        such a what-if check is never re-pinned. A ``log`` that is not the log pinned under
        its name (another path and other bytes) fails, one re-recorded in its place fails as
        ``golden check`` says; both are re-pinned under ``--sgtool-golden-update``. A
        mistake in the call (an unknown option, a damaged pin folder) fails in one line."""
        import dataclasses

        from sgtool.errors import SgtoolError
        from sgtool.planning.option_fields import nearest
        from sgtool.replayers.derived_log import ReplayOptions

        known = [f.name for f in dataclasses.fields(ReplayOptions)]
        for key in sorted(set(options) - set(known)):  # a misspelt option: the near one
            near = nearest(key, known)
            pytest.fail(f"sgtool_golden.check({log}): no replay option {key!r}"
                        + (f"; did you mean {near!r}?" if near else
                           f" (the options: {', '.join(known)})"), pytrace=False)
        try:  # a mistake in the call (a bad value, a damaged pin folder): one line
            given = ReplayOptions(**options) if options else None
        except (SgtoolError, TypeError) as e:
            pytest.fail(f"sgtool_golden.check({log}): {e}", pytrace=False)
        try:
            self._check(Path(log), Path(folder), given)
        except SgtoolError as e:
            pytest.fail(f"sgtool_golden.check({log}): {e}", pytrace=False)

    def _check(self, log: Path, folder: Path, given: Any) -> None:
        from sgtool.analysis.golden_check import check_pins, pin_logs, pin_name, update_pins
        from sgtool.files import sha256_file
        from sgtool.replayers.golden_pins import INDEX, options_dict, overridden, read_pins

        if not log.is_file():
            pytest.fail(f"{log}: no such log", pytrace=False)
        name = pin_name(log)
        pin = read_pins(folder).logs.get(name) if (folder / INDEX).is_file() else None
        if pin is None:
            pin_logs([log], folder, given)
            opts = "" if given is None else " with " + ", ".join(
                f"{k}={v!r}" for k, v in sorted(options_dict(given).items()))
            pytest.fail(f"pinned {log} into {folder}{opts} (first run); commit the pin and "
                        "run again", pytrace=False)
        if sha256_file(log) != pin.log_sha256:  # (a --copy pin holds the same bytes)
            if self.update:  # another log under the name, or this one re-recorded
                pin_logs([log], folder, pin.options, why=pin.why)
                return
            if pin.log_path(folder).resolve() != log.resolve():
                pytest.fail(f"{log} is not the log pinned as {name!r} in {folder} "
                            f"({pin.log_path(folder)}): pins are named by file name, give "
                            "each log its own name or folder (or re-pin with pytest "
                            "--sgtool-golden-update)", pytrace=False)
        # options that change the pinned ones ask "what would this do": never re-pinned
        what_if = given is not None and overridden(pin.options, given) != pin.options
        report = check_pins(folder, given, tolerance=self.tolerance, names=[name],
                            keep=self.update and not what_if)
        c = report.logs[0]
        if c.status == "changed" and self.update and not what_if:
            update_pins(report)
            return
        if c.status != "unchanged":
            pytest.fail("\n".join(c.report()), pytrace=False)


@pytest.fixture
def sgtool_golden(request: pytest.FixtureRequest) -> GoldenFixture:
    """Check logs against their pins from a test (:class:`GoldenFixture`)."""
    cfg = request.config
    return GoldenFixture(bool(cfg.getoption("sgtool_golden_update")),
                         float(cfg.getoption("sgtool_golden_tolerance")))
