"""Import an RGB-D folder, replay it into scene graphs, export the result as a ROS bag.

Run::

    python examples/import_replay_export.py rgbd_dataset_freiburg1_xyz -o out/ \\
        --intrinsics 517.3,516.5,318.6,255.3
    python examples/import_replay_export.py 7scenes/redkitchen/seq-01 -o out/ --limit 100 \\
        --format ros1

Three steps, each one public function (the same work as ``sgtool import rgbd``, ``sgtool
replay`` and ``sgtool export bag``):

1. :func:`sgtool.import_rgbd`: the folder (TUM RGB-D, 7-Scenes or Open3D/Redwood, found
   by its files) into ``OUT/imported.mcap``, made z-up with the floor at z = 0;
2. :func:`sgtool.replay`: that log into ``OUT/derived.mcap`` with the occupancy, Voronoi
   graph, rooms and scene graph of every refresh (real data has no instance ids, so the
   graphs are geometry only: no objects or room categories);
3. :func:`sgtool.export_bag`: the derived log as a ROS 2 bag folder (or a ROS 1 ``.bag``
   file) ``OUT/derived_bag``: ``nav_msgs/OccupancyGrid``, markers, images, ``/tf``.

Each step prints its report. Importing needs ``pip install 'sgtool[import]'``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import sgtool


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("folder", help="an RGB-D folder (TUM RGB-D, 7-Scenes, Open3D/Redwood)")
    parser.add_argument("-o", "--out", default="imported", help="output folder (made if missing)")
    parser.add_argument("--intrinsics", default=None, metavar="FX,FY,CX,CY",
                        help="camera intrinsics in pixels, or a file with them (TUM folders "
                             "do not say theirs)")
    parser.add_argument("--limit", type=int, default=None, help="import at most N frames")
    parser.add_argument("--every", type=int, default=1, help="import every Nth frame")
    parser.add_argument("--format", choices=("ros1", "ros2"), default="ros2", help="bag format")
    parser.add_argument("--force", action="store_true", help="replace the outputs")
    args = parser.parse_args()

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    imported, derived = out / "imported.mcap", out / "derived.mcap"
    bag = out / ("derived.bag" if args.format == "ros1" else "derived_bag")
    for path in (imported, derived):
        if path.exists() and not args.force:
            raise sgtool.SgtoolError(f"{path} exists; not overwriting it (use --force)")

    intrinsics = sgtool.parse_intrinsics(args.intrinsics) if args.intrinsics else None
    options = sgtool.RgbdOptions(intrinsics=intrinsics, limit=args.limit, every=args.every,
                                 progress=False)
    print("\n".join(sgtool.import_rgbd(args.folder, imported, options).lines()))
    print("\n".join(sgtool.replay(imported, derived).lines()))
    print("\n".join(sgtool.export_bag(derived, bag, args.format, force=args.force).lines()))


if __name__ == "__main__":
    try:
        main()
    except sgtool.SgtoolError as e:
        raise SystemExit(f"import_replay_export: {e}") from None
