"""``sgtool demo``: the README's first command."""

from __future__ import annotations

from pathlib import Path

import click


@click.command("demo")
@click.option("-o", "--out", "out_dir", type=click.Path(file_okay=False), default="demo-out",
              show_default=True, help="Folder for the demo's logs and results.")
def command(out_dir: str) -> None:
    """Write a small synthetic log and summarise it (the recorder replaces this soon)."""
    import numpy as np

    from sgtool.log import CameraIntrinsics, LogWriter
    from sgtool.log.inspect import format_summary, summarize

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    path = out / "synthetic.mcap"
    k = CameraIntrinsics.from_fov(320, 240, 60.0)
    with LogWriter(path, seed=0) as w:
        w.write_record("episode", 0, {"kind": "recording", "status": "started",
                                      "source": "synthetic"})
        for i in range(30):
            depth = np.full((240, 320), 2.0 + 0.01 * i, np.float32)
            pose = np.eye(4)
            pose[0, 3] = 0.1 * i
            w.write_frame(i * 100_000_000, depth=depth, pose=pose, intrinsics=k,
                          rgb=np.zeros((240, 320, 3), np.uint8))
        w.write_record("episode", 30 * 100_000_000, {"kind": "recording", "status": "ended",
                                                     "frames": 30, "source": "synthetic"})
    click.echo(format_summary(summarize(path)))
