"""sgtool golden pin / check / diff on a small real log (the first 30 frames of a golden log:
3 refreshes), through the command line as a user runs it."""

from __future__ import annotations

import gzip
import json
import os
import re
import shlex
import shutil
import signal

import pytest
from support.paths import GOLDEN

from sgtool.analysis.golden_check import check_pins, first_decision_change
from sgtool.analysis.golden_decisions import planner_decisions
from sgtool.cli import main
from sgtool.log import LogReader, LogWriter
from sgtool.log.records import Episode
from sgtool.replayers.golden_pins import PIN_FORMAT, Decision, read_pins

FRAMES = ["--max-frames", "30"]


def sgtool(capsys, *args):
    """(exit code, stdout, stderr) of ``sgtool ARGS``."""
    handlers = signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM)
    try:
        main([str(a) for a in args])
        code = 0
    except SystemExit as e:
        code = int(e.code or 0)
    finally:
        signal.signal(signal.SIGINT, handlers[0])
        signal.signal(signal.SIGTERM, handlers[1])
    out = capsys.readouterr()
    return code, out.out, out.err


def summary_row(out, name):
    """The cells of ``name``'s row of the summary table."""
    for line in out.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if line.startswith("|") and cells[0] == name:
            return cells
    raise AssertionError(f"no summary row for {name}")


@pytest.fixture(scope="module")
def log(tmp_path_factory):
    dst = tmp_path_factory.mktemp("logs") / "small.mcap"
    shutil.copyfile(GOLDEN / "house10-start.mcap", dst)
    return dst


@pytest.fixture
def pinned(log, tmp_path, capsys):
    """A pin folder of ``log`` (copied in), replayed for 30 frames."""
    folder = tmp_path / "g"
    code, out, _ = sgtool(capsys, "golden", "pin", log, "--dir", folder, "--copy", *FRAMES)
    assert code == 0, out
    return folder


def test_pin_then_check_is_unchanged(pinned, log, capsys):
    pins = read_pins(pinned)
    pin = pins.logs["small"]
    assert pins.format == PIN_FORMAT
    assert pin.log == "small.mcap" and (pinned / "small.mcap").read_bytes() == log.read_bytes()
    assert pin.refreshes == 4 and pin.options.max_frames == 30  # 3 every 10 frames, 1 action
    assert pin.resolved["every"] == 10 and pin.resolved["voxel_size"] == 0.05
    assert pin.quality is not None and set(pin.quality) == {"strict", "merged"}  # house in log
    assert pin.decisions is None  # a recording, no planner
    # the pin is small: compressed graphs and refresh summaries, well under the log
    small = sum(p.stat().st_size for p in pinned.iterdir() if p.suffix != ".mcap")
    assert small < log.stat().st_size / 20
    code, out, _ = sgtool(capsys, "golden", "check", "--dir", pinned)
    assert code == 0, out
    assert "small: unchanged" in out
    assert "1 pinned log(s): 1 unchanged, 0 changed, 0 error(s)" in out


def test_a_coarser_voxel_size_is_reported_layer_by_layer(pinned, tmp_path, capsys):
    md, xml = tmp_path / "r.md", tmp_path / "j.xml"
    code, out, err = sgtool(capsys, "golden", "check", "--dir", pinned, "--voxel-size", "0.08",
                            "--report", md, "--junit", xml)
    assert code == 1
    assert "small: changed" in out and "voxel_size 0.08" in out
    # the first refresh that differs, by index, log time, frames and reason
    assert "refresh 0 at 3.000 s (after 10 frames, every) differs:" in out
    for layer in ("rooms:", "objects:", "frontiers:", "voronoi:"):
        assert f"    {layer}" in out, layer
    assert "m²" in out  # room areas
    assert "quality (" in out  # the figures before and after: the log carries its house
    row = summary_row(out, "small")
    assert row[1] == "changed" and row[3].startswith("refresh 0 at 3.000 s")
    assert int(row[4]) >= 1 and int(row[5]) >= 1  # rooms, objects differences
    assert "--update" in err
    assert "## small: changed" in md.read_text()
    junit = xml.read_text()
    assert 'tests="1" failures="1" errors="0"' in junit and "<failure" in junit
    code, _, err = sgtool(capsys, "golden", "check", "--dir", pinned, "--report", md,
                          "--junit", md)
    assert code == 2 and f"--report {md} and --junit {md}: one file" in err
    assert "## small: changed" in md.read_text()  # untouched


def test_tolerance_lets_float_level_changes_pass(pinned, capsys):
    # a refactor that moves last bits: one object shifted by 2 mm in every pinned graph
    pins = read_pins(pinned)
    path = pins.graphs_path("small")
    graphs = [json.loads(line) for line in gzip.open(path).read().splitlines()]
    for g in graphs:
        o = g["objects"][0]
        o["position"][0] = round(o["position"][0] + 0.002, 4)
    lines = [json.dumps(g, sort_keys=True, separators=(",", ":")) for g in graphs]
    from sgtool.replayers.golden import sequence_digest, write_graphs

    write_graphs(path, lines)
    index = json.loads((pinned / "expected.json").read_text())
    index["cases"]["small"]["sequence_sha256"] = sequence_digest(lines)
    (pinned / "expected.json").write_text(json.dumps(index))
    code, out, _ = sgtool(capsys, "golden", "check", "--dir", pinned)
    assert code == 1
    assert f"objects: {graphs[0]['objects'][0]['id']}" in out and "moved 0.002 m" in out
    code, out, _ = sgtool(capsys, "golden", "check", "--dir", pinned, "--tolerance", "0.005")
    assert code == 0, out


def test_update_accepts_a_deliberate_change(pinned, capsys):
    code, out, _ = sgtool(capsys, "golden", "check", "--dir", pinned, "--voxel-size", "0.08",
                          "--update")
    assert code == 0
    assert "updated small: accepted the change from refresh 0 at 3.000 s" in out
    assert read_pins(pinned).logs["small"].options.voxel_size == 0.08
    # the log sgtool copied in (--copy) stays its copy: a later pin --copy replaces it
    assert read_pins(pinned).logs["small"].copied is True
    code, out, _ = sgtool(capsys, "golden", "check", "--dir", pinned)
    assert code == 0, out


def test_a_moved_log_is_one_line_naming_it(log, tmp_path, capsys):
    mine = tmp_path / "runs" / "small.mcap"
    mine.parent.mkdir()
    shutil.copyfile(log, mine)
    folder = tmp_path / "g"
    assert sgtool(capsys, "golden", "pin", mine, "--dir", folder, *FRAMES)[0] == 0
    # not below DIR: relative to it all the same (they share tmp_path)
    assert read_pins(folder).logs["small"].log == "../runs/small.mcap"
    mine.rename(tmp_path / "elsewhere.mcap")
    code, out, err = sgtool(capsys, "golden", "check", "--dir", folder)
    assert code == 2
    assert err.count("\n") == 1 and "Traceback" not in err
    assert str(mine) in err and "missing" in err
    # pastes as it is, with the pin's settings
    assert f"`sgtool golden pin {mine.resolve()} --dir {folder} --max-frames 30`" in err
    assert "small: error:" in out


def test_ctrl_c_while_update_writes_leaves_the_pin_folder_whole(pinned, capsys,
                                                                 monkeypatch):
    """Ctrl-C arriving after a graph file is rewritten and before the index (the moment
    that left them out of step): the update finishes its files first, then stops, so the
    folder checks against its index."""
    import os
    import signal

    import sgtool.analysis.golden_check as gc

    real = gc.write_capture

    def interrupted(*args, **kwargs):
        real(*args, **kwargs)
        os.kill(os.getpid(), signal.SIGINT)

    monkeypatch.setattr(gc, "write_capture", interrupted)
    monkeypatch.chdir(pinned.parent)  # --dir as the help shows it: relative
    code, _, _ = sgtool(capsys, "golden", "check", "--dir", pinned.name, "--update",
                        "--voxel-size", "0.08")
    assert code == 130
    monkeypatch.undo()
    code, out, err = sgtool(capsys, "golden", "check", "--dir", pinned, "--voxel-size", "0.08")
    assert code == 0, out + err


def test_a_changed_log_is_refused(pinned, capsys):
    p = pinned / "small.mcap"
    data = bytearray(p.read_bytes())
    data[-100] ^= 0xFF
    p.write_bytes(bytes(data))
    code, _, err = sgtool(capsys, "golden", "check", "--dir", pinned)
    assert code == 2 and "is not the pinned log" in err and err.count("\n") == 1


@pytest.mark.parametrize("damage", ["index", "graphs"])
def test_a_damaged_pin_file_is_one_line_naming_it(pinned, capsys, damage):
    target = pinned / ("expected.json" if damage == "index" else "small.graphs.jsonl.gz")
    target.write_bytes(target.read_bytes()[: len(target.read_bytes()) // 2])
    code, _, err = sgtool(capsys, "golden", "check", "--dir", pinned)
    assert code == 2
    assert err.count("\n") == 1 and "Traceback" not in err
    assert str(target) in err and "damaged pin file" in err


@pytest.mark.parametrize("edit", ["quality", "format"])
def test_a_mistyped_pin_entry_is_one_line_naming_the_file(pinned, capsys, edit):
    """A quality figure set that is not an object, a format that is a boolean: the damaged
    pin file named in one line, not a TypeError from deep inside the check."""
    index = pinned / "expected.json"
    doc = json.loads(index.read_text())
    if edit == "quality":
        doc["cases"]["small"]["quality"] = {"strict": 5}
    else:
        doc["format"] = True
    index.write_text(json.dumps(doc))
    code, _, err = sgtool(capsys, "golden", "check", "--dir", pinned)
    assert code == 2 and err.count("\n") == 1 and "Traceback" not in err, err
    assert str(index) in err and "damaged pin file" in err, err


def test_a_newer_pin_format_is_refused_naming_both_versions(pinned, capsys):
    index = json.loads((pinned / "expected.json").read_text())
    index["format"] = PIN_FORMAT + 1
    (pinned / "expected.json").write_text(json.dumps(index))
    code, _, err = sgtool(capsys, "golden", "check", "--dir", pinned)
    assert code == 2 and err.count("\n") == 1
    assert f"pin format {PIN_FORMAT + 1} is newer" in err and f"(format {PIN_FORMAT}," in err
    # its advice is no loop: pinning again into the same folder is refused the same way
    assert "pin the logs again into a new folder" in err


def test_check_on_two_workers_reports_as_one(pinned, capsys):
    code, out, _ = sgtool(capsys, "golden", "check", "--dir", pinned, "-w", "2",
                          "--no-progress")
    assert code == 0 and "small: unchanged" in out


def test_diff_of_derived_logs(log, tmp_path, capsys):
    d1, d2 = tmp_path / "d1.mcap", tmp_path / "d2.mcap"
    assert sgtool(capsys, "replay", log, "-o", d1, *FRAMES)[0] == 0
    assert sgtool(capsys, "replay", log, "-o", d2, "--voxel-size", "0.06", *FRAMES)[0] == 0
    code, out, _ = sgtool(capsys, "diff", d1, d1)
    assert code == 0 and "the same scene graphs" in out
    code, out, err = sgtool(capsys, "diff", d1, d1, "--voxel-size", "0.3")  # nothing to replay
    assert code == 0 and "the replay options given were not used" in err
    code, out, _ = sgtool(capsys, "diff", d1, d2)
    assert code == 1 and "they differ" in out
    assert "refresh 0 at 3.000 s (after 10 frames, logged) differs:" in out
    assert "  voronoi: " in out and "area" in out
    code, out, _ = sgtool(capsys, "diff", d1, d2, "--json")
    doc = json.loads(out)
    assert code == 1 and doc["same"] is False and doc["refreshes"] == [4, 4]
    assert doc["first"].startswith("refresh 0 at 3.000 s") and doc["layers"]["rooms"] >= 1
    # a raw log is replayed with the options given: the same graphs as its derived log
    code, out, _ = sgtool(capsys, "diff", log, d1, *FRAMES)
    assert code == 0, out


def episode_log(src, dst, planner, options=None):
    """``src`` with Episode records that make it a search episode of ``planner`` (built
    with ``options``, as the closed loop records them)."""
    extra = {"planner_options": options} if options else {}
    with LogReader(src) as r, LogWriter(dst, seed=r.seed) as w:
        w.attach_house(r.house_json())
        ids: dict[int, int] = {}
        last = 0
        w.write_record(Episode(kind="search", status="started", query="mug", planner=planner), 0)
        for schema, ch, m in r.raw_messages():
            if ch.topic == "/sgtool/episode":
                continue
            if ch.id not in ids:
                ids[ch.id] = w.copy_channel(ch.topic, schema.name, schema.encoding,
                                            bytes(schema.data), ch.message_encoding,
                                            dict(ch.metadata))
            w.write_raw(ids[ch.id], m.log_time, bytes(m.data), m.sequence, m.publish_time)
            last = max(last, m.log_time)
        w.write_record(Episode(kind="search", status="failure", query="mug", planner=planner,
                               extra=extra),
                       last)
    return dst


def test_a_planner_that_cannot_be_built_here_is_an_error(log, tmp_path, capsys):
    """An episode log of a plug-in whose module is not on the path: pinning says so in one
    line (it left the decisions out silently), and so does a check of a pin made where the
    module was (it called the log changed)."""
    ep = episode_log(log, tmp_path / "episode.mcap", "labmod_not_here:Planner")
    code, out, err = sgtool(capsys, "golden", "pin", ep, "--dir", tmp_path / "g")
    assert code == 2 and not (tmp_path / "g").exists()
    assert "its planner cannot be built here" in err and "PYTHONPATH" in err
    assert "cannot import module 'labmod_not_here'" in err
    # the planner is built with the options the log records (here one it refuses)
    ep = episode_log(log, tmp_path / "opts.mcap", "scout", {"delta": -1})
    code, _, err = sgtool(capsys, "golden", "pin", ep, "--dir", tmp_path / "g2")
    assert code == 2 and "option delta=-1: must be >= 0" in err


def test_episode_logs_pin_the_planners_decisions(log, tmp_path, capsys):
    ep = episode_log(log, tmp_path / "episode.mcap", "greedy")
    folder = tmp_path / "g"
    code, out, _ = sgtool(capsys, "golden", "pin", ep, "--dir", folder)
    assert code == 0 and "greedy decisions" in out
    pin = read_pins(folder).logs["episode"]
    assert pin.planner == "greedy" and pin.decisions
    assert {d.episode for d in pin.decisions} == {0}
    # the decisions are a function of the replayed graphs: the same again
    report = check_pins(folder)
    assert report.exit_code == 0 and report.logs[0].decision is None
    from sgtool.replayers.golden_pins import capture

    cap = capture(ep, pin.options, quality=False)
    assert planner_decisions(ep, cap.graphs, cap.refreshes) == ("greedy", pin.decisions)
    # a pinned decision that the planner no longer takes is named in the report
    index = json.loads((folder / "expected.json").read_text())
    first = index["cases"]["episode"]["decisions"][0]
    index["cases"]["episode"]["decisions"][0] = [first[0], first[1], "navigate", "room:99"]
    (folder / "expected.json").write_text(json.dumps(index))
    code, out, _ = sgtool(capsys, "golden", "check", "--dir", folder)
    d = pin.decisions[0]
    assert code == 1
    assert (f"decisions: greedy at episode 0, step {d.step}: navigate(room:99) -> "
            f"{d.text()}") in out
    row = summary_row(out, "episode")
    assert row[1] == "changed" and row[-1] == "changed"  # status, decisions
    # --update names the decision it accepts, not "decisions or quality figures"
    code, out, _ = sgtool(capsys, "golden", "check", "--dir", folder, "--update")
    assert code == 0
    assert (f"updated episode: accepted the change from the planner's decisions (greedy at "
            f"episode 0, step {d.step}: navigate(room:99) -> {d.text()})") in out


def test_the_first_decision_that_differs_is_named():
    a = (Decision(0, 1, "navigate", "room:1"), Decision(0, 3, "explore", "frontier:2"))
    b = (a[0], Decision(0, 3, "navigate", "room:2"))
    assert first_decision_change(a, a, "scout") is None
    assert first_decision_change(a, b, "scout") == (
        "decisions: scout at episode 0, step 3: explore(frontier:2) -> navigate(room:2)")
    assert first_decision_change(a, a[:1], "scout") == (
        "decisions: 1 where 2 were pinned; the first 1 agree")


def test_pins_are_added_in_place_and_a_foreign_folder_is_refused(log, tmp_path, capsys):
    folder = tmp_path / "g"
    assert sgtool(capsys, "golden", "pin", log, "--dir", folder, *FRAMES)[0] == 0
    assert (folder / ".sgtool-output").is_file()  # built beside, moved in, with a manifest
    other = tmp_path / "other.mcap"
    shutil.copyfile(log, other)
    assert sgtool(capsys, "golden", "pin", other, "--dir", folder, "--copy", *FRAMES)[0] == 0
    assert sorted(read_pins(folder).logs) == ["other", "small"]
    assert sorted(p.name for p in folder.iterdir() if not p.name.startswith(".")) == [
        "expected.json", "other.graphs.jsonl.gz", "other.mcap", "other.refreshes.jsonl.gz",
        "small.graphs.jsonl.gz", "small.refreshes.jsonl.gz"]
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("a user's file")
    code, _, err = sgtool(capsys, "golden", "pin", log, "--dir", mine, *FRAMES)
    assert code == 2 and "holds files but no pins" in err
    assert [p.name for p in mine.iterdir()] == ["notes.txt"]


def test_a_pin_replacing_another_logs_pin_of_its_name_says_so(log, tmp_path, capsys):
    """Logs of one name from two folders (a run-bench folder names every log ep-NNN) pin
    under one name: the second replaces the first, and the output says which it replaced;
    pinning the same log again says nothing of the kind."""
    a, b = tmp_path / "a" / "ep-000.mcap", tmp_path / "b" / "ep-000.mcap"
    for p in (a, b):
        p.parent.mkdir()
        shutil.copyfile(log, p)
    folder = tmp_path / "g"
    code, out, _ = sgtool(capsys, "golden", "pin", a, "--dir", folder, *FRAMES)
    assert code == 0 and "replaces" not in out
    code, out, _ = sgtool(capsys, "golden", "pin", a, "--dir", folder, *FRAMES)
    assert code == 0 and "replaces" not in out
    code, out, _ = sgtool(capsys, "golden", "pin", b, "--dir", folder, *FRAMES)
    assert code == 0 and "; replaces the pin of ../a/ep-000.mcap (../b/ep-000.mcap)" in out
    # copied in, both pins' log is ep-000.mcap of the folder: another log by its bytes
    c = tmp_path / "c" / "ep-000.mcap"
    c.parent.mkdir()
    shutil.copyfile(GOLDEN / "house6-tour.mcap", c)
    copies = tmp_path / "copies"
    assert sgtool(capsys, "golden", "pin", a, "--dir", copies, "--copy", *FRAMES)[0] == 0
    code, out, _ = sgtool(capsys, "golden", "pin", c, "--dir", copies, "--copy", *FRAMES)
    assert code == 0 and "; replaces the pin of ep-000.mcap (another log, sha256 " in out


def test_a_repository_of_logs_and_pins_checks_out_anywhere(log, tmp_path, capsys):
    """Logs beside the pin folder (logs/, tests/golden/) are stored relative to it: a
    clone elsewhere checks its own copy; the hint to accept a change repeats the options
    and logs checked, quoted."""
    repo = tmp_path / "lab repo"
    (repo / "logs").mkdir(parents=True)
    shutil.copyfile(log, repo / "logs" / "small.mcap")
    pins = repo / "tests" / "golden"
    assert sgtool(capsys, "golden", "pin", repo / "logs" / "small.mcap", "--dir", pins,
                  *FRAMES)[0] == 0
    assert read_pins(pins).logs["small"].log == "../../logs/small.mcap"
    clone = tmp_path / "clone"
    shutil.copytree(repo, clone)
    shutil.rmtree(repo)
    code, out, _ = sgtool(capsys, "golden", "check", "--dir", clone / "tests" / "golden")
    assert code == 0, out
    code, _, err = sgtool(capsys, "golden", "check", "--dir", clone / "tests" / "golden",
                          "--log", "small", "--voxel-size", "0.08")
    assert code == 1
    folder = shlex.quote(str(clone / "tests" / "golden"))
    assert (f"accept it with: sgtool golden check --dir {folder} --log small --voxel-size "
            "0.08 --update") in err
    code, out, _ = sgtool(capsys, "golden", "check", "--dir", clone / "tests" / "golden",
                          "--update")
    assert code == 0 and "nothing to accept" in out


def test_a_symlinked_data_folder_stays_a_link_in_the_index(log, tmp_path, capsys):
    """A repository whose data/ is a symlink to a shared drive: the index names the log
    through the link (../data/small.mcap), so the link pointed at another copy of the same
    log still checks; a second --log of the same name is checked once."""
    first, second = tmp_path / "drive1", tmp_path / "drive2"
    for d in (first, second):
        d.mkdir()
        shutil.copyfile(log, d / "small.mcap")
    repo = tmp_path / "repo"
    repo.mkdir()
    (repo / "data").symlink_to(first)
    pins = repo / "pins"
    assert sgtool(capsys, "golden", "pin", repo / "data" / "small.mcap", "--dir", pins,
                  *FRAMES)[0] == 0
    assert read_pins(pins).logs["small"].log == "../data/small.mcap"
    (repo / "data").unlink()
    (repo / "data").symlink_to(second)
    shutil.rmtree(first)
    code, out, err = sgtool(capsys, "golden", "check", "--dir", pins, "--log", "small",
                            "--log", "small")
    assert code == 0, out + err
    assert summary_row(out, "small")


def test_a_log_without_camera_frames_is_not_pinned(log, tmp_path, capsys):
    """Its replay maps nothing (a refresh at each action record, of an empty map): a pin
    of it would pass whatever the mapping code did."""
    from support.mcap_variants import without

    empty = without(log, tmp_path / "no depth.mcap", "/camera/depth")
    code, _, err = sgtool(capsys, "golden", "pin", empty, "--dir", tmp_path / "g")
    assert code == 2 and "mapped no camera frame" in err and err.count("\n") == 1
    assert not (tmp_path / "g").exists()


def test_a_pin_name_must_stay_in_its_folder(pinned, tmp_path, capsys):
    index = json.loads((pinned / "expected.json").read_text())
    index["cases"]["../escape/small"] = index["cases"].pop("small")
    (pinned / "expected.json").write_text(json.dumps(index))
    code, _, err = sgtool(capsys, "golden", "check", "--dir", pinned, "--update")
    assert code == 2 and "a pin name is a file name" in err
    assert not (tmp_path / "escape").exists()


def test_pinning_elsewhere_drops_the_copy_pinned_before(pinned, log, tmp_path, capsys):
    """A log pinned with --copy, then pinned again from outside the folder: the old copy
    goes, and the pin names the log given."""
    assert (pinned / "small.mcap").is_file()
    assert sgtool(capsys, "golden", "pin", log, "--dir", pinned, *FRAMES)[0] == 0
    assert not (pinned / "small.mcap").exists()
    assert (pinned / read_pins(pinned).logs["small"].log).resolve() == log.resolve()
    code, out, _ = sgtool(capsys, "golden", "check", "--dir", pinned)
    assert code == 0, out


def test_a_pin_folder_reached_through_a_symlink(log, tmp_path, capsys):
    """The folder is a link into another tree; the log lies beside the link: the stored
    path is relative to where the folder really is, and the check finds the log."""
    (tmp_path / "R" / "a" / "b" / "store").mkdir(parents=True)  # deeper than the link
    (tmp_path / "L" / "logs").mkdir(parents=True)
    shutil.copyfile(log, tmp_path / "L" / "logs" / "run.mcap")
    (tmp_path / "L" / "golden").symlink_to(tmp_path / "R" / "a" / "b" / "store")
    folder = tmp_path / "L" / "golden" / "g"
    assert sgtool(capsys, "golden", "pin", tmp_path / "L" / "logs" / "run.mcap", "--dir",
                  folder, *FRAMES)[0] == 0
    code, out, err = sgtool(capsys, "golden", "check", "--dir", folder)
    assert code == 0, out + err


@pytest.mark.parametrize(("value", "verdict"), [(0, "error"), ("x", None)])
def test_a_pinned_option_out_of_range_is_that_case_s_error(pinned, capsys, tmp_path, value,
                                                           verdict):
    """every 0 in the index is that case's error row (the report and JUnit still written),
    as a replay names it; a value of the wrong type is a damaged pin file, one line."""
    index = pinned / "expected.json"
    doc = json.loads(index.read_text())
    doc["cases"]["small"]["options"]["every"] = value
    index.write_text(json.dumps(doc))
    junit = tmp_path / "j.xml"
    code, out, err = sgtool(capsys, "golden", "check", "--dir", pinned, "--junit", junit)
    if verdict == "error":
        assert code == 2 and summary_row(out, "small")[1] == "error", out
        assert "every 0 (--every): must be >= 1" in out and junit.is_file()
    else:
        assert code == 2 and err.count("\n") == 1 and str(index) in err, err
        assert "'every' is a string" in err


def test_update_pins_needs_a_report_that_kept_its_replays(pinned) -> None:
    """A report made without keep=True has nothing to pin: one line, not a silent []."""
    from sgtool.analysis.golden_check import check_pins, update_pins
    from sgtool.errors import SgtoolError
    from sgtool.replayers.derived_log import ReplayOptions

    coarse = ReplayOptions(voxel_size=0.08)
    report = check_pins(pinned, coarse)
    assert report.exit_code == 1
    with pytest.raises(SgtoolError, match=r"check_pins\(\.\.\., keep=True\)"):
        update_pins(report)
    assert update_pins(check_pins(pinned, coarse, keep=True)) != []
    assert check_pins(pinned, coarse).exit_code == 0  # accepted


def test_another_every_is_compared_at_the_times_both_refresh(pinned, capsys):
    """--every 5 against a pin of every 10: refreshes are paired by time (the pinned 3 s
    graph with the new 3 s graph, not with the new refresh 0 at 1.5 s), and the report
    says so."""
    code, out, _ = sgtool(capsys, "golden", "check", "--dir", pinned, "--every", "5")
    assert code == 1
    assert "small: changed" in out and "compared where both refresh" in out
    assert "refresh 0 at 1.500 s" not in out  # no graph at 1.5 s was pinned
    # the count is of the refreshes compared, not of those only one replay has
    assert re.search(r"\b\d+ of the \d+ refreshes compared are not byte-identical", out), out
    heads = [x for x in out.splitlines() if " differs:" in x]
    for head in heads:  # a refresh of the new replay that the pin has a graph for too
        assert any(f"at {t:.3f} s" in head for t in (3.0, 6.0, 9.0)) or "refreshes where" \
            in head, head


def test_reports_say_what_this_check_did(pinned, tmp_path, capsys):
    """--update's accepted change passes in the JUnit file (exit 0 agrees), and a check
    that cannot start (a damaged index) replaces an earlier all-green report with its
    error instead of leaving it."""
    md, xml = tmp_path / "r.md", tmp_path / "j.xml"
    code, out, _ = sgtool(capsys, "golden", "check", "--dir", pinned, "--voxel-size", "0.08",
                          "--update", "--report", md, "--junit", xml)
    assert code == 0 and "updated small: accepted" in out
    assert 'failures="0" errors="0"' in xml.read_text() and "<system-out>" in xml.read_text()
    assert "## Accepted (--update)" in md.read_text()
    code, _, _ = sgtool(capsys, "golden", "check", "--dir", pinned, "--report", md,
                        "--junit", xml)
    assert code == 0 and 'tests="1" failures="0" errors="0"' in xml.read_text()
    (pinned / "expected.json").write_text("{damaged")
    code, _, err = sgtool(capsys, "golden", "check", "--dir", pinned, "--report", md,
                          "--junit", xml)
    assert code == 2 and "damaged pin file" in err
    assert 'errors="1"' in xml.read_text() and "damaged pin file" in xml.read_text()
    assert "error: " in md.read_text() and "unchanged" not in md.read_text()
    # a value click refuses before the check runs replaces the reports too
    code, _, _ = sgtool(capsys, "golden", "check", "--dir", pinned, "--report", md,
                        "--junit", xml, "--tolerance", "-1")
    assert code == 2
    assert 'errors="1"' in xml.read_text() and "--tolerance" in xml.read_text()
    assert "damaged pin file" not in md.read_text() and "--tolerance" in md.read_text()


def test_a_re_recorded_log_is_told_how_to_pin_it_with_its_settings(log, tmp_path, capsys):
    """The hint of a log whose bytes changed gives the pin command with the pinned options
    and note (a bare `golden pin` would reset them); an index of no pins is refused."""
    mine = tmp_path / "small.mcap"
    shutil.copyfile(log, mine)
    folder = tmp_path / "g"
    code, _, _ = sgtool(capsys, "golden", "pin", mine, "--dir", folder, "--every", "5",
                        "--max-frames", "20", "--why", "the lab's kitchen")
    assert code == 0
    shutil.copyfile(GOLDEN / "house6-tour.mcap", mine)  # re-recorded in its place
    code, out, err = sgtool(capsys, "golden", "check", "--dir", folder)
    assert code == 2
    hint = f"sgtool golden pin {mine} --dir {folder} --every 5 --max-frames 20 --why " \
        "'the lab'\"'\"'s kitchen'"
    assert hint in out + err, out + err
    index = json.loads((folder / "expected.json").read_text())
    index["cases"] = {}
    (folder / "expected.json").write_text(json.dumps(index))
    code, _, err = sgtool(capsys, "golden", "check", "--dir", folder)
    assert code == 2 and "its index pins no log" in err


def test_the_re_pin_hint_runs_as_given(log, tmp_path) -> None:
    """A pin made from Python with an option `golden pin` has no flag for (max_depth):
    the hint's command keeps to the flags it takes and names the rest."""
    from sgtool.analysis.golden_check import pin_command, pin_logs
    from sgtool.replayers.derived_log import ReplayOptions

    pin_logs([log], tmp_path / "g", ReplayOptions(max_frames=20, max_depth=3.0))
    pin = read_pins(tmp_path / "g").logs["small"]
    text = pin_command(pin, log, tmp_path / "g")
    assert text == (f"sgtool golden pin {log} --dir {tmp_path / 'g'} --max-frames 20 "
                    "(and from Python: max_depth=3.0)")


def test_a_report_is_never_written_over_a_pinned_log_or_a_pin_file(pinned, tmp_path, capsys):
    """--report/--junit replace an earlier report of their kind, never the pinned copy of a
    log, expected.json or a file of the user's (they took the pins with them before)."""
    before = {p.name: p.read_bytes() for p in pinned.iterdir()}
    notes = tmp_path / "notes.txt"
    notes.write_text("mine\n")
    pom = tmp_path / "pom.xml"  # XML, and another tool's JUnit file: not this check's
    pom.write_text('<?xml version="1.0"?>\n<project/>\n')
    other = tmp_path / "pytest.xml"
    other.write_text('<?xml version="1.0"?><testsuites><testsuite name="pytest"/></testsuites>')
    for option, target in (("--junit", pinned / "small.mcap"),
                           ("--report", pinned / "expected.json"), ("--junit", notes),
                           ("--junit", pom), ("--junit", other)):
        code, _, err = sgtool(capsys, "golden", "check", "--dir", pinned, option, target)
        assert code == 2 and f"{option} {target}: exists and is not a golden check report" \
            in err, err
    assert {p.name: p.read_bytes() for p in pinned.iterdir()} == before
    assert notes.read_text() == "mine\n" and pom.read_text().endswith("<project/>\n")
    md, xml = tmp_path / "r.md", tmp_path / "r.xml"
    for _ in range(2):  # a report of the last check is replaced
        code, _, err = sgtool(capsys, "golden", "check", "--dir", pinned, "--report", md,
                              "--junit", xml)
        assert code == 0, err
    assert md.read_text().startswith("# Golden check of ") and "<testsuite" in xml.read_text()


def test_a_users_log_in_the_pin_folder_is_never_deleted_or_replaced(log, tmp_path, capsys):
    """A log pinned in place in the pin folder (not a copy sgtool made), then a log of the
    same name pinned from elsewhere: the user's log stays (it was taken for an earlier
    copy and deleted). With --copy a file of the user's there is refused, unchanged."""
    folder = tmp_path / "G"
    other = tmp_path / "b.mcap"
    shutil.copyfile(log, other)
    assert sgtool(capsys, "golden", "pin", other, "--dir", folder, *FRAMES)[0] == 0
    mine = folder / "small.mcap"
    shutil.copyfile(log, mine)
    assert sgtool(capsys, "golden", "pin", mine, "--dir", folder, *FRAMES)[0] == 0
    assert read_pins(folder).logs["small"].copied is False
    assert sgtool(capsys, "golden", "pin", log, "--dir", folder, *FRAMES)[0] == 0
    assert mine.read_bytes() == log.read_bytes()  # kept
    # --copy over a file of the user's with other bytes: refused, the file as it was
    user = tmp_path / "H"
    user.mkdir()
    assert sgtool(capsys, "golden", "pin", other, "--dir", user, *FRAMES)[0] == 0
    (user / "small.mcap").write_bytes(b"my own notes, not a log")
    code, _, err = sgtool(capsys, "golden", "pin", log, "--dir", user, "--copy", *FRAMES)
    assert code == 2 and "is a file sgtool did not copy there; not replacing it" in err
    assert (user / "small.mcap").read_bytes() == b"my own notes, not a log"
    assert "small" not in read_pins(user).logs


def test_logs_pinned_in_place_in_a_folder_of_their_own(log, tmp_path, capsys):
    """A folder holding only the logs to pin (the example fixture's layout, first run):
    pinned in place, the logs named as they lie; another file there is still refused."""
    folder = tmp_path / "golden-logs"
    folder.mkdir()
    shutil.copyfile(log, folder / "x.mcap")
    code, out, err = sgtool(capsys, "golden", "pin", folder / "x.mcap", "--dir", folder,
                            *FRAMES)
    assert code == 0, out + err
    assert read_pins(folder).logs["x"].log == "x.mcap" and (folder / "x.mcap").is_file()
    assert sgtool(capsys, "golden", "check", "--dir", folder)[0] == 0


@pytest.mark.parametrize("name", ["..mcap", ".mcap", "x\\y.mcap"])
def test_a_log_whose_name_cannot_name_a_pin_is_refused(log, tmp_path, capsys, name):
    odd = tmp_path / "odd"
    odd.mkdir()
    shutil.copyfile(log, odd / name)
    code, _, err = sgtool(capsys, "golden", "pin", odd / name, "--dir", tmp_path / "Q", *FRAMES)
    assert code == 2 and "cannot name one" in err and "rename the log" in err
    assert not (tmp_path / "Q").exists()


@pytest.mark.parametrize(("damage", "said"), [
    ("lfs", "it is a Git LFS pointer, not the log: fetch it (`git lfs pull`)"),
    ("cut", "it ends without the MCAP footer (cut short"),
    ("other", "it is not an MCAP file")])
def test_a_pinned_log_that_is_no_whole_log_says_what_it_is(pinned, capsys, damage, said):
    """An LFS pointer never fetched, or a log cut short, is not 're-recorded': the check
    says what the file is, not to pin it again."""
    log = pinned / "small.mcap"
    data = log.read_bytes()
    log.write_bytes({"lfs": b"version https://git-lfs.github.com/spec/v1\noid sha256:" +
                            b"0" * 64 + b"\nsize 1460047\n",
                     "cut": data[: len(data) - 100], "other": b"PK\x03\x04 a zip"}[damage])
    code, out, err = sgtool(capsys, "golden", "check", "--dir", pinned)
    assert code != 0 and said in out + err and "pin it again" not in out + err


def test_without_a_refresh_file_other_refreshes_pair_by_the_graphs_times(pinned, capsys,
                                                                          tmp_path):
    """An older pin holds no refresh file (optional): `--every 5` compared the refreshes
    by position, a graph at 1.5 s against one at 3 s. The graphs' own times pair them, as
    the refresh file's do: the same refreshes compared either way."""
    def heads(folder):
        out = sgtool(capsys, "golden", "check", "--dir", folder, "--every", "5")[1]
        return [x.strip() for x in out.splitlines() if x.strip().startswith("refresh ")]

    with_file = heads(pinned)
    (pinned / "small.refreshes.jsonl.gz").unlink()
    assert heads(pinned) == with_file != []


def test_a_check_waits_for_a_pin_being_written(pinned, capsys):
    """A pin of the same folder in progress holds its lock: a check reading the index and
    its graphs waits for it (it read a new graphs file against the old index: 'damaged')."""
    import threading

    from sgtool.analysis.golden_check import check_pins
    from sgtool.analysis.pin_lock import pins_locked

    done: list[str] = []
    with pins_locked(pinned):
        t = threading.Thread(target=lambda: done.append(
            check_pins(pinned).logs[0].status))
        t.start()
        t.join(timeout=3)
        assert t.is_alive() and not done  # waiting for the writer
    t.join(timeout=120)
    assert done == ["unchanged"]


def test_a_file_an_older_index_pinned_is_not_replaced_by_a_copy(pinned, log, tmp_path,
                                                              capsys):
    """An index written before pins recorded 'copied' cannot tell sgtool's copy from a
    log the user pinned in place: --copy of another log of that name is refused with
    the reason (it overwrote a user's log pinned in place), the file as it was; new pins
    say copied true or false."""
    index = json.loads((pinned / "expected.json").read_text())
    assert index["cases"]["small"].pop("copied") is True
    (pinned / "expected.json").write_text(json.dumps(index))
    again = tmp_path / "again" / "small.mcap"  # re-recorded: another log of that name
    again.parent.mkdir()
    shutil.copyfile(GOLDEN / "house6-tour.mcap", again)
    before = (pinned / "small.mcap").read_bytes()
    code, _, err = sgtool(capsys, "golden", "pin", again, "--dir", pinned, "--copy", *FRAMES)
    assert code == 2 and "did not record whether it copied the log there" in err
    assert (pinned / "small.mcap").read_bytes() == before
    mine = tmp_path / "mine"
    mine.mkdir()
    shutil.copyfile(log, mine / "small.mcap")
    assert sgtool(capsys, "golden", "pin", mine / "small.mcap", "--dir", mine, *FRAMES)[0] == 0
    assert json.loads((mine / "expected.json").read_text())["cases"]["small"]["copied"] is False


def test_a_copy_into_a_full_folder_names_the_copy(log, tmp_path, capsys, monkeypatch):
    """A --copy that fails for want of space named the log read ("No space left on
    device: LOG"), not the pin folder's file it could not write; nothing is pinned."""
    import errno

    def full(src, dst, *a, **k):  # type: ignore[no-untyped-def]
        raise OSError(errno.ENOSPC, "No space left on device", str(src))

    monkeypatch.setattr(shutil, "copyfile", full)
    folder = tmp_path / "g"
    code, _, err = sgtool(capsys, "golden", "pin", log, "--dir", folder, "--copy", *FRAMES)
    assert code == 2 and err.count("\n") == 1
    assert f"cannot write {folder / 'small.mcap'}: No space left on device" in err
    assert not (folder / "expected.json").exists()


def test_a_lock_folder_that_is_not_the_user_s_is_one_line(log, tmp_path, capsys,
                                                          monkeypatch):
    """Something else named like this user's lock folder in the temporary folder (a file
    here; another user's folder likewise): one line naming it and the way out, where pin
    and check raised Python's FileExistsError or PermissionError."""
    import tempfile

    tmp = tmp_path / "tmp"
    tmp.mkdir()
    (tmp / f"sgtool-pin-locks-{os.getuid()}").write_text("")
    monkeypatch.setattr(tempfile, "tempdir", str(tmp))
    code, _, err = sgtool(capsys, "golden", "pin", log, "--dir", tmp_path / "g", *FRAMES)
    assert code == 2 and err.count("\n") == 1 and "Traceback" not in err, err
    assert f"its lock folder {tmp / f'sgtool-pin-locks-{os.getuid()}'} is unusable" in err
    assert "set TMPDIR" in err and not (tmp_path / "g" / "expected.json").exists()


@pytest.mark.parametrize("tolerance", [-1, float("nan"), "x"])
def test_check_pins_refuses_a_tolerance_the_cli_refuses(pinned, tolerance):
    """From Python a negative or NaN tolerance ran silently (and passed), text made every
    log a check error; `--tolerance` and `diff_logs` refuse them in one line."""
    from sgtool.errors import SgtoolError

    with pytest.raises(SgtoolError, match="tolerance"):
        check_pins(pinned, tolerance=tolerance)
