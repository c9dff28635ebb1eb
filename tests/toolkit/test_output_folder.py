"""sgtool.files.output_folder: a folder of outputs appears complete, refuses a non-empty
target without force, and force replaces only what sgtool wrote there."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest
from support.read_only import make_read_only

from sgtool.errors import SgtoolError
from sgtool.files import MANIFEST, OutputError, output_folder, read_manifest, remove_empty_folders


def _tree(folder: Path) -> dict[str, str]:
    """Every file under ``folder`` (relative path -> text)."""
    return {str(p.relative_to(folder)): p.read_text() for p in sorted(folder.rglob("*"))
            if p.is_file()}


def _write(folder: Path, **files: str) -> None:
    for name, text in files.items():
        (folder / name).write_text(text)


def test_a_new_folder_appears_complete_with_its_manifest(tmp_path: Path) -> None:
    out = tmp_path / "res"
    with output_folder(out, force=False, command="bench") as stage:
        assert stage.parent == tmp_path and stage.name.startswith(".res.")
        assert not out.exists()  # nothing at the target while the outputs are written
        _write(stage, **{"a.txt": "1", "b.txt": "2"})
    assert _tree(out) == {"a.txt": "1", "b.txt": "2", MANIFEST: (out / MANIFEST).read_text()}
    assert read_manifest(out) == ("bench", frozenset({"a.txt", "b.txt"}))
    assert os.listdir(tmp_path) == ["res"]  # no temporary folder left
    assert (out.stat().st_mode & 0o777) == (0o777 & ~_umask())


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def test_an_empty_folder_is_filled_without_force(tmp_path: Path) -> None:
    out = tmp_path / "res"
    out.mkdir()
    with output_folder(out, force=False) as stage:
        _write(stage, **{"a.txt": "1"})
    assert (out / "a.txt").read_text() == "1"


def test_a_non_empty_folder_is_refused_in_one_line(tmp_path: Path) -> None:
    out = tmp_path / "res"
    out.mkdir()
    _write(out, **{"summary.md": "mine"})
    with pytest.raises(SgtoolError) as e, output_folder(out, force=False, option="-o") as _:
        raise AssertionError("the block must not run")
    assert "\n" not in str(e.value) and "--force" in str(e.value) and "-o" in str(e.value)
    assert _tree(out) == {"summary.md": "mine"}
    assert os.listdir(tmp_path) == ["res"]


def test_a_folder_another_run_filled_meanwhile_is_left_alone(tmp_path: Path) -> None:
    """Two runs started on one new -o: the first to finish moved in, the second replaced
    its outputs with exit 0 (the folder was checked only at the start). The second's
    outputs go beside it now, and it says so."""
    target = tmp_path / "out"
    with pytest.raises(SgtoolError, match=r"-o .*out: another run wrote into it while this "
                       r"one ran; this run's outputs are in .*out\.1 instead"):
        with output_folder(target, force=False, command="sgtool bench") as out:
            (out / "summary.md").write_text("mine")
            target.mkdir()
            (target / "summary.md").write_text("theirs")
    assert (target / "summary.md").read_text() == "theirs"
    assert (tmp_path / "out.1" / "summary.md").read_text() == "mine"
    assert read_manifest(tmp_path / "out.1")[0] == "sgtool bench"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out", "out.1"]


def test_force_replaces_what_sgtool_wrote_and_keeps_the_users_files(tmp_path: Path) -> None:
    out = tmp_path / "res"
    with output_folder(out, force=False, command="c") as stage:
        _write(stage, **{"old.txt": "stale", "same.txt": "v1"})
        (stage / "logs").mkdir()
        _write(stage / "logs", **{"x.log": "v1"})
    _write(out, **{"notes.md": "mine"})  # the user's, unlisted
    with output_folder(out, force=True, command="c") as stage:
        _write(stage, **{"same.txt": "v2", "new.txt": "v2"})
    files = _tree(out)
    del files[MANIFEST]
    # old.txt and logs/ were sgtool's and are not in the new outputs: gone
    assert files == {"same.txt": "v2", "new.txt": "v2", "notes.md": "mine"}
    assert read_manifest(out) == ("c", frozenset({"same.txt", "new.txt"}))
    assert sorted(os.listdir(tmp_path)) == ["res"]
    assert not [n for n in os.listdir(out) if n.startswith(".sgtool-previous")]


def test_force_without_a_manifest_replaces_nothing_named_as_an_output(tmp_path: Path) -> None:
    """No manifest: entries named as the outputs may be a user's (a review lost a `logs/`
    folder of its own data to `run-bench --force`): refused, naming them; other files
    alone are no obstacle."""
    out = tmp_path / "res"
    out.mkdir()
    _write(out, **{"episodes.jsonl": "old", "efficiency_x.png": "old", "mine.txt": "mine"})
    known = ("episodes.jsonl", "efficiency_*.png")
    with pytest.raises(SgtoolError, match=r"holds efficiency_x.png, episodes.jsonl, named as "
                       r"this command's outputs but not listed as sgtool's"):
        with output_folder(out, force=True, known=known) as s:
            _write(s, **{"episodes.jsonl": "new"})
    assert _tree(out) == {"episodes.jsonl": "old", "efficiency_x.png": "old", "mine.txt": "mine"}
    (out / "episodes.jsonl").unlink()
    (out / "efficiency_x.png").unlink()
    with output_folder(out, force=True, known=known) as s:
        _write(s, **{"episodes.jsonl": "new"})
    files = _tree(out)
    del files[MANIFEST]
    assert files == {"episodes.jsonl": "new", "mine.txt": "mine"}


def test_a_manifest_naming_paths_outside_the_folder_removes_nothing_there(
        tmp_path: Path) -> None:
    out = tmp_path / "res"
    out.mkdir()
    (tmp_path / "precious").write_text("keep")
    (out / MANIFEST).write_text(json.dumps({"command": "c", "files": ["../precious", ".."]}))
    with output_folder(out, force=True, command="c") as stage:
        _write(stage, **{"a.txt": "1"})
    assert (tmp_path / "precious").read_text() == "keep"
    assert (out / "a.txt").read_text() == "1"


@pytest.mark.parametrize("error", [KeyboardInterrupt, RuntimeError])
@pytest.mark.parametrize("force", [False, True])
def test_an_interrupted_run_leaves_the_earlier_state(tmp_path: Path, error: type,
                                                     force: bool) -> None:
    out = tmp_path / "res"
    if force:
        with output_folder(out, force=False, command="c") as stage:
            _write(stage, **{"a.txt": "old"})
        _write(out, **{"mine.txt": "mine"})
    before = _tree(out) if out.exists() else None
    with pytest.raises(error) as e, output_folder(out, force=force, command="c") as stage:
        _write(stage, **{"a.txt": "new", "b.txt": "new"})
        raise error()
    assert (_tree(out) if out.exists() else None) == before
    assert os.listdir(tmp_path) == (["res"] if force else [])
    if error is KeyboardInterrupt:  # what the CLI prints: true
        assert "is as it was" in e.value.note  # type: ignore[attr-defined]


def test_an_interrupt_while_moving_in_puts_everything_back(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    out = tmp_path / "res"
    with output_folder(out, force=False, command="c") as stage:
        _write(stage, **{"a.txt": "old", "b.txt": "old"})
    _write(out, **{"mine.txt": "mine"})
    before = _tree(out)
    real = os.replace
    calls = []

    def replace(src: object, dst: object) -> None:
        calls.append(src)
        if len(calls) == 5:  # after the old entries moved aside, amid the new ones
            raise KeyboardInterrupt
        real(src, dst)  # type: ignore[arg-type]

    monkeypatch.setattr(os, "replace", replace)
    with pytest.raises(KeyboardInterrupt), output_folder(out, force=True, command="c") as s:
        _write(s, **{"a.txt": "new", "b.txt": "new", "c.txt": "new"})
    monkeypatch.setattr(os, "replace", real)
    assert len(calls) > 5  # the roll-back ran
    assert _tree(out) == before
    assert os.listdir(tmp_path) == ["res"]
    assert sorted(os.listdir(out)) == sorted(before)


def test_a_read_only_parent_is_one_line(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    parent = tmp_path / "ro"
    parent.mkdir()
    make_read_only(parent, monkeypatch)
    try:
        with pytest.raises(OutputError) as e, output_folder(parent / "res", force=False):
            raise AssertionError("the block must not run")
    finally:
        parent.chmod(0o755)
    assert "\n" not in str(e.value) and "Permission denied" in str(e.value)
    assert os.listdir(parent) == []


def test_a_file_is_not_a_folder(tmp_path: Path) -> None:
    (tmp_path / "res").write_text("x")
    with pytest.raises(SgtoolError, match="not a folder"), output_folder(tmp_path / "res",
                                                                          force=True):
        raise AssertionError("the block must not run")


def test_resume_writes_in_place_into_a_folder_of_its_own(tmp_path: Path) -> None:
    out = tmp_path / "rb"
    with pytest.raises(KeyboardInterrupt), output_folder(out, force=False, command="run-bench",
                                                         resume=True) as folder:
        assert folder == out
        _write(folder, **{"ep-0.log": "done"})
        raise KeyboardInterrupt  # the complete files stay, for the next run
    assert read_manifest(out) == ("run-bench", frozenset({"ep-0.log"}))
    with output_folder(out, force=False, command="run-bench", resume=True) as folder:
        assert folder == out and (folder / "ep-0.log").read_text() == "done"
        _write(folder, **{"ep-1.log": "done"})
    assert read_manifest(out) == ("run-bench", frozenset({"ep-0.log", "ep-1.log"}))
    # another command's folder is refused; force starts afresh beside it
    with pytest.raises(SgtoolError, match="--force"), \
            output_folder(out, force=False, command="bench", resume=True):
        raise AssertionError("the block must not run")
    _write(out, **{"mine.txt": "mine"})
    with output_folder(out, force=True, command="run-bench", resume=True) as folder:
        assert folder != out
        _write(folder, **{"ep-0.log": "again"})
    files = _tree(out)
    del files[MANIFEST]
    assert files == {"ep-0.log": "again", "mine.txt": "mine"}


def test_resume_takes_a_folder_of_known_names_without_a_manifest(tmp_path: Path) -> None:
    out = tmp_path / "rb"
    (out / "logs").mkdir(parents=True)
    with output_folder(out, force=False, command="run-bench", known=("logs",),
                       resume=True) as folder:
        assert folder == out
    assert read_manifest(out) == ("run-bench", frozenset({"logs"}))


def test_the_current_folder_is_built_beside_it(tmp_path: Path,
                                               monkeypatch: pytest.MonkeyPatch) -> None:
    out = tmp_path / "res"
    out.mkdir()
    _write(out, **{"mine.txt": "mine"})
    monkeypatch.chdir(out)
    with output_folder(".", force=True) as stage:
        assert stage.parent == tmp_path
        _write(stage, **{"a.txt": "1"})
    assert sorted(os.listdir(out)) == [MANIFEST, "a.txt", "mine.txt"]
    assert os.listdir(tmp_path) == ["res"]


def test_deferred_interrupts_hold_ctrl_c_until_the_block_ends() -> None:
    """A Ctrl-C inside the block lets the block finish (every file of a commit written),
    then raises as usual; without one nothing is raised, and the handlers are restored."""
    import os
    import signal

    from sgtool.files import deferred_interrupts

    before = signal.getsignal(signal.SIGINT)
    done = []
    with pytest.raises(KeyboardInterrupt):
        with deferred_interrupts():
            os.kill(os.getpid(), signal.SIGINT)
            done.append("after the signal")
    assert done == ["after the signal"]
    with deferred_interrupts():
        done.append("quiet")
    assert signal.getsignal(signal.SIGINT) is before


def test_ctrl_c_as_the_outputs_go_in_says_they_did(tmp_path: Path,
                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    """A Ctrl-C while --force moves the new outputs in (here: as the previous ones are
    deleted) lets the moves finish, then interrupts saying the target holds this run's
    complete outputs; it said the target was as it was, and left the previous outputs in
    a hidden folder there."""
    import shutil
    import signal

    import sgtool.files

    out = tmp_path / "res"
    with output_folder(out, force=False, command="bench") as stage:
        _write(stage, **{"a.txt": "old", "b.txt": "old"})
    rmtree = shutil.rmtree

    def interrupted(path, *a, **k):  # type: ignore[no-untyped-def]
        if Path(path).name.startswith(".sgtool-previous."):
            signal.raise_signal(signal.SIGINT)
        rmtree(path, *a, **k)

    monkeypatch.setattr(sgtool.files.shutil, "rmtree", interrupted)
    with pytest.raises(KeyboardInterrupt) as e:
        with output_folder(out, force=True, command="bench") as stage:
            _write(stage, **{"a.txt": "new"})
    assert "holds this run's complete outputs" in e.value.note  # type: ignore[attr-defined]
    assert sorted(os.listdir(out)) == [MANIFEST, "a.txt"]
    assert (out / "a.txt").read_text() == "new"
    assert os.listdir(tmp_path) == ["res"]


def test_deferred_sigterm_with_the_default_handler_still_ends_the_process(tmp_path) -> None:
    """A library caller keeps Python's default SIGTERM action: a SIGTERM inside the block
    ends the process when the block ends (it was dropped)."""
    import subprocess
    import sys

    script = tmp_path / "term.py"
    script.write_text(
        "import os, signal\n"
        "from sgtool.files import deferred_interrupts\n"
        "with deferred_interrupts():\n"
        "    os.kill(os.getpid(), signal.SIGTERM)\n"
        "    print('block done', flush=True)\n"
        "print('after the block')\n")
    run = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                         timeout=60)
    assert run.returncode == -15 and run.stdout == "block done\n", (run.returncode, run.stdout)


def test_remove_empty_folders_keeps_every_file(tmp_path: Path) -> None:
    for d in ("run/logs/a/house-0", "run/logs/b/house-1/deep", "run/keep"):
        (tmp_path / d).mkdir(parents=True)
    (tmp_path / "run/keep/ep.mcap").write_bytes(b"x")
    remove_empty_folders(tmp_path / "run")
    assert sorted(p.relative_to(tmp_path).as_posix() for p in tmp_path.rglob("*")) == [
        "run", "run/keep", "run/keep/ep.mcap"]
    (tmp_path / "run/keep/ep.mcap").unlink()
    remove_empty_folders(tmp_path / "run")
    remove_empty_folders(tmp_path / "missing")  # nothing there: nothing to do
    assert list(tmp_path.iterdir()) == []


def test_an_input_folder_that_is_the_output_folder_is_refused(tmp_path: Path) -> None:
    from sgtool.errors import SgtoolError
    from sgtool.files import refuse_input_folder

    run = tmp_path / "run"
    run.mkdir()
    (run / "h.json").write_text("{}")
    refuse_input_folder(run, [run / "h.json"])  # a file kept in the run folder: fine
    refuse_input_folder(run / "out", [run])  # outputs in a folder under the inputs: fine
    with pytest.raises(SgtoolError, match="is the input folder"):
        refuse_input_folder(tmp_path / "run" / ".." / "run", [run])


def test_a_write_error_in_the_staging_folder_names_the_target(tmp_path: Path) -> None:
    """The hidden staging folder is gone when the error is shown; the message names the
    file as the user will look for it."""
    import errno

    from sgtool.files import output_error

    out = tmp_path / "run"
    with pytest.raises(OutputError) as e, output_folder(out, force=False) as stage:
        raise output_error(OSError(errno.ENOSPC, "No space left on device"),
                           stage / "summary.md")
    assert str(e.value) == (f"cannot write {out}/summary.md: No space left on device "
                            "(nothing was written)")
    with pytest.raises(OSError) as raw, output_folder(out, force=False) as stage:
        raise OSError(errno.EIO, "Input/output error", str(stage / "a.png"))
    assert raw.value.filename == str(out / "a.png")
    with pytest.raises(OSError) as full, output_folder(out, force=False):
        raise OSError(errno.ENOSPC, "No space left on device")  # a buffered write's
    assert full.value.filename == str(out)
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_force_of_another_command_leaves_a_folder_s_results(tmp_path: Path) -> None:
    """`bench --force` into a run-bench folder deleted its episode logs: the refusal names
    the folder's command, and --force of another command is refused too."""
    out = tmp_path / "rb"
    with output_folder(out, force=False, command="run-bench", resume=True) as folder:
        _write(folder, **{"ep-0.log": "done"})
    for force in (False, True):
        with pytest.raises(SgtoolError, match="a `sgtool run-bench` folder"), \
                output_folder(out, force=force, command="bench"):
            raise AssertionError("the block must not run")
    assert (out / "ep-0.log").read_text() == "done"
    with output_folder(out, force=True, command="run-bench") as folder:  # its own: replaced
        _write(folder, **{"ep-0.log": "again"})
    assert (out / "ep-0.log").read_text() == "again"
    pins = tmp_path / "pins"  # a command named with its program is named once
    with output_folder(pins, force=False, command="sgtool golden") as folder:
        _write(folder, **{"expected.json": "{}"})
    with pytest.raises(SgtoolError, match="^-o .*pins: a `sgtool golden` folder; --force of "
                       "`sgtool bench`"), output_folder(pins, force=True, command="bench"):
        raise AssertionError("the block must not run")
