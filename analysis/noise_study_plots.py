"""Plots of the perception-noise study: scene-graph quality against noise level, one PNG per
factor (and one for the whole profiles), with a point per house and the median over houses.

Three panels per figure, merged scores: the room error against every true room, the
Voronoi purity and the share of objects in the right room. The x axis lists the levels
as categories (0 = noise-free first), so levels a decade apart stay readable. Drawn with
matplotlib's Agg backend; the PNGs carry no timestamp.
"""

from __future__ import annotations

import io
import math
import statistics
from collections.abc import Sequence
from pathlib import Path

from sgtool.analysis.noise_study import FACTOR_UNITS, NONE, PROFILE, Condition, StudyResult
from sgtool.analysis.noise_study_tables import by_factor
from sgtool.files import atomic_write

PANELS: tuple[tuple[str, str, float], ...] = (
    # (merged score field, axis label, scale)
    ("room_error_vs_true", "rooms found - true", 1.0),
    ("purity", "Voronoi purity", 1.0),
    ("object_accuracy", "objects in the right room (%)", 100.0),
)
MARKERS = "osD^v<>ph*"


def _label(c: Condition, factor: str) -> str:
    if c.factor == NONE:
        return "none" if factor == PROFILE else "0"
    return c.level


def plot_factor(res: StudyResult, factor: str, conds: Sequence[Condition],
                path: str | Path) -> Path:
    """One factor's figure (module doc) at ``path``."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    from matplotlib.figure import Figure

    houses = [h.id for h in res.config.houses]
    fig = Figure(figsize=(10.5, 3.4), dpi=100)
    xs = list(range(len(conds)))
    for k, (key, label, scale) in enumerate(PANELS):
        ax = fig.add_subplot(1, len(PANELS), k + 1)
        for i, h in enumerate(houses):
            ys = []
            for c in conds:
                cell = res.cell(h, c.noise)
                ys.append(float(cell.merged[key]) * scale if cell is not None else float("nan"))
            off = (i - (len(houses) - 1) / 2) * 0.04  # houses side by side, not on top
            ax.plot([x + off for x in xs], ys, linestyle="none", marker=MARKERS[i % 10],
                    markersize=4, alpha=0.6, label=h)
        med = []
        for c in conds:
            vals = [float(cell.merged[key]) * scale for h in houses
                    if (cell := res.cell(h, c.noise)) is not None
                    and math.isfinite(float(cell.merged[key]))]
            med.append(statistics.median(vals) if vals else float("nan"))
        ax.plot(xs, med, color="black", linewidth=1.6, marker="_", markersize=12,
                label="median")
        ax.set_xticks(xs)
        ax.set_xticklabels([_label(c, factor) for c in conds], fontsize=8)
        ax.set_ylabel(label, fontsize=9)
        ax.grid(True, alpha=0.3)
        if key == "purity":
            ax.set_ylim(-0.02, 1.02)
        elif key == "object_accuracy":
            ax.set_ylim(-2, 102)
        if k == 0:
            ax.legend(fontsize=7, loc="best")
    unit = FACTOR_UNITS.get(factor, "")
    fig.suptitle(f"{factor} ({unit})" if factor != PROFILE else "noise profiles",
                 fontsize=10)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", metadata={"Software": None})
    return atomic_write(path, buf.getvalue())


def plot_study(res: StudyResult, folder: str | Path) -> list[Path]:
    """Every factor's figure as ``folder/FACTOR.png`` (``profiles.png`` for the profiles)."""
    out = []
    for factor, conds in by_factor(res).items():
        name = "profiles" if factor == PROFILE else factor
        out.append(plot_factor(res, factor, conds, Path(folder) / f"{name}.png"))
    return out
