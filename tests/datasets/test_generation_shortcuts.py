"""The generator's shortcuts give what the plain computations give: start poses found on
windows of the grid, and the final house made from the draft without parsing it again."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from sgtool.datasets.generator import generate_house
from sgtool.datasets.house_plan import PlanRetry
from sgtool.datasets.robot_clearance import REACH, ROBOT_RADIUS, start_poses
from sgtool.house.io import load_house
from sgtool.house.spec import HouseSpec
from sgtool.mapping.occupancy import geodesic_distances, house_occupancy
from sgtool.mapping.raster import cell_centers


def _whole_grid_start_poses(rng: np.random.Generator, spec: HouseSpec) -> list[dict]:
    """start_poses as first written: every mask over the whole grid."""
    occ = house_occupancy(spec, closed_doors_free=True, robot_radius=ROBOT_RADIUS)
    reach = np.isfinite(geodesic_distances(occ, spec.rooms[0].centroid, max_snap=1.0))
    X, Y = cell_centers(occ)
    starts = []
    for r in spec.rooms:
        x0, y0, x1, y1 = r.bounds
        inside = (X > x0) & (X < x1) & (Y > y0) & (Y < y1) & reach
        if not inside.any():
            raise PlanRetry
        cx, cy = r.centroid
        i = int(np.argmin(np.where(inside, (X - cx) ** 2 + (Y - cy) ** 2, np.inf)))
        yaw = round(float(rng.uniform(-math.pi, math.pi)), 4)
        starts.append({"x": round(float(X.ravel()[i]), 4), "y": round(float(Y.ravel()[i]), 4),
                       "yaw": yaw, "room": r.id})
    for f in spec.furniture:
        if not f.affordances:
            continue
        (ax, ay), (bx, by) = f.footprint()[0], f.footprint()[2]
        dx = np.maximum(np.maximum(min(ax, bx) - X, X - max(ax, bx)), 0.0)
        dy = np.maximum(np.maximum(min(ay, by) - Y, Y - max(ay, by)), 0.0)
        if not ((dx ** 2 + dy ** 2 <= (REACH - ROBOT_RADIUS) ** 2) & reach).any():
            raise PlanRetry
    return starts


@pytest.mark.parametrize("seed", [0, 3])
def test_windowed_start_poses_equal_the_whole_grid_ones(seed: int) -> None:
    spec = generate_house(seed, rooms=(6, 8), preset="symsearch")
    got = start_poses(np.random.default_rng(5), spec)
    assert got == _whole_grid_start_poses(np.random.default_rng(5), spec)
    assert [s["room"] for s in got] == [r.id for r in spec.rooms]
    # the house's own start poses are the cells start_poses picks (its yaws: another rng)
    assert [(s.x, s.y) for s in spec.starts] == [(s["x"], s["y"]) for s in got]


def test_an_unreachable_container_is_refused_like_before() -> None:
    spec = generate_house(1, rooms=(5, 6))
    f = next(k for k, p in enumerate(spec.furniture) if p.affordances)
    far = spec.furniture[f].__class__(**{**spec.furniture[f].__dict__,
                                         "center": (500.0, 500.0, 0.5)})
    bad = spec.__class__(**{**spec.__dict__,
                            "furniture": (*spec.furniture[:f], far, *spec.furniture[f + 1:])})
    for poses in (start_poses, _whole_grid_start_poses):
        with pytest.raises(PlanRetry):
            poses(np.random.default_rng(0), bad)


@pytest.mark.parametrize("seed,rooms,preset", [(0, (12, 16), "symsearch"), (2, (4, 8), "default")])
def test_generated_house_is_what_loading_its_json_gives(seed: int, rooms: tuple[int, int],
                                                        preset: str) -> None:
    spec = generate_house(seed, rooms=rooms, preset=preset)
    again = load_house(json.loads(spec.to_json()))
    assert spec == again
    assert spec.starts and all(type(s.x) is float and type(s.yaw) is float
                               for s in spec.starts)
