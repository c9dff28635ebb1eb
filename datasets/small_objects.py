"""Small objects of a generated house: containers filled and supporters dressed with
candidates of the piece's room type (:mod:`sgtool.datasets.object_candidates`), each object
in its own slot (a shelf level inside a container, a spot on a top face) so objects never
overlap and lie really inside or on top. How many, and from which pool, is set by the
generator preset (:mod:`sgtool.datasets.presets`)."""

from __future__ import annotations

import math

import numpy as np

from sgtool.datasets.house_plan import Piece
from sgtool.datasets.object_candidates import candidates, has_novel
from sgtool.datasets.presets import PRESETS, GeneratorPreset
from sgtool.datasets.sizes import object_size
from sgtool.datasets.synsets import readable_name

# fewer objects on thin evidence: the mean count is scaled by min(1, pool size / this)
FULL_POOL = 3


def _slots(p: Piece, relation: str) -> list[tuple[float, float, float, float, float, float]]:
    """Slots (cx, cy, z_floor, sx, sy, sz_max) in world coordinates for a piece."""
    sx, sy, sz = p.size
    out = []
    if relation == "inside":
        wall = 0.03
        ix, iy = sx - 2 * wall, sy - 2 * wall
        ih = sz - 2 * wall
        levels = max(1, int(ih // 0.4))
        lh = ih / levels
        nx, ny = max(1, int(ix // 0.22)), max(1, int(iy // 0.22))
        for lv in range(levels):
            z = p.z0 + wall + lv * lh
            for i in range(nx):
                for j in range(ny):
                    lx = -ix / 2 + (i + 0.5) * ix / nx
                    ly = -iy / 2 + (j + 0.5) * iy / ny
                    out.append((*_to_world(p, lx, ly), z, ix / nx, iy / ny, lh - 0.01))
    else:
        nx, ny = max(1, int(sx // 0.25)), max(1, int(sy // 0.25))
        for i in range(nx):
            for j in range(ny):
                lx = -sx / 2 + (i + 0.5) * sx / nx
                ly = -sy / 2 + (j + 0.5) * sy / ny
                out.append((*_to_world(p, lx, ly), p.z0 + sz, sx / nx, sy / ny, 0.6))
    return out


def _to_world(p: Piece, lx: float, ly: float) -> tuple[float, float]:
    cx, cy = (p.box.x0 + p.box.x1) / 2, (p.box.y0 + p.box.y1) / 2
    c, s = math.cos(p.yaw), math.sin(p.yaw)
    return (cx + c * lx - s * ly, cy + s * lx + c * ly)


def _distinct_categories(rng: np.random.Generator, w: np.ndarray, n: int) -> list[int]:
    """``n`` draws of candidate indices with weights ``w``, none repeated while the pool
    lasts."""
    first = min(n, int(np.count_nonzero(w)))
    out = rng.choice(len(w), size=first, replace=False, p=w).tolist()
    return out + rng.choice(len(w), size=n - first, p=w).tolist()


def place_objects(rng: np.random.Generator, split: str, pieces: list[Piece],
                  room_types: dict[int, str],
                  preset: GeneratorPreset = PRESETS["default"],
                  extras: frozenset[int] = frozenset()) -> list[dict]:
    """Small-object records (spec ``objects`` entries without ids) for ``pieces``;
    ``room_types`` maps plan room index -> room type; ``preset`` sets the mean counts and
    the candidate pool (and scales the mean count of a pool without unseen categories);
    of the pieces whose index is in ``extras`` (the extra holders of
    :mod:`sgtool.datasets.first_level`) only ``preset.extra_fill_share`` are filled, the
    others stay empty."""
    objs: list[dict] = []
    for pi, p in enumerate(pieces):
        if pi in extras and rng.random() >= preset.extra_fill_share:
            continue
        for relation in ("inside", "ontop"):
            if relation == "inside" and "container" not in p.affordances:
                continue
            if relation == "ontop" and ("supporter" not in p.affordances or p.top_used
                                        or p.size[2] > 1.7):
                continue
            names, w = candidates(split, p.synset, relation, room_types[p.room],
                                  preset.long_tail, preset.novel_share)
            if not names:
                continue
            lam = preset.lambda_inside if relation == "inside" else preset.lambda_ontop
            lam *= min(1.0, len(names) / FULL_POOL)
            if preset.seen_pool_scale != 1.0 and not has_novel(split, names):
                lam *= preset.seen_pool_scale
            slots = _slots(p, relation)
            n = min(int(rng.poisson(lam)), len(slots))
            if n == 0:
                continue
            chosen_slots = sorted(rng.choice(len(slots), size=n, replace=False).tolist())
            cats = _distinct_categories(rng, w, n) if preset.long_tail else None
            for i, si in enumerate(chosen_slots):
                cx, cy, z, ssx, ssy, szmax = slots[si]
                syn = names[int(rng.choice(len(names), p=w)) if cats is None else cats[i]]
                bx, by, bz = object_size(syn)
                k = rng.uniform(0.9, 1.1)
                # objects keep the piece's orientation; clip them to the slot
                ox = round(min(bx * k, ssx - 0.02), 3)
                oy = round(min(by * k, ssy - 0.02), 3)
                oz = round(min(bz * k, szmax - 0.01), 3)
                if min(ox, oy, oz) <= 0.005:
                    continue
                objs.append({
                    "category": readable_name(syn), "synset": syn, "parent": f"furn_{pi}",
                    "relation": relation, "room": f"room_{p.room}",
                    "position": [round(cx, 4), round(cy, 4), round(z + oz / 2, 4)],
                    "size": [ox, oy, oz],
                })
    return objs
