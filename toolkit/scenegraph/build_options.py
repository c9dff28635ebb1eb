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
MAX_DEPTH_M = VoxelConfig().max_range  # depth farther is not mapped (MoMa-LLM: 0-5 m)
MAX_DEPTH_RANGE = (0.5, 20.0)  # m, what --max-depth accepts


@dataclass(frozen=True)
class ResolvedOptions:
    every: int
    classifier: str
    min_points: int
    voxel_size: float
    max_frames: int | None
    max_depth: float = MAX_DEPTH_M  # m

    def to_metadata(self) -> dict[str, str]:
        """The options as text; ``max_depth`` only when it is not the default (so default
        replays write what they wrote before it was an option)."""
        return {k: "" if v is None else str(v) for k, v in asdict(self).items()
                if k != "max_depth" or v != MAX_DEPTH_M}


def default_min_points(width: int, height: int) -> int:
    """MoMa-LLM's 50 points at 320x240, scaled by the pixel count (at least 5)."""
    return max(5, round(MIN_POINTS_320x240 * width * height / (320 * 240)))


def mapping_record(options: ResolvedOptions) -> dict[str, Any]:
    """What a live builder writes into its Episode record (``extra.mapping``) so that a
    replay with default options rebuilds its graphs."""
    return {"every": options.every, "classifier": options.classifier,
            "min_points": options.min_points, "voxel_size": options.voxel_size,
            **({"max_depth": options.max_depth} if options.max_depth != MAX_DEPTH_M else {}),
            # the voxel map left mixed depth pixels out (logs without the key kept them)
            "mixed_pixels": VoxelConfig().mixed_pixels}


def builder_config(options: ResolvedOptions) -> BuilderConfig:
    return BuilderConfig(voxels=VoxelConfig(resolution=options.voxel_size,
                                            min_points=options.min_points,
                                            max_range=options.max_depth),
                         refresh_every=options.every)
