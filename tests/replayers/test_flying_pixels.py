"""A recording with mixed ("flying") depth pixels maps as the clean one does.

The small two-room house is recorded twice with the same tour, once clean and once with
`--noise flying=0.3` (three in ten depth-edge pixels read between the two surfaces), and
both logs are mapped. A mixed pixel's point floats in the free space behind an edge; in
the bird's-eye map one such point in the height band makes its cell an obstacle. With
the mixed pixels left out (the default), what the flying log adds to the clean map's
obstacles hugs them (points within the test's tolerance of a surface, a cell or two
off); without, it is scattered through the rooms."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import cKDTree
from support.small_house import small_house

from sgtool import CameraConfig, LogReader, RecordOptions, parse_noise, record_house
from sgtool.mapping.grid import OCCUPIED, OccupancyGrid
from sgtool.mapping.voxels import VoxelConfig
from sgtool.scenegraph.builder_config import BuilderConfig
from sgtool.scenegraph.stream import SceneGraphStream

pytest.importorskip("pybullet")

FAR = 0.2  # m: an obstacle cell this far from every clean obstacle is a phantom


@pytest.fixture(scope="module")
def logs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("flying")
    out = {}
    for noise in ("none", "flying=0.3"):
        out[noise] = root / f"{noise.replace('=', '-')}.mcap"
        record_house(small_house(), out[noise], RecordOptions(
            fps=4, camera=CameraConfig(width=160, height=120), noise=parse_noise(noise)))
    return out


def _obstacles(log: Path, mixed_pixels: bool) -> np.ndarray:
    """World (x, y) of the occupied cells of the log's final map."""
    stream = SceneGraphStream(None, None, BuilderConfig(voxels=VoxelConfig(
        mixed_pixels=mixed_pixels)))
    with LogReader(log) as reader:
        for frame in reader.frames():
            stream.frame(frame)
    last = stream.finish() or stream.current
    assert last is not None and last.layers is not None
    grid: OccupancyGrid = last.layers.occupancy
    ys, xs = np.nonzero(grid.grid == OCCUPIED)
    return np.stack([grid.origin[0] + xs * grid.resolution,
                     grid.origin[1] + ys * grid.resolution], axis=1)


def _phantoms(logs: dict[str, Path], mixed_pixels: bool) -> int:
    clean = _obstacles(logs["none"], mixed_pixels)
    noisy = _obstacles(logs["flying=0.3"], mixed_pixels)
    dist, _ = cKDTree(clean).query(noisy)
    return int(np.count_nonzero(dist > FAR + 1e-9))


def test_flying_pixels_add_no_phantom_obstacles(logs: dict[str, Path]) -> None:
    kept = _phantoms(logs, mixed_pixels=True)
    raw = _phantoms(logs, mixed_pixels=False)
    assert raw > 100  # the fault is strong enough to matter: ~0.25 m2 of phantoms
    assert kept <= 20 and kept * 10 <= raw  # left out, fewer than 20 cells (0.05 m2)


def test_the_clean_map_keeps_its_obstacles(logs: dict[str, Path]) -> None:
    """Surfaces have next to no mixed pixels (the odd pixel where a face steps in the
    image): the clean log maps to the same cells within a few of its ~1,700 either way."""
    on, off = _obstacles(logs["none"], True), _obstacles(logs["none"], False)
    a = {tuple(p) for p in np.round(on / 0.05).astype(int).tolist()}
    b = {tuple(p) for p in np.round(off / 0.05).astype(int).tolist()}
    assert len(b) > 1500 and len(a ^ b) <= 5
