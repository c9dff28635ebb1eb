"""`sgtool scenes`: generate (same seed, same bytes, also across processes), show (a real
PNG), stats (Table I columns equal to the library's), episodes, knowledge, user errors."""

from __future__ import annotations

import json
import subprocess
import sys

from click.testing import CliRunner

from sgtool.cli import cli
from sgtool.datasets.generator import generate_house
from sgtool.datasets.scene_stats import house_stats
from sgtool.house.io import load_house


def test_generate_is_byte_stable(tmp_path):
    a, b = tmp_path / "a.json", tmp_path / "b.json"
    r = CliRunner().invoke(cli, ["scenes", "generate", "--seed", "5", "--rooms", "6-8",
                                 "-o", str(a)])
    assert r.exit_code == 0, r.output
    assert "rooms" in r.output
    # a separate process (fresh caches, fresh hash seed) writes the same bytes
    code = ("from sgtool.cli import main; main(['scenes', 'generate', '--seed', '5', "
            f"'--rooms', '6-8', '-o', {str(b)!r}])")
    subprocess.run([sys.executable, "-c", code], check=True, capture_output=True,
                   env={"PYTHONHASHSEED": "123", "PATH": "/usr/bin:/bin"})
    assert a.read_bytes() == b.read_bytes()
    spec = load_house(a)
    assert 6 <= len(spec.rooms) <= 8
    assert spec.to_json() == generate_house(5, rooms=(6, 8)).to_json()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.json", "b.json"]


def test_show_writes_a_png(tmp_path):
    house = tmp_path / "h.json"
    CliRunner().invoke(cli, ["scenes", "generate", "--seed", "2", "--rooms", "5", "-o",
                             str(house)])
    r = CliRunner().invoke(cli, ["scenes", "show", str(house), "-o", str(tmp_path / "p.png")])
    assert r.exit_code == 0, r.output
    data = (tmp_path / "p.png").read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 20_000
    # default output name beside the house
    r = CliRunner().invoke(cli, ["scenes", "show", str(house), "--no-objects"])
    assert r.exit_code == 0 and (tmp_path / "h.png").is_file()
    r = CliRunner().invoke(cli, ["scenes", "show", str(house), "-o", str(tmp_path / "p.gif")])
    assert r.exit_code == 2
    # svg and pdf carry no date, program or random ids: the same house, the same bytes
    for ext in ("svg", "pdf"):
        made = []
        for name in ("a", "b"):
            out = tmp_path / f"{name}.{ext}"
            r = CliRunner().invoke(cli, ["scenes", "show", str(house), "-o", str(out)])
            assert r.exit_code == 0, r.output
            made.append(out.read_bytes())
        assert made[0] == made[1], ext


def test_stats_json_matches_the_library():
    r = CliRunner().invoke(cli, ["scenes", "stats", "-n", "3", "--seed", "10", "--rooms", "5-7",
                                 "--json"])
    assert r.exit_code == 0, r.output
    out = json.loads(r.output)
    ours = out["rows"]["sgtool eval houses"]
    ref = house_stats(generate_house(s, rooms=(5, 7)) for s in (10, 11, 12)).to_dict()
    assert ours == ref
    assert ours["scenes"] == 3 and 5 <= ours["rooms_per_scene"] <= 7
    assert out["rows"]["bddl scenes, all (measured)"]["scenes"] == 51
    assert out["rows"]["bddl scenes, all (measured)"]["rooms_per_scene"] == 374 / 51
    assert out["rows"]["OmniGibson (SCOUT Table I)"]["rooms_per_scene"] == 7.1
    text = CliRunner().invoke(cli, ["scenes", "stats", "-n", "2"]).output
    assert "Contained Obj./Sc." in text and "InteriorGS (SCOUT Table I)" in text


def test_episodes_and_knowledge(tmp_path):
    house = tmp_path / "h.json"
    CliRunner().invoke(cli, ["scenes", "generate", "--seed", "1", "--rooms", "5", "-o",
                             str(house)])
    r = CliRunner().invoke(cli, ["scenes", "episodes", str(house), "--json"])
    assert r.exit_code == 0, r.output
    eps = json.loads(r.output)
    spec = load_house(house)
    assert len(eps) == len({o.category for o in spec.objects})
    assert all(e["shortest_path"] > 0 for e in eps)
    r = CliRunner().invoke(cli, ["scenes", "episodes", str(house), "-n", "3"])
    assert r.exit_code == 0 and r.output.count("ep_") == 3
    r = CliRunner().invoke(cli, ["scenes", "knowledge", "--json"])
    k = json.loads(r.output)
    assert k["all"]["relations"] == {"inside": 2608, "ontop": 5313, "inroom": 3207}
    assert k["train"]["activities"] + k["eval"]["activities"] == 1016


def test_a_house_without_start_poses_lists_the_episodes_the_bench_runs(tmp_path):
    """No start poses: `scenes episodes` adds those the bench and `sgtool run` add (with a
    note) instead of listing nothing, and `scenes check` notes it."""
    from sgtool.analysis.bench_houses import bench_episodes

    doc = json.loads(generate_house(1, rooms=(5, 5)).to_json())
    doc["starts"] = []
    house = tmp_path / "nostarts.json"
    house.write_text(json.dumps(doc))
    r = CliRunner().invoke(cli, ["scenes", "episodes", str(house), "--json", "-n", "4",
                                 "--seed", str(doc["seed"])])  # the bench's draw
    assert r.exit_code == 0, r.output
    assert "no start poses" in r.stderr
    listed = json.loads(r.stdout)
    ran = bench_episodes(load_house(house), 4)
    assert [(e["query"], e["start"]) for e in listed] == \
        [(e.query, e.to_dict()["start"]) for e in ran]
    r = CliRunner().invoke(cli, ["scenes", "check", str(house)])
    assert r.exit_code == 0 and "note: no start poses" in r.output


def test_user_errors_name_the_problem(tmp_path):
    bad = tmp_path / "bad.json"
    spec = json.loads(generate_house(0, rooms=(4, 4)).to_json())
    spec["furniture"][0]["size"] = [1, -1, 1]
    bad.write_text(json.dumps(spec))
    r = CliRunner().invoke(cli, ["scenes", "episodes", str(bad)])
    assert r.exit_code == 2
    assert "furniture[0].size: every side must be > 0" in r.output
    r = CliRunner().invoke(cli, ["scenes", "generate", "--rooms", "3-5", "-o",
                                 str(tmp_path / "x.json")])
    assert r.exit_code == 2 and "--rooms" in r.output
    assert not (tmp_path / "x.json").exists()
    r = CliRunner().invoke(cli, ["scenes", "show", str(tmp_path / "missing.json")])
    assert r.exit_code == 2 and "no such house spec file" in r.output


def test_outputs_are_checked_before_writing(tmp_path):
    out = tmp_path / "h.json"
    args = ["scenes", "generate", "--seed", "1", "--rooms", "4,5", "-o", str(out)]
    assert CliRunner().invoke(cli, args).exit_code == 0  # MIN,MAX works as MIN-MAX does
    r = CliRunner().invoke(cli, args)
    assert r.exit_code == 2 and "use --force" in r.output
    assert CliRunner().invoke(cli, args + ["--force"]).exit_code == 0
    r = CliRunner().invoke(cli, ["scenes", "generate", "-o", str(tmp_path / "no" / "h.json")])
    assert r.exit_code == 2 and "does not exist" in r.output
    r = CliRunner().invoke(cli, ["scenes", "show", str(out), "-o",
                                 str(tmp_path / "no" / "p.png")])
    assert r.exit_code == 2 and "does not exist" in r.output
    assert not (tmp_path / "no").exists()
    r = CliRunner().invoke(cli, ["scenes", "show", str(out), "-o", str(tmp_path / "p.gif")])
    assert r.exit_code == 2 and ".png" in r.output


def test_symsearch_preset_generate_stats_episodes(tmp_path):
    house = tmp_path / "dense.json"
    r = CliRunner().invoke(cli, ["scenes", "generate", "--seed", "2", "--rooms", "9-12",
                                 "--preset", "symsearch", "-o", str(house)])
    assert r.exit_code == 0, r.output
    spec = load_house(house)
    assert spec == generate_house(2, rooms=(9, 12), preset="symsearch")
    r = CliRunner().invoke(cli, ["scenes", "stats", "-n", "1", "--seed", "2", "--rooms",
                                 "9-12", "--preset", "symsearch", "--json"])
    assert r.exit_code == 0, r.output
    out = json.loads(r.output)
    assert out["preset"] == "symsearch"
    row = out["rows"]["sgtool eval houses (symsearch)"]
    assert row["objects_per_scene"] == len(spec.furniture) + len(spec.objects)
    r = CliRunner().invoke(cli, ["scenes", "episodes", str(house), "-n", "6", "--preset",
                                 "symsearch", "--json"])
    assert r.exit_code == 0, r.output
    eps = json.loads(r.output)
    furn = [e for e in eps if e["targets"][0].startswith("furn_")]
    assert len(eps) == 6 and len(furn) == 2  # a third ask for furniture
    assert all(e["shortest_path"] is not None and not e["hidden"] for e in furn)


def test_episodes_draw_as_the_bench_and_spellings_are_one_furniture_query(tmp_path):
    """By default `scenes episodes` draws with the house file's seed, as the bench does; two
    spellings of one furniture category are one query with both pieces as targets."""
    from sgtool.analysis.bench_houses import bench_episodes

    doc = json.loads(generate_house(3, rooms=(5, 5)).to_json())
    cats = sorted({f["category"] for f in doc["furniture"]})
    same = [f for f in doc["furniture"] if f["category"] == cats[0]]
    other = next(f for f in doc["furniture"] if f["category"] != cats[0])
    other["category"] = cats[0].upper()  # another spelling of the first category
    house = tmp_path / "h.json"
    house.write_text(json.dumps(doc))
    r = CliRunner().invoke(cli, ["scenes", "episodes", str(house), "--json", "-n", "4"])
    assert r.exit_code == 0, r.output
    assert [e["query"] for e in json.loads(r.stdout)] == \
        [e.query for e in bench_episodes(load_house(house), 4)]
    r = CliRunner().invoke(cli, ["scenes", "episodes", str(house), "--json", "--preset",
                                 "symsearch", "-n", "60"])
    eps = json.loads(r.stdout)
    assert cats[0].upper() not in {e["query"] for e in eps}
    targets = {tuple(e["targets"]) for e in eps if e["query"] == cats[0]}
    assert targets == {tuple(sorted([*(f["id"] for f in same), other["id"]],
                                    key=lambda i: int(i.split("_")[-1])))}


def test_show_of_names_the_font_lacks_prints_no_warnings(tmp_path):
    """CJK room names (the font draws boxes): no matplotlib warning with source lines per
    glyph (laying the plan out warned before it was saved)."""
    import json
    import warnings

    from support.datasets_fixtures import two_rooms

    from sgtool.datasets.draw import draw_house
    from sgtool.house.io import load_house

    d = two_rooms()
    d["rooms"][0]["category"] = "\u5bdd\u5ba4"
    spec = load_house(json.loads(json.dumps(d)))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        draw_house(spec, tmp_path / "u.png")
    assert (tmp_path / "u.png").stat().st_size > 0
