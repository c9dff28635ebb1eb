"""Floor-plan pictures of house specs (matplotlib, Agg backend, no display needed).

Rooms are filled with one colour per room category and labelled with their category and
id; walls are black bars; doors are gaps with a coloured leaf line (green open, red
closed); open-plan passages are dotted; furniture is drawn as its oriented box (containers
hatched, closed openables darker); small objects are dots on their parent (crosses for
objects hidden in a closed container); start poses are arrows.
"""

from __future__ import annotations

import math
import os
import warnings
from pathlib import Path

from sgtool.files import atomic_output
from sgtool.house.spec import HouseSpec, hidden_objects

_PALETTE = [
    "#8dd3c7", "#ffffb3", "#bebada", "#fb8072", "#80b1d3", "#fdb462", "#b3de69",
    "#fccde5", "#d9d9d9", "#bc80bd", "#ccebc5", "#ffed6f", "#a6cee3", "#e5d8bd",
]



# per image format, the metadata matplotlib would stamp with the date or its version
_STABLE_METADATA: dict[str, dict[str, None]] = {
    ".png": {"Software": None},
    ".svg": {"Date": None, "Creator": None},
    ".pdf": {"CreationDate": None, "Creator": None, "Producer": None},
}

def room_colours(spec: HouseSpec) -> dict[str, str]:
    """Category -> colour, stable for a given set of categories (sorted order)."""
    cats = sorted({r.category for r in spec.rooms})
    return {c: ("#eeeeee" if c == "corridor" else _PALETTE[i % len(_PALETTE)])
            for i, c in enumerate(c for c in cats)}


def draw_house(spec: HouseSpec, path: str | os.PathLike[str], dpi: int = 120,
               show_objects: bool = True, title: str | None = None) -> Path:
    """Draw ``spec`` to an image file (format from the suffix: .png, .svg, .pdf); the file
    is written atomically."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt
    from matplotlib.patches import Polygon, Rectangle

    path = Path(path)
    xmin, ymin, xmax, ymax = spec.bounds()
    w, h = xmax - xmin, ymax - ymin
    scale = 0.55
    fig, ax = plt.subplots(figsize=(max(4.0, w * scale + 1.5), max(3.0, h * scale + 1.2)))
    colours = room_colours(spec)
    for r in spec.rooms:
        ax.add_patch(Polygon(r.polygon, closed=True, facecolor=colours[r.category],
                             edgecolor="none", zorder=0))
        cx, cy = r.centroid
        label = r.category.replace("_", " ")
        if r.open_plan_group:
            label += " (open plan)"
        ax.text(cx, cy, f"{label}\n{r.id}", ha="center", va="center", fontsize=7,
                color="#333333", zorder=6,
                bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.6})
    for wl in spec.walls:
        ax.plot([wl.a[0], wl.b[0]], [wl.a[1], wl.b[1]], color="black",
                linewidth=max(1.0, wl.thickness * 30), solid_capstyle="butt", zorder=4)
    for d in spec.doors:
        (x0, y0), (x1, y1) = d.segment
        ax.plot([x0, x1], [y0, y1], color="#2ca02c" if d.is_open else "#d62728",
                linewidth=2.5 if d.is_open else 4.0, linestyle="-" if not d.is_open else "--",
                zorder=5)
    for p in spec.passages:
        (x0, y0), (x1, y1) = p.segment
        ax.plot([x0, x1], [y0, y1], color="#777777", linewidth=1.0, linestyle=":", zorder=5)
    for f in spec.furniture:
        corners = f.footprint()
        closed = f.state == "closed"
        ax.add_patch(Polygon(corners, closed=True,
                             facecolor="#8c6d46" if closed else "#c8a97e",
                             edgecolor="#4d3b24", linewidth=0.6,
                             hatch="///" if f.is_container else None,
                             zorder=2 if f.bottom < 0.05 else 3, alpha=0.9))
        # front marker: a short tick on the local +y face
        fx = f.center[0] - math.sin(f.yaw) * f.size[1] / 2
        fy = f.center[1] + math.cos(f.yaw) * f.size[1] / 2
        ax.plot([fx], [fy], marker=".", color="#4d3b24", markersize=2, zorder=3)
        if max(f.size[0], f.size[1]) >= 0.6:
            ax.text(f.center[0], f.center[1], f.category, ha="center", va="center",
                    fontsize=4.5, color="#222222", zorder=7, clip_on=True)
    if show_objects:
        hidden_ids = hidden_objects(spec)
        for o in spec.objects:
            hidden = o.id in hidden_ids
            ax.plot([o.position[0]], [o.position[1]], marker="x" if hidden else "o",
                    markersize=3 if hidden else 2.5,
                    color="#1f4e9e" if o.relation == "inside" else "#e377c2", zorder=8,
                    linestyle="none")
    for s in spec.starts:
        ax.add_patch(Rectangle((s.x - 0.05, s.y - 0.05), 0.1, 0.1, color="#ff7f0e", zorder=9))
        ax.arrow(s.x, s.y, 0.3 * math.cos(s.yaw), 0.3 * math.sin(s.yaw), width=0.02,
                 color="#ff7f0e", zorder=9, length_includes_head=True)
    ax.set_xlim(xmin - 0.5, xmax + 0.5)
    ax.set_ylim(ymin - 0.5, ymax + 0.5)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    n_in = sum(1 for o in spec.objects if o.relation == "inside")
    ax.set_title(title or (f"house seed {spec.seed} ({spec.split}): {len(spec.rooms)} rooms, "
                           f"{len(spec.furniture)} furniture, {len(spec.objects)} objects "
                           f"({n_in} inside)"), fontsize=9)
    from matplotlib.lines import Line2D

    handles = [
        Line2D([], [], color="#2ca02c", linestyle="--", label="open door"),
        Line2D([], [], color="#d62728", linewidth=3, label="closed door"),
        Line2D([], [], color="#777777", linestyle=":", label="open-plan passage"),
        Line2D([], [], marker="o", color="#e377c2", linestyle="none", label="object on top"),
        Line2D([], [], marker="o", color="#1f4e9e", linestyle="none", label="object inside"),
        Line2D([], [], marker="x", color="#1f4e9e", linestyle="none",
               label="hidden in closed container"),
        Line2D([], [], marker="s", color="#ff7f0e", linestyle="none", label="start pose"),
    ]
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=6,
              frameon=False)
    try:
        with warnings.catch_warnings():
            # a name in a script the font lacks (emoji, CJK) draws as boxes: no warning
            # with source lines for each glyph (laying out draws the text too)
            warnings.filterwarnings("ignore", message=r"Glyph \d+ .*missing from")
            fig.tight_layout()
        with atomic_output(path, suffix=path.suffix) as tmp, warnings.catch_warnings():
            warnings.filterwarnings("ignore", message=r"Glyph \d+ .*missing from")
            # no date, program or random ids in the file: the same house, the same bytes
            with plt.rc_context({"svg.hashsalt": "sgtool"}):
                fig.savefig(tmp, dpi=dpi, bbox_inches="tight",  # the legend beside the plan
                            metadata=_STABLE_METADATA.get(path.suffix.lower()))
    finally:
        plt.close(fig)
    return path
