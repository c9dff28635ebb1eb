"""House files for the benchmark: ids, folders, every problem reported before anything runs;
episodes of a hand-made house; one episode run from a script."""

from __future__ import annotations

from pathlib import Path

import pytest
from support.foreign_house import QUERIES, cottage, write_cottage

from sgtool.analysis.bench_houses import (
    HouseFilesError,
    bench_episodes,
    generated_houses,
    load_house_files,
)
from sgtool.house.io import load_house
from sgtool.recorders.symbolic_environment import RunOneError, SymbolicHouse, run_one


def test_ids_from_file_names_or_the_spec(tmp_path) -> None:
    write_cottage(tmp_path / "a")
    write_cottage(tmp_path / "a", "barn.json")
    own = write_cottage(tmp_path / "b", "x.json", id="Villa Rosa")
    (tmp_path / "a" / "notes.txt").write_text("not a house")
    houses = load_house_files([tmp_path / "a", own])
    assert [h.id for h in houses] == ["barn", "cottage", "Villa Rosa"]
    assert houses[2].source == str(own) and houses[2].spec is not None
    assert [h.id for h in generated_houses(2, 5)] == ["house-5", "house-6"]


def test_every_bad_file_is_named_with_its_field(tmp_path) -> None:
    good = write_cottage(tmp_path)
    no_rooms = write_cottage(tmp_path, "bad1.json", rooms=[])
    d = cottage()
    d["furniture"][0]["size"] = [0.8, 0, 1.8]
    bad_size = write_cottage(tmp_path, "bad2.json", furniture=d["furniture"])
    empty = write_cottage(tmp_path, "empty.json", objects=[])
    with pytest.raises(HouseFilesError) as e:
        load_house_files([tmp_path])
    lines = str(e.value).splitlines()
    assert len(lines) == 3
    assert lines[0].startswith(f"{no_rooms}: rooms:")
    assert lines[1].startswith(f"{bad_size}: furniture[0].size:")
    assert lines[2] == f"{empty}: objects: no small objects, nothing to search for"
    with pytest.raises(HouseFilesError, match="house id 'house-0' is already used by a "
                                              "generated house"):
        load_house_files([good, write_cottage(tmp_path / "g", "house-0.json")],
                         taken=["house-0"])
    with pytest.raises(HouseFilesError, match="no such house spec file"):
        load_house_files([tmp_path / "missing.json"])
    (tmp_path / "none").mkdir()
    with pytest.raises(HouseFilesError, match="no \\*.json house files"):
        load_house_files([tmp_path / "none"])


def test_episodes_of_a_hand_made_house() -> None:
    spec = load_house(cottage())
    eps = bench_episodes(spec, 5)
    assert sorted(e.query for e in eps) == sorted(QUERIES)  # 5 categories, no repeat
    assert bench_episodes(spec, 5) == eps  # seeded by the house seed
    assert len(bench_episodes(spec, 7)) == 7  # more than categories: again, other starts


def test_run_one_on_a_hand_made_house(tmp_path: Path) -> None:
    spec = load_house(cottage())
    house = SymbolicHouse(spec)
    # start in the bedroom, look for the milk in the closed fridge of the kitchen
    r = run_one(house, "greedy", "Milk", start="region:2.0", seed=1, house_id="cottage")
    assert r.success and r.end == "found" and r.house == "cottage" and r.planner == "greedy"
    assert r.n_open >= 1  # the fridge (and the closed bedroom door) must be opened
    assert r.travelled_m >= r.shortest_m > 4.0
    again = run_one(spec, "greedy", "milk", start="region:2.0", seed=1, house_id="cottage")
    assert again.trace == r.trace  # the same from a spec
    path = write_cottage(tmp_path)
    from_file = run_one(path, "greedy", "milk", start="region:2.0", seed=1, house_id="cottage")
    assert from_file.trace == r.trace  # and from its file
    from sgtool.datasets.start_poses import start_poses

    bedroom = start_poses(spec)[2]
    by_pose = run_one(house, "greedy", "milk", start=bedroom, seed=1, house_id="cottage")
    assert by_pose.trace == r.trace  # the bedroom's one region
    drawn = run_one(house, "random", "pillow", seed=0)  # start drawn outside the bedroom
    assert drawn.success and run_one(house, "random", "pillow", seed=0).trace == drawn.trace
    with pytest.raises(RunOneError, match="no object of that category"):
        run_one(house, "greedy", "piano")
    with pytest.raises(RunOneError, match="no region 'region:9.0'"):
        run_one(house, "greedy", "milk", start="region:9.0")


def test_a_house_path_typed_three_ways_is_recorded_one_way(tmp_path, monkeypatch) -> None:
    """`--house ./hs/`, `--house $PWD/hs` and `--house hs` run the same houses: the
    settings and house sources a summary records are the same text."""
    from sgtool.analysis.bench import BenchConfig, run_benchmark

    write_cottage(tmp_path / "hs")
    monkeypatch.chdir(tmp_path)
    runs = [run_benchmark(BenchConfig(planners=("greedy",), houses=0, episodes=1, seeds=1,
                                      house_files=(given,)), progress=False)
            for given in ("./hs/", str(tmp_path / "hs"), "hs")]
    assert {tuple(r.config.settings()["house_files"]) for r in runs} == {("hs",)}
    assert {tuple(h.source for h in r.houses) for r in runs} == {("hs/cottage.json",)}
    outside = BenchConfig(planners=("greedy",), houses=0, house_files=(str(tmp_path.parent),))
    assert outside.house_files == (str(tmp_path.parent),)  # outside the working folder: as is


def test_a_house_file_given_twice_is_named_so(tmp_path) -> None:
    """`--house d/h.json --house d/h.json` (or the file and its folder): it said the file's
    id was already used by the file itself."""
    f = write_cottage(tmp_path / "d")
    for paths in ([f, f], [f, tmp_path / "d"], [f, tmp_path / "d" / ".." / "d" / f.name]):
        with pytest.raises(HouseFilesError, match=r"given twice .*: give it once$"):
            load_house_files(paths)
