"""The options a scene graph is built with, as a live builder logs them and a replay reads them.

A closed-loop log records them in its ``sgtool.Episode`` record (``extra.mapping``,
:func:`mapping_record`), so a replay with default options rebuilds the graphs the planner
decided on.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

from sgtool.mapping.voxels import VoxelConfig
from sgtool.scenegraph.builder import BuilderConfig

# ``llm`` (MoMa-LLM's room classification) needs a chat client or a transcript from the caller
CLASSIFIERS = ("containment", "frequency", "llm", "none")
MIN_POINTS_320x240 = 50  # MoMa-LLM: an object is seen with > 50 points (256x256 camera)


@dataclass(frozen=True)
class ResolvedOptions:
    every: int
    classifier: str
    min_points: int
    voxel_size: float
    max_frames: int | None

    def to_metadata(self) -> dict[str, str]:
        return {k: "" if v is None else str(v) for k, v in asdict(self).items()}


def default_min_points(width: int, height: int) -> int:
    """MoMa-LLM's 50 points at 320x240, scaled by the pixel count (at least 5)."""
    return max(5, round(MIN_POINTS_320x240 * width * height / (320 * 240)))


def mapping_record(options: ResolvedOptions) -> dict[str, Any]:
    """What a live builder writes into its Episode record (``extra.mapping``) so that a
    replay with default options rebuilds its graphs."""
    return {"every": options.every, "classifier": options.classifier,
            "min_points": options.min_points, "voxel_size": options.voxel_size}


def builder_config(options: ResolvedOptions) -> BuilderConfig:
    return BuilderConfig(voxels=VoxelConfig(resolution=options.voxel_size,
                                            min_points=options.min_points),
                         refresh_every=options.every)
