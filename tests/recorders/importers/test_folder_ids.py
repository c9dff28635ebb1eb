"""Instance ids of one's own in an RGB-D folder (`sgtool import rgbd --ids DIR --instances
FILE`, sgtool.recorders.importers.folder_ids): an outside lab's folder of 16-bit id PNGs
beside its depth could not be imported at all (no flag; the folder passed without a
word). Each id image is paired with its depth image by name, written as the frame's ids
with the table at the first frame; a depth image without its id image, one of another
size, a colour image as ids and a table without ids are one line each."""

from __future__ import annotations

import json

import cv2
import numpy as np
import pytest
from click.testing import CliRunner
from support.rgbd_folders import make_tum_folder

from sgtool.cli import cli
from sgtool.errors import SgtoolError
from sgtool.log import LogReader
from sgtool.log.records import Instances, SceneGraphRecord
from sgtool.recorders.importers.rgbd import RgbdOptions, import_rgbd
from sgtool.recorders.importers.textformats import PinholeParams

K = PinholeParams(60.0, 60.0, 39.5, 29.5)  # the test folders' camera
TIMES = [100.0 + i / 30 for i in range(6)]
TABLE = {"instances": [{"id": 3, "category": "chair", "kind": "furniture"},
                       {"id": 700, "category": "mug", "kind": "object"}]}


def _with_ids(tmp_path, fmt: str = ".png"):
    root = make_tum_folder(tmp_path / "f", TIMES)
    (root / "instance").mkdir()
    for i, d in enumerate(sorted((root / "depth").iterdir())):
        ids = np.zeros(cv2.imread(str(d), cv2.IMREAD_UNCHANGED).shape, np.uint16)
        ids[10:20, 5 + i:25 + i] = 3  # a chair moving across the image
        ids[40:44, 60:64] = 700  # a mug: an id beyond 8 bits
        if fmt == ".npy":
            np.save(root / "instance" / f"{d.stem}.npy", ids.astype(np.int32))
        else:
            cv2.imwrite(str(root / "instance" / f"{d.stem}{fmt}"), ids)
    (tmp_path / "table.json").write_text(json.dumps(TABLE))
    return root


@pytest.mark.parametrize("fmt", [".png", ".npy"])
def test_a_folders_id_images_are_imported_with_their_table(tmp_path, fmt) -> None:
    root = _with_ids(tmp_path, fmt)
    r = CliRunner().invoke(cli, ["import", "rgbd", str(root), "--ids", str(root / "instance"),
                                 "--instances", str(tmp_path / "table.json"), "-o",
                                 str(tmp_path / "a.mcap"), "--intrinsics", "60,60,39.5,29.5",
                                 "--quiet", "--json"])
    assert r.exit_code == 0, r.output
    assert json.loads(r.stdout)["instance_ids"] is True
    reader = LogReader(tmp_path / "a.mcap")
    frames = list(reader.frames())
    assert len(frames) == 6
    for i, f in enumerate(frames):
        assert f.ids is not None and f.ids.dtype == np.int32
        assert sorted(np.unique(f.ids).tolist()) == [0, 3, 700]
        assert (f.ids[10:20, 5 + i:25 + i] == 3).all() and (f.ids == 3).sum() == 200
    [(t, table)] = list(reader.records(Instances))
    assert t == frames[0].time_ns
    assert [(x.id, x.category) for x in table.instances] == [(3, "chair"), (700, "mug")]
    if fmt == ".png":  # and a replay builds the lab's objects from them
        r = CliRunner().invoke(cli, ["replay", str(tmp_path / "a.mcap"), "-o",
                                     str(tmp_path / "d.mcap")])
        assert r.exit_code == 0, r.output
        _, last = list(LogReader(tmp_path / "d.mcap").records(SceneGraphRecord))[-1]
        assert sorted(o.category for o in last.graph().objects) == ["chair", "mug"]


def test_a_folder_of_ids_not_asked_for_is_named(tmp_path) -> None:
    root = _with_ids(tmp_path)
    rep = import_rgbd(root, tmp_path / "a.mcap", RgbdOptions(intrinsics=K, progress=False))
    assert not rep.has_ids
    assert any(n.startswith("instance/ not read: give --ids ") for n in rep.notes), rep.notes


def test_id_images_that_do_not_fit_are_one_line(tmp_path) -> None:
    root = _with_ids(tmp_path)
    ids = root / "instance"
    first = sorted(ids.iterdir())[0]
    first.unlink()
    with pytest.raises(SgtoolError, match=r"^--ids .*instance: 1 of the 6 depth images have no "
                       r"id image of the same name there \(first: 0000 with"):
        import_rgbd(root, tmp_path / "a.mcap", RgbdOptions(intrinsics=K, progress=False, ids=ids))
    cv2.imwrite(str(first), np.zeros((30, 40), np.uint16))  # half the size
    with pytest.raises(SgtoolError, match=r"0000.png: 40x30 pixels, its depth image has 80x60"):
        import_rgbd(root, tmp_path / "a.mcap", RgbdOptions(intrinsics=K, progress=False, ids=ids))
    cv2.imwrite(str(first), np.zeros((60, 80, 3), np.uint8))  # a colour image
    with pytest.raises(SgtoolError, match=r"0000.png: an id image must be single-channel "
                       r"integers"):
        import_rgbd(root, tmp_path / "a.mcap", RgbdOptions(intrinsics=K, progress=False, ids=ids))
    assert not list(tmp_path.glob("a.mcap*"))  # nothing half written
    table = Instances.from_json(TABLE)
    with pytest.raises(SgtoolError, match=r"^--instances is the table of the instance ids: "
                       r"give the folder of the id images too \(--ids DIR\)$"):
        import_rgbd(root, tmp_path / "a.mcap",
                    RgbdOptions(intrinsics=K, progress=False, instances=table))


def test_a_palette_png_of_ids_says_to_save_them_grey(tmp_path) -> None:
    """Label tools save masks as palette (indexed-colour) PNGs, one channel of indices;
    OpenCV expands them to colour, and the message called the file a colour image."""
    import zlib
    from pathlib import Path

    from sgtool.recorders.importers.folder_ids import read_ids

    def chunk(kind: bytes, data: bytes) -> bytes:
        return (len(data).to_bytes(4, "big") + kind + data
                + zlib.crc32(kind + data).to_bytes(4, "big"))

    h, w = 3, 4
    rows = b"".join(b"\x00" + bytes([0, 1, 2, 1]) for _ in range(h))
    png = (b"\x89PNG\r\n\x1a\n"
           + chunk(b"IHDR", w.to_bytes(4, "big") + h.to_bytes(4, "big") + bytes([8, 3, 0, 0, 0]))
           + chunk(b"PLTE", bytes([0, 0, 0, 255, 0, 0, 0, 255, 0]))
           + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))
    path = Path(tmp_path / "0000.png")
    path.write_bytes(png)
    with pytest.raises(SgtoolError, match=r"0000.png: a palette \(indexed-colour\) PNG, whose "
                       r"colours OpenCV reads, not its indices: save the ids as a greyscale"):
        read_ids(path, (h, w))
