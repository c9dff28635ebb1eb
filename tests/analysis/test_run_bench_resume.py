"""`sgtool run-bench` resumes only from logs run with the same settings on the same house:
a log of a changed house file is refused in one line naming the log, the message for other
settings names what differs, and a log carrying the same house in another text form (older
code, a 1.x attachment) still resumes (sgtool.analysis.run_bench_resume)."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from sgtool.analysis import closed_loop_bench as clb
from sgtool.analysis.run_bench_resume import same_house, settings_differences
from sgtool.cli import cli
from sgtool.datasets.generator import generate_house
from sgtool.house.io import save_house

ARGS = ["run-bench", "--planners", "random", "--houses", "0", "--episodes", "1",
        "--resolution", "64x48", "--max-steps", "2", "--frames", "60", "--no-progress"]


def _closed(spec):
    return dataclasses.replace(spec, doors=tuple(dataclasses.replace(d, state="closed")
                                                 for d in spec.doors))


def test_the_house_is_compared_in_canonical_form() -> None:
    spec = generate_house(6, rooms=(4, 4))
    assert same_house(spec.to_json(), spec)
    assert same_house(json.dumps(spec.to_dict()), spec)  # other spacing, no indent
    v1 = dict(spec.to_dict(), version="1.0")  # no 2.0 field used: the same house as 1.0
    assert same_house(json.dumps(v1, sort_keys=False), spec)
    assert not same_house(_closed(spec).to_json(), spec)
    assert not same_house(None, spec)
    assert not same_house("{not json", spec)
    assert not same_house('{"version": "2.0"}', spec)


def test_settings_differences_name_the_setting() -> None:
    assert settings_differences({"max_steps": 2, "seed": 0}, {"max_steps": 3, "seed": 0}) \
        == ["max steps: 2 in the log, 3 now"]
    # options given at their defaults are not kept: no options read as the defaults
    assert settings_differences({"planner_options": {"k": 2.0}}, {"planner_options": {}}) \
        == ['planner options (-O): {"k": 2.0} in the log, {} (the defaults) now']


def _first_run(tmp_path: Path) -> tuple[object, Path, Path, list[str]]:
    """A house file, a finished one-episode run of random on it: (spec, house file,
    output folder, the command)."""
    spec = generate_house(6, rooms=(4, 4))
    house = tmp_path / "myhouse.json"
    save_house(spec, house)
    out = tmp_path / "rb"
    cmd = [*ARGS, "--house", str(house), "-o", str(out)]
    first = CliRunner().invoke(cli, cmd)
    assert first.exit_code == 0, first.output
    return spec, house, out, cmd


def test_a_changed_house_file_is_not_resumed(tmp_path: Path, monkeypatch) -> None:
    spec, house, out, cmd = _first_run(tmp_path)
    log = out / "logs/none/random/myhouse/ep-000.mcap"
    monkeypatch.setattr(clb, "run_episode", lambda *a, **k: pytest.fail("ran again"))
    # the same house in another text form (as an older writer might attach it): resumed
    house.write_text(json.dumps(spec.to_dict()))
    assert CliRunner().invoke(cli, cmd).exit_code == 0
    # the same file name, another house: refused in one line naming the log
    save_house(_closed(spec), house)
    res = CliRunner().invoke(cli, cmd)
    assert res.exit_code == 2 and "Traceback" not in res.output
    assert res.output.strip().splitlines() == [
        f"sgtool: error: {log} was run on another house: the house of {house} changed "
        "since; give a fresh -o folder (out_dir=), --force to run every episode again "
        "(from Python: a fresh out_dir), or delete the log to run the episode again"]
    # other settings: the message names them
    save_house(spec, house)
    other = list(cmd)
    other[other.index("--max-steps") + 1] = "3"
    res = CliRunner().invoke(cli, other)
    assert res.exit_code == 2
    assert "was run with other settings (max steps: 2 in the log, 3 now)" in res.output


def test_a_log_of_other_frame_settings_is_not_resumed(tmp_path: Path) -> None:
    """Which ticks are frames is a setting of the log: a run with another render step or
    turn angle does not reuse it (the message names the setting), the same ones do."""
    from sgtool.analysis.run_bench_resume import logged_settings, task_settings
    from sgtool.recorders.sim.camera import CameraConfig
    from sgtool.recorders.sim.closed_loop import ClosedLoopOptions

    spec = generate_house(6, rooms=(4, 4))
    house = tmp_path / "myhouse.json"
    save_house(spec, house)
    out = tmp_path / "rb"
    res = CliRunner().invoke(cli, [*ARGS, "--house", str(house), "-o", str(out)])
    assert res.exit_code == 0, res.output
    logged, _ = logged_settings(out / "logs/none/random/myhouse/ep-000.mcap")
    opts = ClosedLoopOptions(camera=CameraConfig(width=64, height=48), max_steps=2, frames=60)
    ep = logged["episode"]
    assert settings_differences(logged, task_settings(opts, "none", ep)) == []
    assert settings_differences(
        logged, task_settings(dataclasses.replace(opts, render_step_m=0.5), "none", ep)) \
        == ["render step (m): 0.25 in the log, 0.5 now"]
    assert settings_differences(
        logged, task_settings(dataclasses.replace(opts, turn_render_deg=0.0), "none", ep)) \
        == ["turn render angle (deg): 20.0 in the log, 0.0 now"]
    # the room categories the planners saw are a setting too
    assert settings_differences(
        logged, task_settings(dataclasses.replace(opts, classifier="containment"), "none",
                              ep)) \
        == ['room classifier: "frequency" in the log, "containment" now']
    # so is how far an explore goes on
    assert settings_differences(
        logged, task_settings(dataclasses.replace(opts, explore_on=3), "none", ep)) \
        == ["explore on (frontiers): 0 in the log, 3 now"]
    # and how far the robot backs off from what it opened
    assert logged["look_in"] == 1.4
    assert settings_differences(
        logged, task_settings(dataclasses.replace(
            opts, live=dataclasses.replace(opts.live, look_in=0.0)), "none", ep)) \
        == ["look in (m): 1.4 in the log, 0.0 now",
            "look in beyond (deg): 45.0 in the log, null now"]
    # and after which opens it does (nothing to compare while it is off)
    assert logged["look_in_beyond"] == 45.0
    assert task_settings(dataclasses.replace(opts, live=dataclasses.replace(
        opts.live, look_in=0.0, look_in_beyond=10.0)), "none", ep)["look_in_beyond"] is None
    assert settings_differences(
        logged, task_settings(dataclasses.replace(
            opts, live=dataclasses.replace(opts.live, look_in_beyond=0.0)), "none", ep)) \
        == ["look in beyond (deg): 45.0 in the log, 0.0 now"]
    # a log from before each episode drew its own planner seed is not reused
    assert logged["episode_seeds"] is True
    assert settings_differences(dict(logged, episode_seeds=False),
                                task_settings(opts, "none", ep)) \
        == ["planner seed per episode: false in the log, true now"]
    # and whether the head tilted into the containers it opened (the default both ways)
    peek = opts.live.peek
    assert logged["peek"] is peek
    assert settings_differences(
        logged, task_settings(dataclasses.replace(
            opts, live=dataclasses.replace(opts.live, peek=not peek)), "none", ep)) \
        == [f"peek into containers: {str(peek).lower()} in the log, "
            f"{str(not peek).lower()} now"]
    # and whether the look-arounds kept to the camera's sight lines (off by default)
    assert logged["sight_lines"] is False
    assert settings_differences(
        logged, task_settings(dataclasses.replace(
            opts, live=dataclasses.replace(opts.live, sight_lines=True)), "none", ep)) \
        == ["sight lines: false in the log, true now"]
    # and how far an explore drove on past its frontier (a log from before: 0)
    through = opts.live.explore_through
    assert logged["explore_through"] == through
    assert settings_differences(
        logged, task_settings(dataclasses.replace(
            opts, live=dataclasses.replace(opts.live, explore_through=through + 1.0)),
            "none", ep)) \
        == [f"explore through (m): {through} in the log, {through + 1.0} now"]


def test_an_episode_drawn_otherwise_under_the_same_id_is_not_resumed(tmp_path: Path) -> None:
    """Which episodes a house gets depends on --episodes: house 1's ep-000 (4 rooms, the
    default mix) has the same id and query for 1 and 2 episodes but another start. A folder
    run with --episodes 1 does not lend that log to a run with --episodes 2: it is refused
    in one line naming the log (it was reused, and the summary differed from a fresh run)."""
    from sgtool.analysis.run_bench_resume import logged_settings

    args = ["run-bench", "--planners", "random", "--houses", "1", "--house-seed", "1",
            "--rooms", "4-4", "--preset", "default", "--resolution", "64x48",
            "--max-steps", "2", "--frames", "60", "--no-progress", "-o", str(tmp_path / "rb")]
    res = CliRunner().invoke(cli, [*args, "--episodes", "1"])
    assert res.exit_code == 0, res.output
    log = next((tmp_path / "rb" / "logs").rglob("ep-000.mcap"))
    ep_id, query, targets, rooms, start_room, pose = logged_settings(log)[0]["episode"]
    assert ep_id and query and targets and rooms and start_room and len(pose) == 3
    res = CliRunner().invoke(cli, [*args, "--episodes", "2"])
    assert res.exit_code != 0 and "ep-000.mcap was run with other settings" in res.output
    assert "Traceback" not in res.output


def test_a_refused_resume_runs_nothing_and_defaults_are_no_change(tmp_path: Path) -> None:
    """A resume with a changed setting is refused before any new episode runs (a planner
    named first used to run into the folder under the new setting); an option given at its
    default resumes; a run naming fewer planners says which logs its report leaves out."""
    _, _, out, base = _first_run(tmp_path)
    changed = [a if a != "random" else "greedy,random" for a in base]
    changed[changed.index("--max-steps") + 1] = "3"
    r = CliRunner().invoke(cli, changed)
    assert r.exit_code == 2 and "max steps: 2 in the log, 3 now" in r.output, r.output
    assert not (out / "logs/none/greedy").exists()  # nothing ran under the new setting
    recorded = json.loads((out / "run-options.json").read_text())["options"]
    assert recorded["max_steps"] == 2 and recorded["planners"] == "random"  # kept
    r = CliRunner().invoke(cli, [*base, "-O", "random.max_failures=2"])  # its default
    assert r.exit_code == 0, r.output
    r = CliRunner().invoke(cli, [a if a != "random" else "greedy,random" for a in base])
    assert r.exit_code == 0, r.output
    r = CliRunner().invoke(cli, [a if a != "random" else "greedy" for a in base])
    assert r.exit_code == 0, r.output
    recorded = json.loads((out / "run-options.json").read_text())["options"]
    assert recorded["planners"] == "greedy,random"  # read back only: the run's options kept
    assert (f"sgtool: note: 1 episode log(s) in {out}/logs are left out of this report "
            "(logs/none/random/myhouse/ep-000.mcap)") in r.stderr


def test_a_resume_replaces_a_damaged_options_file(tmp_path: Path) -> None:
    """A resume that runs nothing more replaces a damaged run-options.json (it was left,
    and the next --report-only asked to delete it) and keeps a readable one."""
    _, _, out, cmd = _first_run(tmp_path)
    options = out / "run-options.json"
    good = options.read_text()
    wrong = good.replace('"max_steps": 2', '"max_steps": "two"')  # edited by hand
    assert wrong != good
    for damaged in ("{", "[1, 2]", good[: len(good) // 2], '{"options": {}}', wrong):
        options.write_text(damaged)
        r = CliRunner().invoke(cli, cmd)
        assert r.exit_code == 0, r.output
        assert options.read_text() == good
        r = CliRunner().invoke(cli, ["run-bench", "-o", str(out), "--report-only",
                                     "--no-progress"])
        assert r.exit_code == 0, r.output


def test_report_only_tables_the_run_as_it_was_made(tmp_path: Path, monkeypatch) -> None:
    """--report-only needs none of the run's options again (run-options.json has them);
    one given is the user's (a setting the logs were not run with is refused); the report
    settings are the command's."""
    _, _, out, _ = _first_run(tmp_path)
    summary, timings = (out / "summary.md").read_text(), (out / "run.md").read_text()
    r = CliRunner().invoke(cli, ["run-bench", "-o", str(out), "--report-only",
                                 "--no-progress"])
    assert r.exit_code == 0, r.output
    assert (out / "summary.md").read_text() == summary
    assert (out / "run.md").read_text() == timings  # the run's wall clock, not "run now 0"
    r = CliRunner().invoke(cli, ["run-bench", "-o", str(out), "--report-only", "--budgets",
                                 "7", "--max-steps", "2", "--no-progress"])
    assert r.exit_code == 0, r.output
    assert "7 f/room" in (out / "summary.md").read_text()
    # the house file by its absolute path: a report from another folder finds it
    options = json.loads((out / "run-options.json").read_text())["options"]
    assert options["house_files"] == [str((tmp_path / "myhouse.json").resolve())]
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    r = CliRunner().invoke(cli, ["run-bench", "-o", str(out), "--report-only",
                                 "--no-progress"])
    assert r.exit_code == 0, r.output
    edited = out / "run-options.json"  # a value of the wrong type, by hand: one line
    text = edited.read_text()
    edited.write_text(text.replace('"max_steps": 2', '"max_steps": "2"'))
    r = CliRunner().invoke(cli, ["run-bench", "-o", str(out), "--report-only"])
    assert r.exit_code == 2 and r.output.strip() == (
        f'sgtool: error: {edited}: max_steps is "2", not a value of that option; delete the '
        "file and give the options the run was made with"), r.output
    edited.write_text(text)
    r = CliRunner().invoke(cli, ["run-bench", "-o", str(out), "--report-only",
                                 "--max-steps", "3"])  # given: not the run's, refused
    assert r.exit_code == 2 and "max steps: 2 in the log, 3 now); --report-only: give the " \
        "options the run was made with" in r.output, r.output
    (out / "run-options.json").unlink()  # a folder of an older sgtool: give the options
    r = CliRunner().invoke(cli, ["run-bench", "-o", str(out), "--report-only"])
    assert r.exit_code == 2 and "give the options the run was made with" in r.output
    r = CliRunner().invoke(cli, ["run-bench", "-o", str(out), "--report-only", "--planners",
                                 "random", "--house", str(tmp_path / "myhouse.json"),
                                 "--episodes", "1"])
    assert r.exit_code == 2
    assert "max steps: 2 in the log, 50 now" in r.output
    assert r.output.strip().endswith("; --report-only: give the options the run was made with")


def test_logs_from_before_mixed_pixels_were_left_out_say_so(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Logs written before the live map left mixed depth pixels out record neither that
    nor the ``flying`` fault: their folder is refused naming the map's change (their
    episodes were mapped otherwise), not the noise, which did not change (a fault a log
    does not name was off)."""
    from sgtool.recorders.sim import closed_loop, episode_extras
    from sgtool.recorders.sim.noise import NoiseProfile

    full, record = NoiseProfile.to_dict, episode_extras.mapping_record

    def older(options):  # type: ignore[no-untyped-def]
        return {k: v for k, v in record(options).items() if k != "mixed_pixels"}

    monkeypatch.setattr(NoiseProfile, "to_dict",  # as sgtool wrote them before both
                        lambda self: {k: v for k, v in full(self).items() if k != "flying"})
    monkeypatch.setattr(episode_extras, "mapping_record", older)
    monkeypatch.setattr(closed_loop, "mapping_record", older)
    _, _, out, cmd = _first_run(tmp_path)
    monkeypatch.undo()
    monkeypatch.setattr(clb, "run_episode", lambda *a, **k: pytest.fail("ran again"))
    again = CliRunner().invoke(cli, cmd)
    assert again.exit_code == 2, again.output
    assert "mixed depth pixels left out: false in the log, true now" in again.output
    assert "noise:" not in again.output


def test_a_log_drifted_by_the_per_frame_model_is_not_resumed(tmp_path: Path) -> None:
    """Pose drift became a random walk in the distance (the same numbers mean another
    sensor): a drifted log records the model, 2; one without it is model 1 and is not
    resumed, where its noise numbers alone matched."""
    from sgtool.analysis.run_bench_resume import logged_settings, task_settings
    from sgtool.recorders.sim.camera import CameraConfig
    from sgtool.recorders.sim.closed_loop import ClosedLoopOptions

    spec = generate_house(6, rooms=(4, 4))
    house = tmp_path / "myhouse.json"
    save_house(spec, house)
    out = tmp_path / "rb"
    res = CliRunner().invoke(cli, [*ARGS, "--house", str(house), "--noise", "drift_yaw=0.02",
                                   "-o", str(out)])
    assert res.exit_code == 0, res.output
    (log,) = (out / "logs").rglob("ep-000.mcap")
    logged, _ = logged_settings(log)
    opts = ClosedLoopOptions(camera=CameraConfig(width=64, height=48), max_steps=2, frames=60)
    now = task_settings(opts, "drift_yaw=0.02", logged["episode"])
    assert logged["drift_model"] == now["drift_model"] == 2
    assert settings_differences(logged, now) == []
    assert settings_differences(dict(logged, drift_model=1), now) == [
        "pose drift model (1: per frame, sgtool before 992f26a, or a log of 992f26a that "
        "did not record it; 2: per distance): 1 in the log, 2 now"]
    assert task_settings(opts, "none", logged["episode"])["drift_model"] is None


def test_where_an_llm_planner_gets_its_answers_is_no_setting() -> None:
    """A run-bench of moma-llm resumed against the endpoint on another port, or replayed
    from its transcript, decides alike: base_url, replay and transcript are not compared
    (resume was refused, eval noted other options); the options that decide still are."""
    from sgtool.planning.registry import effective_options

    live = {"base_url": "http://127.0.0.1:18777/v1", "transcript": "t.jsonl",
            "history_limit": 5}
    assert effective_options("moma-llm", live) == {"history_limit": 5}
    assert effective_options("moma-llm", {"replay": "t.jsonl", "history_limit": 5}) == \
        {"history_limit": 5}
    assert effective_options("moma-llm", {"history_limit": 30}) == {}  # the default


@pytest.mark.parametrize("keep", [0.0, 0.3, 0.9])
def test_a_log_recovered_from_a_cut_run_is_not_resumed(tmp_path: Path, keep: float) -> None:
    """A log that `sgtool doctor --recover` rebuilt from a killed run's partial file is not
    a finished episode: a resume refuses it in one line (it was scored as an episode that
    ended at its last step, or, holding no episode at all (``keep`` 0: a log with no
    records), refused as "run with other settings" of 17 nulls)."""
    from sgtool.log.writer import LogWriter

    _, _, out, cmd = _first_run(tmp_path)
    log = next((out / "logs").rglob("ep-000.mcap"))
    cut = tmp_path / "cut.mcap"
    data = log.read_bytes()
    cut.write_bytes(data[: int(len(data) * keep)])
    log.unlink()
    if keep:
        r = CliRunner().invoke(cli, ["doctor", str(cut), "--recover", str(log)])
    else:
        LogWriter(log).close()
    assert log.is_file()
    r = CliRunner().invoke(cli, cmd)
    assert r.exit_code == 2, r.output
    line = r.output.strip().splitlines()[-1]
    assert line.startswith(f"sgtool: error: {log}") and (
        "its episode has no closing record" in line or "holds no closed-loop episode" in line)
    assert "delete" in line and "other settings" not in line
    r = CliRunner().invoke(cli, ["run-bench", "-o", str(out), "--report-only"])
    line = r.output.strip().splitlines()[-1]  # no option given again mends such a log
    assert r.exit_code == 2 and line.endswith(("delete the log to run the episode again",
                                               "delete it to run the episode again")), line


def test_a_resumed_log_s_shortest_path_is_measured_as_now(tmp_path: Path,
                                                          monkeypatch) -> None:
    """SPL's shortest path of a resumed log is measured again as a new run measures it
    (a log of older code kept the grid geodesic), so a run resumed across the change pairs
    its episodes; the log's own figure is not read."""
    _, _, out, cmd = _first_run(tmp_path)

    def shortest(name: str) -> float:
        (row,) = [json.loads(line) for line in (out / name).read_text().splitlines()]
        return float(row["shortest_m"])

    logged = shortest("episodes.jsonl")
    monkeypatch.setattr(clb, "run_episode", lambda *a, **k: pytest.fail("ran again"))
    monkeypatch.setattr(clb, "driven_shortest", lambda spec, ep: logged + 1.25)
    assert CliRunner().invoke(cli, cmd).exit_code == 0
    assert shortest("episodes.jsonl") == pytest.approx(logged + 1.25)
