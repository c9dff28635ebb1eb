"""Where each parameter of an import came from, and what an import found wrong on the way.

The import report and the log's ``sgtool.import`` metadata state, for the intrinsics, the
depth scale, the up direction and the floor, whether each was given with a flag, read from a
file or a topic, taken from a dataset or folder-name default, or estimated.

A problem found by :mod:`.sanity` is an error when the value in question was not given by
the user (defaults and estimates must not be silently wrong) and a warning when it was: see
:class:`Findings`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from sgtool.errors import SgtoolError
from sgtool.recorders.importers.upright import WorldAlignment

UP_ORIGINS = {
    "given": "flag --up",
    "camera-up": "estimate: the cameras' mean image-up direction",
    "horizontal-normals": "estimate: the normals of horizontal surfaces",
    "none": "kept: the source world's z (no --up given for a trajectory)",
}
FLOOR_ORIGINS = {
    "given": "flag --floor",
    "horizontal-plane": "estimate: the lowest large horizontal plane",
    "horizontal-surfaces": "estimate: the lowest upward-facing surfaces",
    "all-points": "estimate: the lowest depth points (few horizontal surfaces)",
    "none": "kept: not estimated (--floor none, or a trajectory without --floor)",
    "no-depth": "kept: not estimated (no valid depth point in the sampled frames)",
}
ESTIMATED_FLOORS = ("horizontal-plane", "horizontal-surfaces", "all-points")


def alignment_sources(a: WorldAlignment) -> list[tuple[str, str, str]]:
    """(parameter, value, origin) of the up direction and the floor."""
    return [
        ("up", "({:.3f}, {:.3f}, {:.3f})".format(*a.up), UP_ORIGINS.get(a.up_method, a.up_method)),
        ("floor", f"{a.floor:.3f} m in the source",
         FLOOR_ORIGINS.get(a.floor_method, a.floor_method)),
    ]


def source_metadata(sources: list[tuple[str, str, str]]) -> dict[str, str]:
    """``{name}_source`` entries of the log metadata."""
    return {f"{name.replace(' ', '_')}_source": origin for name, _, origin in sources}


@dataclass
class Findings:
    """Collects the warnings of an import; ``warn`` shows each at once (the CLI prints it
    to stderr before the heavy work)."""

    warn: Callable[[str], None] | None = None
    warnings: list[str] = field(default_factory=list)

    def problem(self, text: str | None, *, given: bool) -> None:
        """A problem of a value the user ``given`` is a warning (its advice to give the
        value to keep it becomes that it is kept); of a default or an estimate, an error
        (one line)."""
        if text is None:
            return
        if not given:
            raise SgtoolError(text)
        head, sep, tail = text.rpartition("; give it, or ")
        if sep and tail.endswith("to keep this one"):  # the value given is what is kept
            text = f"{head}; the value given is kept"
        self.warning(text)

    def floor_doubt(self, text: str | None) -> str | None:
        """``text`` (a floor problem, naming ``--floor``) with a word on the poses when a
        warning before doubted them: wrong poses misplace the floor too, and a ``--floor``
        given then writes a wrong map."""
        if text is None or not any(w.startswith(("the poses (", "the poses' "))
                                   for w in self.warnings):
            return text
        return (f"{text}; but the poses were doubted above: wrong poses misplace the floor "
                "too, so fix them (or give --estimate-poses) before giving --floor")

    def warning(self, text: str) -> None:
        self.warnings.append(text)
        if self.warn is not None:
            self.warn(text)
