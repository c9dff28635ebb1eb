"""`sgtool scenes` and `--house` take a house path as a path, even one that starts with "{";
a refused house is one line naming the file and the field, exit 2."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner
from support.datasets_fixtures import no_free_floor, two_rooms, walled_off

from sgtool.cli import cli
from sgtool.commands.options import house_from_options


def _write(path: Path, doc: dict) -> Path:
    path.write_text(json.dumps(doc))
    return path


def test_a_house_file_named_with_a_brace_loads(tmp_path: Path) -> None:
    p = _write(tmp_path / "{h1}.json", two_rooms())
    r = CliRunner().invoke(cli, ["scenes", "episodes", str(p), "-n", "1"])
    assert r.exit_code == 0, r.output
    assert "apple" in r.output or "cup" in r.output
    spec, house_id = house_from_options(str(p), None, "4-12")
    assert house_id == "{h1}" and len(spec.rooms) == 2


def test_a_refused_house_is_one_line_naming_file_and_field(tmp_path: Path) -> None:
    p = _write(tmp_path / "typo.json", dict(two_rooms(), passage=[]))
    r = CliRunner().invoke(cli, ["scenes", "episodes", str(p)])
    assert r.exit_code == 2
    lines = [x for x in r.output.splitlines() if x.strip()]
    assert len(lines) == 1 and "typo.json: passage: unknown key (did you mean 'passages'?)" \
        in lines[0]
    q = _write(tmp_path / "{bad}.json", dict(two_rooms(), id="../../escape"))
    r = CliRunner().invoke(cli, ["scenes", "show", str(q), "-o", str(tmp_path / "x.png")])
    assert r.exit_code == 2 and "{bad}.json: id: '../../escape' contains '/'" in r.output
    assert not (tmp_path / "x.png").exists()


def test_episodes_of_a_house_without_free_floor_name_the_room(tmp_path: Path) -> None:
    """A room filled by its furniture gives no episodes: `scenes episodes` says why (the
    bench's check of house files), not "no small objects"."""
    tiny = no_free_floor()
    p = _write(tmp_path / "tiny.json", tiny)
    r = CliRunner().invoke(cli, ["scenes", "episodes", str(p)])
    assert r.exit_code == 2
    assert f"{p}: rooms: room room_0 has no free floor" in r.output
    assert "no small objects" not in r.output


def test_check_names_every_file_with_its_verdict(tmp_path: Path) -> None:
    """`scenes check` runs the bench's checks file by file (folders too): an ok line with
    the counts and notes for each good file, an error line for each bad one, exit 2."""
    from support.datasets_fixtures import walled_off

    (tmp_path / "houses").mkdir()
    good = _write(tmp_path / "houses" / "a.json", two_rooms())
    cut = _write(tmp_path / "houses" / "b.json", walled_off(two_rooms(), "door_0"))
    tiny = _write(tmp_path / "tiny.json", no_free_floor())
    r = CliRunner().invoke(cli, ["scenes", "check", str(tmp_path / "houses")])
    assert r.exit_code == 0, r.output
    lines = r.output.splitlines()
    assert lines[0] == (f"ok {good}: a: 2 room(s), 2 piece(s) of furniture, 2 small "
                        "object(s), 2 query category(ies)")
    assert lines[1].startswith(f"ok {cut}: b: ")
    assert lines[2].startswith("   note: room_") and len(lines) == 3
    r = CliRunner().invoke(cli, ["scenes", "check", str(good), str(tiny)])
    assert r.exit_code == 2
    assert r.output.splitlines()[1] == (f"error {tiny}: rooms: room room_0 has no free floor "
                                        "(no cell where the robot fits) and no door or "
                                        "passage to a room that has")
    assert r.output.splitlines()[-1] == "sgtool: error: 1 problem(s) in the house files above"
    r = CliRunner().invoke(cli, ["scenes", "check", str(good), str(good)])  # one file twice
    assert r.exit_code == 2 and "given twice" in r.output
    (tmp_path / "none").mkdir()
    r = CliRunner().invoke(cli, ["scenes", "check", str(tmp_path / "none")])
    assert r.exit_code == 2 and f"error {tmp_path / 'none'}: no *.json house files" in r.output
    bare = two_rooms()
    bare["furniture"][1]["affordances"] = []  # the table the cup lies on
    bare_file = _write(tmp_path / "bare.json", bare)
    r = CliRunner().invoke(cli, ["scenes", "check", str(bare_file)])
    assert r.exit_code == 0 and r.output.splitlines()[1] == (
        "   note: read as supporters, with something on top and no 'supporter' in the file: "
        "table")


def test_check_gives_each_files_lines_as_it_is_checked(tmp_path: Path,
                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    """A folder of big houses takes minutes: each file's lines go out when it is done, not
    all at the end (the second file is loaded after the first's line was emitted)."""
    from sgtool.analysis import bench_houses

    good = _write(tmp_path / "a.json", two_rooms())
    other = _write(tmp_path / "b.json", walled_off(two_rooms(), "door_0"))
    emitted: list[str] = []
    seen: list[str] = []
    real = bench_houses.load_house_files

    def load(paths, taken=()):  # noqa: ANN001, ANN202 - the loader, watched
        seen.append(f"load {Path(paths[0]).name} after {len(emitted)} line(s)")
        return real(paths, taken)

    monkeypatch.setattr(bench_houses, "load_house_files", load)
    lines, ok = bench_houses.check_house_files([good, other], emit=emitted.append)
    assert ok and emitted == lines
    assert seen == ["load a.json after 0 line(s)", "load b.json after 1 line(s)"]
