"""`sgtool demo` (the README's first command) end to end, shortened: every stage runs and
leaves its output."""

from __future__ import annotations

from click.testing import CliRunner

from sgtool.cli import cli
from sgtool.log import LogReader


def test_demo_runs_every_stage(tmp_path):
    out = tmp_path / "demo"
    r = CliRunner().invoke(cli, ["demo", "-o", str(out), "--frames", "40", "--houses", "1",
                                 "--episodes", "2", "--seeds", "1"])
    assert r.exit_code == 0, r.output
    for stage in ("sgtool record", "sgtool info", "sgtool replay", "sgtool bench"):
        assert f"== {stage}" in r.output
    assert "quality (merged)" in r.output and "| scout" in r.output
    with LogReader(out / "demo.mcap") as log:
        assert log.frame_count() == 40
    with LogReader(out / "derived.mcap") as log:
        assert log.message_count("/sgtool/scene_graph") >= 4  # every 10 frames, and actions
    assert (out / "view.rrd").stat().st_size > 0
    assert (out / "bench" / "summary.md").exists()


def test_demo_refuses_a_file_as_its_folder(tmp_path):
    f = tmp_path / "file"
    f.write_text("x")
    r = CliRunner().invoke(cli, ["demo", "-o", str(f)])
    assert r.exit_code == 2 and "is a file" in r.output and "Traceback" not in r.output


def test_a_demo_cut_short_leaves_no_outputs_of_the_run_before(tmp_path, monkeypatch):
    """A demo run again into its folder and stopped in its first stage: the previous run's
    log, replay, view and bench tables are gone (not left to pass for this run's), a
    user's own file in the folder stays."""
    import json

    import sgtool.recorders.sim as sim

    out = tmp_path / "demo"
    (out / "bench").mkdir(parents=True)
    for name in ("demo.mcap", "derived.mcap", "view.rrd", "bench/summary.md", "mine.txt",
                 "bench/notes.txt"):
        (out / name).write_text("old")
    (out / "bench" / ".sgtool-output").write_text(json.dumps(
        {"command": "bench", "files": ["summary.md"]}))
    (out / ".sgtool-output").write_text(json.dumps(
        {"command": "demo", "files": ["demo.mcap", "derived.mcap", "view.rrd"]}))

    def stopped(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(sim, "record_house", stopped)
    r = CliRunner().invoke(cli, ["demo", "-o", str(out), "--frames", "5"])
    assert r.exit_code != 0
    left = sorted(p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file())
    assert left == [".sgtool-output", "bench/notes.txt", "mine.txt"]


def test_a_demo_never_deletes_a_users_files_of_its_output_names(tmp_path, monkeypatch):
    """A folder holding a derived.mcap sgtool demo did not write (no manifest lists it):
    one error line before any work, the file untouched; in a folder an older demo wrote
    (its bench's folder, no manifest of its own) they are the demo's, replaced."""
    import json

    import sgtool.recorders.sim as sim

    out = tmp_path / "logs"
    out.mkdir()
    (out / "derived.mcap").write_text("mine")
    r = CliRunner().invoke(cli, ["demo", "-o", str(out), "--frames", "5"])
    assert r.exit_code == 2 and "derived.mcap" in r.output
    assert (out / "derived.mcap").read_text() == "mine"
    (out / "bench").mkdir()  # beside a bench's folder of its own: a user's files stay
    (out / "bench" / ".sgtool-output").write_text(json.dumps({"command": "bench",
                                                             "files": []}))
    r = CliRunner().invoke(cli, ["demo", "-o", str(out), "--frames", "5"])
    assert r.exit_code == 2 and (out / "derived.mcap").read_text() == "mine", r.output
    from sgtool.log.writer import LogWriter

    (out / "derived.mcap").unlink()  # a log of the demo house there: an older demo's folder
    with LogWriter(out / "derived.mcap", metadata={"house_id": "demo"}):
        pass
    (out / "bench" / ".sgtool-output").write_text(json.dumps({"command": "bench",
                                                             "files": []}))

    def stopped(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(sim, "record_house", stopped)
    r = CliRunner().invoke(cli, ["demo", "-o", str(out), "--frames", "5"])
    assert r.exit_code != 0 and not (out / "derived.mcap").exists(), r.output
