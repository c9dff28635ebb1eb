"""Efficiency curves as PNG: success rate against budget, one line per planner.

MoMa-LLM's efficiency curve (and SCOUT's Fig. 8 for the step budget): the share of all
episodes solved within each budget, the polyline of AUC-E
(:func:`sgtool.analysis.search_metrics.efficiency_curve`) over all seeds' episodes; the
legend gives each planner's AUC-E as the tables do (the mean of the seeds' areas).
Drawn with matplotlib's Agg backend (no display needed); the PNG carries no timestamp.
"""

from __future__ import annotations

import io
import os
from collections.abc import Sequence
from pathlib import Path

from sgtool.analysis.search_metrics import CostModel, curve_of, mean_auc_e
from sgtool.files import atomic_write
from sgtool.results import EpisodeResult


def plot_efficiency(results_by_planner: Sequence[tuple[str, Sequence[EpisodeResult]]],
                    model: CostModel, path: str | os.PathLike[str], title: str = "") -> Path:
    """Write the efficiency curves of ``model`` for each planner to ``path`` (PNG)."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6.4, 4.2), dpi=110)
    ax = fig.add_subplot(1, 1, 1)
    for name, results in results_by_planner:
        xs, ys = curve_of(results, model)
        ax.plot(xs, ys, label=f"{name} (AUC-E {mean_auc_e(results, model):.3f})",
                linewidth=1.6)
    ax.set_xlim(0, model.max_cost)
    ax.set_ylim(0, 1.0)
    ax.set_xlabel(f"budget: {model.label}")
    ax.set_ylabel("success rate")
    ax.grid(True, alpha=0.3)
    ax.set_title(title or f"Efficiency curve ({model.name} budget, max {model.max_cost:g})",
                 fontsize=10)
    ax.legend(fontsize=8, loc="lower right")
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", metadata={"Software": None})
    return atomic_write(path, buf.getvalue())
