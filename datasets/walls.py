"""Wall segments of a generated floor plan: the union of all room edges minus the door
and passage openings."""

from __future__ import annotations

from sgtool.datasets.house_plan import Plan


def wall_segments(plan: Plan) -> list[tuple[tuple[float, float], tuple[float, float]]]:
    """Wall segments: the union of all room edges minus door and passage openings."""
    lines: dict[tuple[bool, float], list[tuple[float, float]]] = {}
    for r in plan.rooms:
        x0, y0, x1, y1 = r.rect.x0, r.rect.y0, r.rect.x1, r.rect.y1
        for horiz, c, a, b in ((True, y0, x0, x1), (True, y1, x0, x1),
                               (False, x0, y0, y1), (False, x1, y0, y1)):
            lines.setdefault((horiz, round(c, 4)), []).append((a, b))
    cuts: dict[tuple[bool, float], list[tuple[float, float]]] = {}
    for o in plan.openings:
        if o.horizontal:
            key = (True, round(o.center[1], 4))
            c = o.center[0]
        else:
            key = (False, round(o.center[0], 4))
            c = o.center[1]
        cuts.setdefault(key, []).append((c - o.width / 2, c + o.width / 2))
    out = []
    for key in sorted(lines):
        horiz, c = key
        merged = _merge_intervals(lines[key])
        for a, b in _cut_intervals(merged, cuts.get(key, [])):
            if b - a < 0.05 - 1e-9:
                continue
            a, b = round(a, 4), round(b, 4)
            out.append(((a, c), (b, c)) if horiz else ((c, a), (c, b)))
    return out


def _merge_intervals(iv: list[tuple[float, float]]) -> list[tuple[float, float]]:
    iv = sorted(iv)
    out: list[list[float]] = []
    for a, b in iv:
        if out and a <= out[-1][1] + 1e-9:
            out[-1][1] = max(out[-1][1], b)
        else:
            out.append([a, b])
    return [(a, b) for a, b in out]


def _cut_intervals(iv: list[tuple[float, float]],
                   cuts: list[tuple[float, float]]) -> list[tuple[float, float]]:
    out = []
    for a, b in iv:
        pieces = [(a, b)]
        for ca, cb in sorted(cuts):
            nxt = []
            for pa, pb in pieces:
                if cb <= pa + 1e-9 or ca >= pb - 1e-9:
                    nxt.append((pa, pb))
                    continue
                if ca > pa:
                    nxt.append((pa, ca))
                if cb < pb:
                    nxt.append((cb, pb))
            pieces = nxt
        out += pieces
    return out
