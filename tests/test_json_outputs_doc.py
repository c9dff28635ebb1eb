"""docs/json-outputs.md lists the top-level keys every ``--json`` prints: each command is run
with ``--json`` on a small input and the keys it prints are compared with the doc's ``key``
tables (read from the doc, so the two cannot drift apart); every command with a ``--json``
option has its section."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import click
import pytest
from click.testing import CliRunner
from support.bag_export import write_log_as_bag
from support.frames_log import frames_log
from support.logfixtures import write_log
from support.paths import GOLDEN, REPO
from support.rgbd_folders import make_tum_folder
from support.semantics_fixtures import ChatServer
from support.small_house import small_house

from sgtool.cli import cli
from sgtool.house.io import save_house
from sgtool.results import EpisodeResult, write_jsonl

DOC = REPO / "docs" / "json-outputs.md"
# sections documented from the code only (the doc says why)
NOT_RUN = {"distill": "a training is too heavy for this test and needs torch"}
# command path -> its section, where they differ
SECTION_OF = {"import bag": "import", "import rgbd": "import"}


def doc_tables() -> dict[str, dict[str, str]]:
    """Section heading -> {key: its ``present`` cell} of the section's ``key`` table."""
    out: dict[str, dict[str, str]] = {}
    section = None
    columns: list[str] | None = None
    for line in DOC.read_text(encoding="utf-8").splitlines():
        if line.startswith("## "):
            section, columns = line[3:].strip(), None
            continue
        if not line.startswith("|"):
            columns = None
            continue
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if columns is None:
            columns = cells
            continue
        if columns[0] != "key" or set(line) <= set("|-: "):
            continue
        assert section is not None, line
        key = re.fullmatch(r"`([^`]+)`", cells[0])
        assert key, f"{DOC.name}: {section}: a key cell is not one `name`: {line}"
        table = out.setdefault(section, {})
        assert key[1] not in table, f"{DOC.name}: {section}: {key[1]} listed twice"
        table[key[1]] = cells[columns.index("present")]
    return out


TABLES = doc_tables()


def check_keys(section: str, printed: Any, required: set[str] | frozenset[str] = frozenset(),
               optional: set[str] | frozenset[str] = frozenset()) -> None:
    """The keys of ``printed`` are the section's ``always`` keys, the conditional ones this
    run must print (``required``) and any of ``optional`` (conditional keys that depend on
    the data)."""
    table = TABLES[section]
    always = {k for k, present in table.items() if present == "always"}
    conditional = set(table) - always
    assert set(required) | set(optional) <= conditional, (section, required, optional)
    assert isinstance(printed, dict), printed
    keys = set(printed)
    assert keys - set(table) == set(), f"{section}: printed but not documented"
    assert always - keys == set(), f"{section}: documented as always but not printed"
    assert set(required) - keys == set(), f"{section}: conditional keys not printed"
    assert keys == always | set(required) | (keys & set(optional)), (
        f"{section}: printed conditional keys this run should not print: "
        f"{sorted(keys - always - set(required) - set(optional))}")


def run(args: list[str], exit_code: int = 0) -> Any:
    r = CliRunner().invoke(cli, args)
    assert r.exit_code == exit_code, (args, r.output, r.exception)
    return json.loads(r.stdout, parse_constant=not_json)


def not_json(name: str) -> None:
    raise AssertionError(f"{name} printed: not JSON (a strict parser refuses it)")


def test_every_json_option_has_its_section() -> None:
    found = []

    def walk(cmd: click.Command, ctx: click.Context, path: list[str]) -> None:
        if isinstance(cmd, click.Group):  # (its commands may load lazily)
            for name in cmd.list_commands(ctx):
                sub = cmd.get_command(ctx, name)
                assert sub is not None, name
                walk(sub, click.Context(sub, parent=ctx, info_name=name), [*path, name])
        elif any("--json" in p.opts for p in cmd.params):
            found.append(" ".join(path))

    walk(cli, click.Context(cli, info_name="sgtool"), [])
    assert {"info", "import bag", "scenes episodes", "llm check"} <= set(found), found
    missing = [c for c in found if SECTION_OF.get(c, c) not in TABLES]
    assert not missing, f"commands with --json that {DOC.name} does not document: {missing}"
    for section in NOT_RUN:
        assert section in TABLES


@pytest.fixture(scope="module")
def small(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("jsondoc")


def test_info(small: Path) -> None:
    log = write_log(small / "info.mcap")
    conditional = {k for k, present in TABLES["info"].items() if present != "always"}
    check_keys("info", run(["info", str(log), "--json"]),
               required=conditional - {"repeated_frame_times"})


def test_info_of_a_rerun_recording(small: Path) -> None:
    from sgtool.analysis.view_run import write_rerun

    rrd = write_rerun(write_log(small / "rrd.mcap", n=3), small / "info.rrd", voxels=False)
    check_keys("info FILE.rrd", run(["info", str(rrd), "--json"]))


def test_doctor(small: Path) -> None:
    log = write_log(small / "doctor.mcap")
    check_keys("doctor", run(["doctor", str(log), "--json"]))
    cut = small / "cut.mcap"
    cut.write_bytes(log.read_bytes()[: log.stat().st_size * 2 // 3])
    doc = run(["doctor", str(cut), "--recover", str(small / "rec.mcap"), "--json"],
              exit_code=1)
    assert doc["status"] == "truncated"
    check_keys("doctor", doc, required={"recovered_to"})


def test_replay_with_score_and_an_llm(tmp_path: Path) -> None:
    """Then from the transcript: no answer timed, so no speed (it printed NaN, no JSON)."""
    def rooms(request: dict) -> dict:
        return {"text": "kitchen"}

    talk = tmp_path / "rooms.jsonl"
    with ChatServer(responder=rooms) as srv:
        doc = run(["replay", str(GOLDEN / "house6-tour.mcap"), "--max-frames", "12",
                   "--classifier", "llm", "--llm-base-url", srv.base_url, "--llm-model", "m",
                   "--llm-constraint", "none", "--llm-transcript", str(talk), "--score",
                   "--json"])
    check_keys("replay", doc, required={"score", "llm_answers"}, optional={"warnings", "notes"})
    again = run(["replay", str(GOLDEN / "house6-tour.mcap"), "--max-frames", "12",
                 "--classifier", "llm", "--llm-replay", str(talk), "--json"])
    assert again["llm_answers"]["tokens_per_s"] is None


def test_replay_many(small: Path) -> None:
    log = frames_log(small / "many.mcap")
    doc = run(["replay", str(log), "--out-dir", str(small / "derived"), "--json"])
    check_keys("replay --out-dir", doc)
    assert [x["status"] for x in doc["logs"]] == ["replayed"]


def test_replay_and_diff(small: Path) -> None:
    a = frames_log(small / "a.mcap")
    b = frames_log(small / "b.mcap", shift=(0.2, 0.0, 0.0))
    doc = run(["replay", str(a), "-o", str(small / "a-derived.mcap"), "--json"])
    check_keys("replay", doc, optional={"warnings", "notes"})
    check_keys("diff", run(["diff", str(a), str(b), "--json"], exit_code=1))
    check_keys("diff", run(["diff", str(a), str(a), "--json"]))


def test_eval(small: Path) -> None:
    run_ = EpisodeResult("greedy", 0, "house-0", 0, "mug", True, steps=4, travelled_m=10.0,
                         shortest_m=9.48)
    rows = [run_, EpisodeResult("scout", 0, "house-0", 0, "mug", False, steps=50,
                                travelled_m=20.0, shortest_m=9.48)]
    write_jsonl(rows, small / "episodes.jsonl")
    check_keys("eval", run(["eval", str(small / "episodes.jsonl"), "--json"]))


def test_import_rgbd_and_bag(small: Path) -> None:
    tum = make_tum_folder(small / "tum", [100.0 + i / 30 for i in range(5)])
    check_keys("import", run(["import", "rgbd", str(tum), "-o", str(small / "tum.mcap"),
                              "--intrinsics", "60,60,39.5,29.5", "--quiet", "--json"]))
    bag = small / "bag"
    write_log_as_bag(frames_log(small / "for-bag.mcap"), bag)
    check_keys("import", run(["import", "bag", str(bag), "-o", str(small / "bag.mcap"),
                              "--depth", "/camera/depth/image_raw", "--rgb",
                              "/camera/rgb/image_raw", "--info", "/camera/depth/camera_info",
                              "--quiet", "--json"]))
    listed = run(["import", "bag", str(bag), "--list", "--json"])  # (was its text listing)
    check_keys("import bag --list", listed)
    assert {"topic": "/camera/depth/image_raw", "type": "sensor_msgs/msg/Image",
            "count": 4} in listed["topics"]


def test_scenes(small: Path) -> None:
    check_keys("scenes stats",
               run(["scenes", "stats", "-n", "1", "--rooms", "4-5", "--json"]))
    check_keys("scenes knowledge", run(["scenes", "knowledge", "--json"]))
    house = small / "house.json"
    save_house(small_house(), house)
    episodes = run(["scenes", "episodes", str(house), "-n", "2", "--json"])
    assert isinstance(episodes, list) and episodes
    for e in episodes:
        check_keys("scenes episodes", e)


def test_distill_report() -> None:
    check_keys("distill --report", run(["distill", "--report", "--json"]))


def test_llm_check() -> None:
    """A scripted endpoint: the speed request's reply, then a decision that does not parse
    (exit 1, the JSON printed)."""
    with ChatServer([{"text": "kitchen bathroom bedroom hallway"}, {"text": "no idea"}]) as srv:
        doc = run(["llm", "check", "--llm-base-url", srv.base_url, "--llm-model", "m",
                   "--json"], exit_code=1)
    check_keys("llm check", doc)
    assert doc["decision_parsed"] is False
