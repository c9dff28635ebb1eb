"""The perception-noise study (`sgtool study noise`): its cells are the scores `sgtool replay
--score` gives for the log `sgtool record --noise` writes, the tables are byte-identical
when the study runs again (from the cache, on two workers), and bad input is one line."""

from __future__ import annotations

import csv
import json
import re
from pathlib import Path

import pytest
from click.testing import CliRunner
from support.small_house import small_house

from sgtool.analysis.noise_study import (
    FACTORS,
    NONE,
    PROFILE,
    RecordingSettings,
    cache_key,
    conditions_of,
    parse_factor,
)
from sgtool.cli import cli
from sgtool.errors import SgtoolError

TINY = ("--resolution", "64x48", "--fps", "2")


def _study(house: Path, cache: Path, out: Path, *extra: str):  # type: ignore[no-untyped-def]
    return CliRunner().invoke(cli, [
        "study", "noise", "--houses", "0", "--house", str(house), *TINY,
        "--factor", "label_dropout=0.2,0.05", "--cache", str(cache), "-o", str(out),
        "--no-progress", *extra])


@pytest.fixture(scope="module")
def study(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("study")
    house = root / "small.json"
    house.write_text(small_house().to_json())
    r = _study(house, root / "cache", root / "first")
    assert r.exit_code == 0, r.output
    assert "3 log(s) recorded now" in r.output
    return {"root": root, "house": house, "cache": root / "cache", "out": root / "first"}


def test_cells_are_the_scores_of_record_then_replay_score(study: dict[str, Path]) -> None:
    root = study["root"]
    log = root / "direct.mcap"
    rec = CliRunner().invoke(cli, ["record", "--house", str(study["house"]), *TINY,
                                   "--noise", "none,label_dropout=0.2", "-o", str(log),
                                   "--quiet"])
    assert rec.exit_code == 0, rec.output
    rep = CliRunner().invoke(cli, ["replay", str(log), "--score", "--json"])
    assert rep.exit_code == 0, rep.output
    direct = json.loads(rep.output)["score"]
    doc = json.loads((study["out"] / "results.json").read_text())
    cell = next(c for c in doc["cells"] if c["noise"] == "none,label_dropout=0.2")
    assert cell["factor"] == "label_dropout" and cell["level"] == "0.2"
    for variant in ("merged", "strict"):
        want = dict(direct[variant])
        want["room_error_vs_true"] = want["rooms"] - want["gt_rooms"]
        assert cell[variant] == want
    # the cache holds the very log `sgtool record` writes for that house and noise
    cached = [p for p in (study["cache"] / "small").glob("*.mcap")
              if json.loads(p.with_suffix(".json").read_text())["noise"]
              == "none,label_dropout=0.2"]
    assert len(cached) == 1 and cached[0].read_bytes() == log.read_bytes()


def test_tables_list_every_condition_once(study: dict[str, Path]) -> None:
    out = study["out"]
    rows = list(csv.DictReader((out / "results.csv").open()))
    assert [(r["house"], r["factor"], r["level"]) for r in rows] == [
        ("small", "none", "0"), ("small", "label_dropout", "0.05"),
        ("small", "label_dropout", "0.2")]
    doc = json.loads((out / "results.json").read_text())
    for r, c in zip(rows, doc["cells"], strict=True):
        assert float(r["merged_purity"]) == c["merged"]["purity"]
        assert int(r["merged_rooms"]) == c["merged"]["rooms"]
    text = (out / "summary.md").read_text()
    assert "## label_dropout (per object and frame)" in text
    cell = re.search(r"^\| label_dropout=0\.2 +\| 2/2 \d\.\d{3} \d+\.\d% of (\d+)", text,
                     re.M)
    assert cell is not None  # "of N": the objects the accuracy is over
    row = next(r for r in rows if r["level"] == "0.2")
    assert int(cell.group(1)) == int(row["merged_objects"])
    # the objects a level kept, against the noise-free graph's (a lost object is no error
    # of "objects right")
    base = next(r for r in rows if r["factor"] == "none")
    kept = 100 * int(row["merged_objects"]) / int(base["merged_objects"])
    assert "| objects kept vs none |" in text and f"| {kept:.1f}% " in text
    # the room-type stage has its column too
    assert re.search(r"\| ARI +\| categories right +\|", text)
    cats = 100 * float(base["merged_category_accuracy"])
    assert re.search(rf"^\| 0 \(none\) .*\| {cats:.1f}% +\|", text, re.M), text
    assert "Houses: small (file " in text
    assert (out / "plots" / "label_dropout.png").read_bytes()[:4] == b"\x89PNG"


def test_second_run_reuses_the_cache_and_writes_the_same_bytes(study: dict[str, Path]) -> None:
    again = study["root"] / "again"
    r = _study(study["house"], study["cache"], again, "-w", "2")
    assert r.exit_code == 0, r.output
    assert "0 log(s) recorded now" in r.output
    for name in ("summary.md", "results.json", "results.csv"):
        assert (again / name).read_bytes() == (study["out"] / name).read_bytes(), name


def test_a_non_empty_output_folder_is_refused_without_force(study: dict[str, Path]) -> None:
    r = _study(study["house"], study["cache"], study["out"])
    assert r.exit_code == 2
    assert r.output.count("\n") == 1 and "not empty" in r.output and "--force" in r.output


@pytest.mark.parametrize(("args", "says"), [
    (("--factor", "blur=0.1"), "unknown factor 'blur'"),
    (("--factor", "holes=0.1,lots"), "level 'lots' is not a number"),
    (("--factor", "holes=-0.1"), "must be >= 0"),
    (("--factor", "label_swap=2"), "a probability, at most 1"),
    (("--factor", "depth_sigma=1e300"), "'depth_sigma=1e300': level 1e300: at most 1"),
    (("--factor", "holes"), "give NAME=L1,L2"),
    (("--profile", "awful"), "unknown profile"),
])
def test_bad_input_is_one_line(tmp_path: Path, args: tuple[str, ...], says: str) -> None:
    r = CliRunner().invoke(cli, ["study", "noise", "--houses", "1", *args,
                                 "--cache", str(tmp_path / "c"), "-o", str(tmp_path / "o")])
    assert r.exit_code == 2, r.output
    assert r.output.count("\n") == 1 and says in r.output, r.output
    assert not (tmp_path / "o").exists() and not (tmp_path / "c").exists()


def test_factor_levels_and_conditions() -> None:
    assert parse_factor("holes=0.05, 1e-2,0.05") == ("holes", (0.05, 0.01))
    conds = conditions_of({"holes": (0.05, 0.0, 0.01), "depth_sigma": (0.001,)},
                          ("strong", "none"))
    assert [(c.factor, c.level, c.noise) for c in conds] == [
        (NONE, "0", "none"),
        ("depth_sigma", "0.001", "none,depth_sigma=0.001"),
        ("holes", "0.01", "none,holes=0.01"), ("holes", "0.05", "none,holes=0.05"),
        (PROFILE, "strong", "strong")]
    assert set(FACTORS) == {"depth_sigma", "holes", "label_swap", "label_dropout",
                            "drift_xy", "drift_yaw", "flying"}
    with pytest.raises(SgtoolError, match="unknown factor"):
        parse_factor("name=1")


def test_cache_key_changes_with_every_recording_input() -> None:
    house = {"generated": 3, "rooms": [8, 8]}
    base = cache_key(house, "none", RecordingSettings())
    assert base == cache_key(dict(house), "none", RecordingSettings())
    others = {cache_key({"generated": 4, "rooms": [8, 8]}, "none", RecordingSettings()),
              cache_key(house, "mild", RecordingSettings()),
              cache_key(house, "none", RecordingSettings(width=320, height=240)),
              cache_key(house, "none", RecordingSettings(fps=10.0)),
              cache_key(house, "none", RecordingSettings(frames=50)),
              cache_key(house, "none", RecordingSettings(noise_seed=1))}
    assert base not in others and len(others) == 6


def test_a_preset_is_cached_by_its_values(monkeypatch) -> None:
    """A profile named by its preset is keyed by the preset's values: a newer sgtool whose
    "mild" drifts otherwise does not reuse the older one's recordings of "mild"."""
    from sgtool.recorders.sim import noise

    house = {"generated": 3, "rooms": [8, 8]}
    before = cache_key(house, "mild", RecordingSettings())
    mild = noise.PROFILES["mild"]
    newer = noise.NoiseProfile(**{**mild.to_dict(), "name": "newer", "drift_yaw": 0.5})
    monkeypatch.setattr(noise, "parse_noise", lambda text: newer if text == "mild" else mild)
    assert cache_key(house, "mild", RecordingSettings()) != before


def test_a_json_profile_of_ones_own_is_studied_by_its_name(tmp_path: Path) -> None:
    """`--profile my.json` (record --noise and --closed-loop-noise take it) was refused as
    an unknown profile; it is a condition labelled by its name, recorded anew when the
    file's faults change."""
    mine = tmp_path / "my.json"
    mine.write_text('{"name": "cheap-camera", "holes": 0.03}')
    conds = conditions_of({}, ("mild", str(mine)))
    assert [(c.factor, c.level, c.noise) for c in conds][-2:] == [
        (PROFILE, "mild", "mild"), (PROFILE, "cheap-camera", str(mine))]
    house = {"generated": 3, "rooms": [8, 8]}
    before = cache_key(house, str(mine), RecordingSettings())
    mine.write_text('{"name": "cheap-camera", "holes": 0.05}')
    assert cache_key(house, str(mine), RecordingSettings()) != before
    with pytest.raises(SgtoolError, match="unknown profile .*or a JSON profile's file"):
        conditions_of({}, ("extreme",))
    other = tmp_path / "other.json"  # another file of that name and other faults: refused
    other.write_text('{"name": "cheap-camera", "holes": 0.2}')
    with pytest.raises(SgtoolError, match="named 'cheap-camera' as .* is, with other faults"):
        conditions_of({}, (str(mine), str(other)))


def test_closed_loop_rows_are_the_run_bench_episodes(study: dict[str, Path]) -> None:
    out = study["root"] / "closed"
    r = _study(study["house"], study["cache"], out, "--closed-loop", "scout",
               "--closed-loop-noise", "none,holes=0.05", "--episodes", "1",
               "--frames-per-room", "30")
    assert r.exit_code == 0, r.output
    runs = [json.loads(line) for line in (out / "closed_loop" / "episodes.jsonl").open()]
    assert len(runs) == 2  # one episode, two profiles
    # each row names its log relative to the folder of episodes.jsonl (not in the staging
    # folder the run wrote into, nor as this machine's absolute path)
    assert all(not Path(e["source"]).is_absolute()
               and (out / "closed_loop" / e["source"]).is_file() for e in runs)
    doc = json.loads((out / "results.json").read_text())
    rows = doc["closed_loop"]
    assert [(x["noise"], x["planner"], x["episode"]) for x in rows] == [
        ("none", "scout", 0), ("holes=0.05", "scout", 0)]
    assert [x["success"] for x in rows] == [e["success"] for e in runs]
    assert [x["query"] for x in rows] == [e["query"] for e in runs]
    text = (out / "summary.md").read_text()
    sr = [f"{float(x['success']):.3f}" for x in rows]
    assert re.search(rf"^\| scout +\| none +\| 1 +\| {sr[0]} ", text, re.M)
    assert re.search(rf"^\| scout +\| holes=0\.05 +\| 1 +\| {sr[1]} ", text, re.M)


def test_closed_loop_episodes_run_as_run_bench_runs_them(study: dict[str, Path],
                                                         monkeypatch) -> None:
    """The study's closed loop goes through run-bench's episode runner (logs land in the
    output folder as episodes finish, and come back from other nodes): every task passes
    through it, its log in the study's closed_loop/logs."""
    from sgtool.analysis.closed_loop_bench_run import EpisodeRunner

    seen: list[Path] = []
    call = EpisodeRunner.__call__

    def spy(self, fn, items):  # type: ignore[no-untyped-def]
        items = list(items)
        seen.extend(t.output for t in items)
        return call(self, fn, items)

    monkeypatch.setattr(EpisodeRunner, "__call__", spy)
    out = study["root"] / "runner"
    r = _study(study["house"], study["cache"], out, "--closed-loop", "scout", "--episodes",
               "1", "--frames-per-room", "20")
    assert r.exit_code == 0, r.output
    runs = [json.loads(line) for line in (out / "closed_loop" / "episodes.jsonl").open()]
    assert len(seen) == len(runs) >= 1  # one task per noise profile, each through it
    for p in seen:
        assert p.parts[-6:-4] == ("closed_loop", "logs") and p.name == "ep-000.mcap"
        assert out.joinpath(*p.parts[-6:]).exists()


def test_a_share_over_nothing_is_no_zero(study: dict[str, Path]) -> None:
    """A recording too short to see an object scores no object accuracy ("-", null), not
    0 %, so it cannot pull a median or plot down."""
    out = study["root"] / "short"
    r = CliRunner().invoke(cli, [
        "study", "noise", "--houses", "0", "--house", str(study["house"]),
        "--resolution", "64x48", "--frames", "1", "--factor", "holes=0.1",
        "--cache", str(study["root"] / "cache-short"), "-o", str(out), "--no-progress"])
    assert r.exit_code == 0, r.output
    cells = json.loads((out / "results.json").read_text())["cells"]
    assert all(c["merged"]["objects"] == 0 for c in cells)
    assert all(c["merged"]["object_accuracy"] is None for c in cells)


def test_a_drift_condition_says_what_its_scores_count(study: dict[str, Path]) -> None:
    """Under pose drift the map is in the drifted frame: the drift table says how it was
    aligned and what its position-based scores still count; the label-fault tables do
    not."""
    out = study["root"] / "drift"
    r = _study(study["house"], study["cache"], out, "--factor", "drift_yaw=0.01")
    assert r.exit_code == 0, r.output
    text = (out / "summary.md").read_text()
    drift = text[text.index("## drift_yaw"):]
    assert "Under pose drift the map lies in the drifted odometry frame" in drift
    assert "best fit the logged poses to the true ones" in drift
    assert "drifted odometry frame" not in text[:text.index("## drift_yaw")]
    # the cache's sidecar says what the key holds: the faults' values and the drift model
    sides = [json.loads(p.read_text()) for p in (study["cache"] / "small").glob("*.json")]
    side = next(d for d in sides if d["noise"] == "none,drift_yaw=0.01")
    assert side["noise_key"]["drift_yaw"] == 0.01 and side["noise_key"]["drift_model"] == 2


def test_the_study_takes_every_resolution_record_takes() -> None:
    """One rule for a camera image's sides (record's, the camera's): the study refused
    8..15 pixels that record and the closed loop take."""
    from sgtool.analysis.noise_study import RecordingSettings
    from sgtool.recorders.sim.camera import SIDE_RANGE, CameraConfig

    lo, hi = SIDE_RANGE
    for w, h in ((lo, lo), (hi, lo)):
        RecordingSettings(w, h).check()
        CameraConfig(width=w, height=h)
    for w, h in ((lo - 1, 16), (16, hi + 1)):
        with pytest.raises(SgtoolError, match=f"each side {lo}..{hi} pixels"):
            RecordingSettings(w, h).check()


def test_a_cached_log_with_a_damaged_chunk_is_not_taken(tmp_path: Path) -> None:
    """The cache takes a log only when it is complete: one flipped byte inside a chunk (a
    CRC mismatch) opened as a log and failed the study at its replay, twice."""
    from support.logfixtures import write_log

    from sgtool.analysis.noise_study import complete_log
    from sgtool.log import LogReader

    log = tmp_path / "c.mcap"
    write_log(log, n=4)
    assert complete_log(log)
    with LogReader(log) as r:
        chunk = max(r.summary.chunk_indexes, key=lambda c: c.chunk_length)
    data = bytearray(log.read_bytes())
    data[chunk.chunk_start_offset + chunk.chunk_length // 2] ^= 0xFF
    log.write_bytes(bytes(data))
    with LogReader(log):  # it opens
        pass
    assert not complete_log(log)
    assert not complete_log(tmp_path / "none.mcap")
