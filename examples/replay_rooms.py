"""Replay an sgtool log and print the rooms of every refresh's scene graph.

Run::

    python examples/replay_rooms.py tests/golden/house6-tour.mcap --classifier containment
    python examples/replay_rooms.py run.mcap --every 5 --max-frames 100

Each refresh prints one header line (its index, log time, why it refreshed and the frames
integrated so far), then one line per room: its id, its category, how many objects the
graph places in it (nested ones included) and whether it is explored (a room seen only
through a closed door is not). Nothing is written: the replay runs without an output log.
"""

from __future__ import annotations

import argparse

import sgtool


def room_lines(graph: sgtool.SceneGraph) -> list[str]:
    """One line per room of ``graph``: id, category, objects in it, explored or not."""
    return [f"  {room.id:<10} {room.category:<16} {len(graph.objects_in(room.id)):>3} objects"
            f"{'' if room.explored else '  (unexplored)'}" for room in graph.rooms]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("log", help="an sgtool log (MCAP) with depth frames")
    parser.add_argument("--every", type=int, default=None,
                        help="frames between refreshes (default: what the log says, else 10)")
    parser.add_argument("--max-frames", type=int, default=None, help="stop after N frames")
    parser.add_argument("--classifier", choices=("frequency", "containment", "none"),
                        default=None, help="room categories from contents (default: what "
                        "the log says, else frequency; the golden logs are pinned with "
                        "containment)")
    args = parser.parse_args()

    def on_refresh(refresh: sgtool.Refresh, stream: sgtool.SceneGraphStream) -> None:
        graph = refresh.graph
        print(f"refresh {refresh.index} at {refresh.time_ns / 1e9:.3f} s ({refresh.reason}, "
              f"{refresh.frames} frames): {len(graph.rooms)} rooms, "
              f"{len(graph.objects)} objects")
        for line in room_lines(graph):
            print(line)

    options = sgtool.ReplayOptions(every=args.every, max_frames=args.max_frames,
                                   classifier=args.classifier)
    report = sgtool.replay(args.log, options=options, on_refresh=on_refresh)
    print(f"{report.frames} frames, {report.refreshes} refreshes")


if __name__ == "__main__":
    try:
        main()
    except sgtool.SgtoolError as e:  # a user's mistake (no such log, ...): one line
        raise SystemExit(f"replay_rooms: {e}") from None
