"""``sgtool record``: simulate a robot exploring a house in PyBullet and log it to MCAP.

The work is done in :mod:`sgtool.recorders.sim` (through
:func:`sgtool.analysis.sim_session.record_tour`: progress bar, live viewer, report); this
module parses the options into :class:`RecordArgs`, checks the output and the inputs and
picks the house (a spec file, a generated house, or the demo house shipped in the package).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from sgtool.commands.options import FINITE_FLOAT, SEED, PathParam, check_log_output, house_options
from sgtool.errors import SgtoolError

if TYPE_CHECKING:
    from sgtool.analysis.sim_session import RecordRequest


def _pair(option: str, text: str) -> tuple[float, float]:
    a, sep, b = text.partition(",")
    try:
        if not sep:
            raise ValueError
        return float(a), float(b)
    except ValueError:
        raise SgtoolError(f"{option} {text!r}: give two numbers MIN,MAX") from None


@click.command("record")
@house_options(
    seed_help="Generate the house for this seed (`sgtool scenes generate`) instead of "
    "reading --house.",
    rooms_help="Room count range for a house generated with --seed (N, MIN-MAX; "
    "corridors included, 4..30).")
@click.option("-o", "--output", required=True, type=PathParam(dir_okay=False),
              help="The log to write (OUT.mcap).")
@click.option("--frames", type=int, default=None,
              help="Stop after this many frames. Default: when the scripted exploration has "
              "visited every room.")
@click.option("--fps", type=FINITE_FLOAT, default=10.0, show_default=True,
              help="Frames per second of log time. The robot drives at --speed, so a higher "
              "rate gives more, closer frames for the same run.")
@click.option("--noise", default="none", show_default=True,
              help="Sensor faults: a profile (none, mild, strong), optionally with "
              "overrides ('mild,holes=0.05'), or a JSON file. Fields: depth_sigma (m of std "
              "at 1 m, grows with z^2), holes (share of depth pixels lost), label_swap, "
              "label_dropout (per visible object and frame), drift_xy (m of std after 1 m "
              "driven), drift_yaw (rad of std after 1 m driven or 1 rad turned), flying "
              "(share of depth-edge pixels read between the two surfaces, as "
              "time-of-flight cameras do).")
@click.option("--noise-seed", type=SEED, default=0, show_default=True,
              help="Seed of the sensor faults.")
@click.option("--resolution", default="320x240", show_default=True,
              help="Camera image size WIDTHxHEIGHT.")
@click.option("--fov", type=FINITE_FLOAT, default=75.0, show_default=True,
              help="Vertical field of view (degrees); square pixels.")
@click.option("--depth-range", default="0.1,6.0", show_default=True,
              help="Depth sensor range MIN,MAX (m); outside it depth reads 0.")
@click.option("--camera-height", type=FINITE_FLOAT, default=1.2, show_default=True,
              help="Camera height above the floor (m).")
@click.option("--tilt", type=FINITE_FLOAT, default=15.0, show_default=True,
              help="Downward tilt of the camera (degrees).")
@click.option("--speed", type=FINITE_FLOAT, default=0.5, show_default=True,
              help="Driving speed (m/s, at most 5); turning is 90 deg/s.")
@click.option("--start", type=int, default=0, show_default=True,
              help="Index of the house's start pose (one per room in generated houses; a "
              "house file without \"starts\" gets one per reachable room, as in `sgtool "
              "bench`).")
@click.option("--no-open-containers", is_flag=True,
              help="Do not open closed containers on the way (doors are still opened).")
@click.option("--explore", type=click.Choice(["script", "frontier"]), default="script",
              show_default=True,
              help="script: the scripted tour of every room (it knows the house); frontier: "
              "frontier exploration on the robot's own map, opening closed doors it sees "
              "when no frontier is left; reports the share of the floor seen over time.")
@click.option("--compression", type=click.Choice(["zstd", "lz4", "none"]), default="zstd",
              show_default=True, help="MCAP chunk compression.")
@click.option("--force", is_flag=True, help="Overwrite the output log.")
@click.option("--quiet", is_flag=True, help="No progress bar, no report.")
@click.option("--rerun", "rerun_to", default=None,
              metavar="spawn|connect[:URL]|serve[:WEB_PORT[:GRPC_PORT]]",
              help="Stream every frame (camera images, robot, path) to Rerun while recording: "
              "spawn a viewer, connect to one, or serve a web viewer (headless machines; "
              "waits for Ctrl-C at the end).")
def command(**given: Any) -> None:
    """Record a robot exploring a house in PyBullet: RGB-D, instance ids, poses, the
    instances table with open/closed states, every action, to an MCAP log.

    Without a planner the robot runs a scripted exploration: it visits every room
    (nearest first), opening closed doors on the way and the closed containers of each
    room, and looks around in each (again from further places of a room one look-around
    does not show whole: an L- or U-shaped room, one longer than the camera reaches).
    With no --house and no --seed it records the demo
    house shipped with sgtool. The same house, options and seeds give a byte-identical
    log. Example: `sgtool record -o demo.mcap && sgtool info demo.mcap`.
    """
    from sgtool.analysis.sim_session import record_tour

    args = RecordArgs(**given)
    out = check_log_output(args.output, force=args.force, inputs=(args.house_path, args.noise))
    request = _request(args, out)
    record_tour(request, show=click.echo, note=lambda m: click.echo(m, err=True))


@dataclass(frozen=True)
class RecordArgs:
    """The options of `sgtool record` as given (the click parameters, by name)."""

    house_path: str | None
    seed: int | None
    rooms: str
    preset: str
    output: str
    frames: int | None
    fps: float
    noise: str
    noise_seed: int
    resolution: str
    fov: float
    depth_range: str
    camera_height: float
    tilt: float
    speed: float
    start: int
    no_open_containers: bool
    explore: str
    compression: str
    force: bool
    quiet: bool
    rerun_to: str | None = None


def _request(args: RecordArgs, out: Path) -> RecordRequest:
    """The input check: the options, then the house (with start poses)."""
    from dataclasses import replace

    from sgtool.analysis.sim_session import RecordRequest
    from sgtool.commands.options import house_from_options, parse_resolution, with_starts
    from sgtool.recorders.sim import (
        CameraConfig,
        RecordOptions,
        RobotConfig,
        ScriptOptions,
        parse_noise,
    )

    if args.frames is not None and args.frames < 1:
        raise SgtoolError(f"--frames {args.frames}: must be >= 1")
    width, height = parse_resolution(args.resolution)
    dmin, dmax = _pair("--depth-range", args.depth_range)
    if not 0.0 < dmin < dmax:
        raise SgtoolError(f"--depth-range {args.depth_range}: need 0 < MIN < MAX (metres)")
    camera = CameraConfig(width=width, height=height, vfov_deg=args.fov,
                          mount_height=args.camera_height, tilt_deg=args.tilt,
                          depth_min=dmin, depth_max=dmax, near=min(0.05, dmin))
    profile = parse_noise(args.noise)
    house, house_id = house_from_options(args.house_path, args.seed, args.rooms, args.preset)
    house = with_starts(house, args.house_path or house_id)  # a hand-made house: as bench
    opts = RecordOptions(fps=args.fps, frames=args.frames, camera=camera,
                         robot=replace(RobotConfig(), speed=args.speed), noise=profile,
                         seed=args.noise_seed, start=args.start,
                         script=ScriptOptions(open_containers=not args.no_open_containers),
                         compression=args.compression, explore=args.explore)
    return RecordRequest(house=house, house_id=house_id, output=out, options=opts,
                         quiet=args.quiet, rerun_to=args.rerun_to)
