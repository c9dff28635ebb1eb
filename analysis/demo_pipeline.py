"""The pipeline of `sgtool demo` on the demo house: record, summarise, replay (scored,
with a Rerun recording), then a small symbolic benchmark.

Every step prints the command line it stands for and its report to ``show``; progress bars
go to stderr when ``progress``. The same arguments give the same logs.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sgtool.files import quoted

DEMO_PLANNERS = ("random", "greedy", "sbert", "scout")

Echo = Callable[[str], None]


@dataclass(frozen=True)
class DemoRequest:
    """A checked `sgtool demo`: the output folder (exists), the frame limit of the
    recording (None: the whole tour) and the size of the closing benchmark."""

    out: Path
    frames: int | None = None
    houses: int = 3
    episodes: int = 10
    seeds: int = 2


def _bar(total: int | None, desc: str, progress: bool) -> Any:
    from tqdm import tqdm

    return tqdm(total=total, unit="frame", desc=desc, file=sys.stderr, leave=False,
                disable=not progress, dynamic_ncols=True)


def _record(request: DemoRequest, log: Path, show: Echo, progress: bool) -> int:
    """Record and summarise the demo house; the frames recorded."""
    from sgtool.datasets import demo_house
    from sgtool.log.inspect import format_summary, summarize
    from sgtool.recorders.sim import RecordOptions, record_house

    show(f"\n== sgtool record -o {log}: the demo house in PyBullet")
    with _bar(request.frames, "record", progress) as bar:
        rep = record_house(demo_house(), log, RecordOptions(frames=request.frames),
                           house_id="demo", progress=bar)
    for line in rep.lines():
        show(line)
    show(f"\n== sgtool info {log}")
    show(format_summary(summarize(log)))
    return int(rep.frames)


def _replay(log: Path, derived: Path, frames: int, show: Echo, progress: bool) -> None:
    """Replay the log into scene graphs and score them against the demo house."""
    from sgtool.datasets import demo_house
    from sgtool.replayers.derived_log import replay
    from sgtool.replayers.score import score, score_lines

    final: dict[str, Any] = {}
    with _bar(frames, "replay", progress) as bar:
        rrep = replay(log, derived, progress=bar,
                      on_refresh=lambda r, s: final.update(ref=r, stream=s))
    for line in rrep.lines():
        show(line)
    ref, stream = final["ref"], final["stream"]
    for line in score_lines(score(demo_house(), stream.builder.instances, ref.layers,
                                  ref.graph, stream.builder.trajectory),
                            len(ref.graph.objects)):
        show(line)


def _demo_log(path: Path) -> bool:
    """Whether ``path`` is an sgtool log of the demo house (an older demo's output)."""
    from sgtool.errors import SgtoolError
    from sgtool.log import LogReader

    if not path.is_file():
        return False
    try:
        with LogReader(path) as r:
            return r.metadata.get("sgtool", {}).get("house_id") == "demo"
    except (SgtoolError, OSError, ValueError):
        return False


def run_demo(request: DemoRequest, show: Echo, progress: bool,
             write_view: Callable[[Path, Path, bool], None]) -> None:
    """Run the demo into ``request.out``: ``demo.mcap``, ``derived.mcap``, ``view.rrd``
    (made by ``write_view(derived, rrd, progress)``; left out, with a note, when Rerun is
    not installed) and ``bench/``. A previous demo's outputs there go first, so that a run
    cut short leaves its own outputs only (each written whole), not a mix of two runs;
    files of those names the folder's manifest does not list as the demo's (a user's) are
    an error before any work (a folder of an older demo, with a bench's ``bench/`` and no
    manifest of its own, is the demo's)."""
    import importlib.util

    from sgtool.analysis.bench import OUTPUT_NAMES, run_bench
    from sgtool.errors import SgtoolError
    from sgtool.files import MANIFEST, note_written, read_manifest, sgtool_entries

    out = request.out
    log, derived, rrd = out / "demo.mcap", out / "derived.mcap", out / "view.rrd"
    owner, listed = read_manifest(out)
    if owner is None and read_manifest(out / "bench")[0] == "bench":  # an older demo's?
        # only logs of the demo house are (a user's own bench/ beside files of these names
        # is no demo's folder); its view.rrd beside them
        logs = {p.name for p in (log, derived) if _demo_log(p)}
        owner, listed = "demo", frozenset(logs | ({rrd.name} if logs else set()))
    theirs = [p.name for p in (log, derived, rrd)
              if p.exists() and (owner != "demo" or p.name not in listed)]
    if theirs:  # a user's files of these names: never deleted or replaced
        raise SgtoolError(f"-o {out}: holds {', '.join(theirs)}, named as the demo's outputs "
                          f"but not listed as its own ({MANIFEST}); not replacing them: move "
                          "them away, or give another folder")
    for old in (log, derived, rrd, *(out / "bench" / n for n in sgtool_entries(
            out / "bench", OUTPUT_NAMES))):  # the bench's own files (a user's stay)
        if not old.is_dir():
            old.unlink(missing_ok=True)
    note_written(out, "demo", [log.name, derived.name, rrd.name])
    frames = _record(request, log, show, progress)
    show(f"\n== sgtool replay {log} -o {derived} --rrd {rrd} --score")
    _replay(log, derived, frames, show, progress)
    if importlib.util.find_spec("rerun") is None:
        show("note: no Rerun recording: Rerun is not installed (pip install 'sgtool[view]')")
    else:
        write_view(derived, rrd, progress)
        show(f"wrote {rrd}; open it with: rerun {quoted(rrd)}")
    show(f"\n== sgtool bench --planners {','.join(DEMO_PLANNERS)} --houses {request.houses} "
         f"--episodes {request.episodes} --seeds {request.seeds} -o {out / 'bench'}")
    show(run_bench(DEMO_PLANNERS, houses=request.houses, episodes=request.episodes,
                   seeds=request.seeds, out_dir=out / "bench", progress=progress))
