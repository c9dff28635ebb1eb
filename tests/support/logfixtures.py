"""Synthetic RGB-D + instance frames that look like simulator renders (flat shading,
piecewise-planar depth), and a small log with every channel type, for log tests and
benchmarks."""

from __future__ import annotations

import numpy as np
from foxglove_schemas_protobuf.Color_pb2 import Color
from foxglove_schemas_protobuf.LinePrimitive_pb2 import LinePrimitive
from foxglove_schemas_protobuf.Point3_pb2 import Point3
from foxglove_schemas_protobuf.SceneEntity_pb2 import SceneEntity
from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate

from sgtool.log import CameraIntrinsics, LogWriter, codec
from sgtool.log import schemas as S


def synthetic_frame(i: int, width: int = 64, height: int = 48):
    """Frame ``i``: a floor, a wall and a box whose position moves with ``i``. The camera
    drives 0.05 m a frame towards the wall, which comes as near in the depth (down to
    0.5 m): depth and poses agree, as the imports' pose check asks."""
    k = CameraIntrinsics.from_fov(width, height, 60.0)
    v, u = np.mgrid[0:height, 0:width]
    depth = np.full((height, width), max(3.0 - 0.05 * i, 0.5), np.float32)
    ids = np.full((height, width), 2, np.int32)  # wall
    floor = v > height * 0.6
    depth[floor] = (1.2 * k.fy / np.maximum(v[floor] - k.cy, 1)).astype(np.float32)
    ids[floor] = 1
    x0 = (i * 3) % max(width - 10, 1)
    box = (u >= x0) & (u < x0 + 10) & (v > height * 0.4) & (v < height * 0.8)
    depth[box] = 1.5
    ids[box] = 3
    palette = np.array([[0, 0, 0], [120, 110, 90], [200, 200, 190], [30, 90, 160]], np.uint8)
    rgb = palette[ids]
    base = np.eye(4)
    base[0, 3] = 0.05 * i
    cam = np.array([[0, 0, 1, 0], [-1, 0, 0, 0], [0, -1, 0, 1.2], [0, 0, 0, 1]], float)
    pose = base @ cam
    return k, rgb, depth, ids, pose, base


# a log with every channel type (FPS frames a second)
FPS = 10
DT = 1_000_000_000 // FPS


def write_log(path, n=12, **kw):
    with LogWriter(path, seed=7, **kw) as w:
        w.attach_house('{"version": "1.0"}')
        w.write_record("instances", 0, {"instances": [
            {"id": 1, "category": "floor", "kind": "structure"},
            {"id": 3, "category": "cabinet", "kind": "furniture", "state": "closed",
             "affordances": ["openable", "container"]},
        ]})
        w.write_record("episode", 0, {"kind": "recording", "status": "started"})
        for i in range(n):
            k, rgb, depth, ids, pose, base = synthetic_frame(i)
            w.write_frame(i * DT, rgb=rgb, depth=depth, ids=ids, pose=pose, intrinsics=k,
                          base_pose=base)
        grid = np.full((4, 5), -1, np.int8)
        grid[1:3, 1:4] = 0
        grid[0, 0] = 100
        w.write_proto(S.OCCUPANCY, n * DT, codec.encode_grid(n * DT, grid, (1.5, -2.0), 0.05))
        upd = SceneUpdate(entities=[SceneEntity(
            id="voronoi", frame_id="world",
            lines=[LinePrimitive(type=LinePrimitive.LINE_LIST, thickness=0.02,
                                 points=[Point3(x=0, y=0, z=0), Point3(x=1, y=2, z=0)],
                                 color=Color(r=1, g=0, b=0, a=1))],
        )])
        w.write_proto(S.VORONOI, n * DT, upd)
        w.write_record("action", n * DT, {"skill": "open", "target": "obj:3",
                                          "outcome": "success", "travelled_m": 1.25})
        w.write_record("scene_graph", n * DT, {"version": "1.0", "rooms": [], "objects": []})
        w.write_record("llm_exchange", n * DT, {"model": "m", "messages": [{"role": "user",
                       "content": "hi"}], "response": "Command: done()", "latency_s": 0.5})
        w.write_record("episode", n * DT, {"kind": "recording", "status": "ended", "frames": n})
    return path
