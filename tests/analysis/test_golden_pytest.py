"""The golden pytest plug-in as a lab uses it: `pytest --sgtool-golden DIR` in a subprocess
(one test per pinned log) and the checked-in example test with the fixture."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys

from support.paths import GOLDEN, REPO

from sgtool.analysis.golden_check import pin_logs
from sgtool.replayers.derived_log import ReplayOptions


def pytest_run(*args, cwd):
    env = {**os.environ, "HF_HUB_OFFLINE": "1", "TRANSFORMERS_OFFLINE": "1", "MPLBACKEND": "Agg"}
    done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                           "-p", "no:dash", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, env=env, timeout=600)
    return done.returncode, done.stdout + done.stderr


def lab_test(tmp_path, arguments):
    """run.mcap (house10-start) pinned into tmp_path/pins, and a lab's test_lab.py that
    calls ``sgtool_golden.check(ARGUMENTS)`` (HERE: its folder)."""
    shutil.copyfile(GOLDEN / "house10-start.mcap", tmp_path / "run.mcap")
    pin_logs([tmp_path / "run.mcap"], tmp_path / "pins", ReplayOptions(max_frames=20))
    (tmp_path / "test_lab.py").write_text(
        "from pathlib import Path\nHERE = Path(__file__).parent\n\n"
        "def test_run(sgtool_golden):\n"
        f"    sgtool_golden.check({arguments})\n")


def test_one_test_per_pinned_log_and_the_report_as_failure(tmp_path):
    logs = []
    for name in ("a", "b"):
        logs.append(tmp_path / f"{name}.mcap")
        shutil.copyfile(GOLDEN / "house10-start.mcap", logs[-1])
    folder = tmp_path / "pins"
    pin_logs(logs, folder, ReplayOptions(max_frames=20), copy=True)
    code, out = pytest_run("--sgtool-golden", folder, cwd=tmp_path)
    assert code == 0, out
    assert "2 passed" in out
    # b's pin holds the graphs of 8 cm voxels, but says 5 cm (a mapping change in effect):
    # its test fails with the layer-by-layer report
    pin_logs([folder / "b.mcap"], folder, ReplayOptions(max_frames=20, voxel_size=0.08))
    index = json.loads((folder / "expected.json").read_text())
    del index["cases"]["b"]["options"]["voxel_size"]
    (folder / "expected.json").write_text(json.dumps(index))
    code, out = pytest_run("--sgtool-golden", folder, "-rf", cwd=tmp_path)
    assert code == 1, out
    assert "1 failed, 1 passed" in out
    assert "b: changed" in out and "refresh 0 at" in out and "rooms:" in out
    assert "sgtool golden check --dir" in out  # how to accept it
    code, out = pytest_run("--sgtool-golden", folder, "--sgtool-golden-update", cwd=tmp_path)
    assert code == 0 and "2 passed" in out
    code, out = pytest_run("--sgtool-golden", folder, cwd=tmp_path)
    assert code == 0 and "2 passed" in out


def test_a_damaged_pin_folder_is_a_collection_error_naming_it(tmp_path):
    folder = tmp_path / "pins"
    folder.mkdir()
    (folder / "expected.json").write_text("{not json")
    code, out = pytest_run("--sgtool-golden", folder, cwd=tmp_path)
    assert code != 0
    assert f"{folder / 'expected.json'}: damaged pin file" in out
    (folder / "expected.json").write_text('{"format": 2, "cases": {}}')  # pins lost
    (tmp_path / "test_other.py").write_text("def test_ok():\n    pass\n")
    code, out = pytest_run("--sgtool-golden", folder, "test_other.py", cwd=tmp_path)
    assert code != 0 and "its index pins no log" in out, out


def test_the_example_test_runs_with_the_fixture(tmp_path, monkeypatch):
    """examples/test_golden_logs.py against a pin folder made here with the current code
    (SGTOOL_GOLDEN_DIR), so that a deliberate mapping change fails tests/golden once, not
    this test too."""
    pins = tmp_path / "pins"
    pin_logs([GOLDEN / "house6-tour.mcap", GOLDEN / "house10-start.mcap"], pins,
             ReplayOptions(every=10, classifier="containment"), copy=True)
    monkeypatch.setenv("SGTOOL_GOLDEN_DIR", str(pins))
    code, out = pytest_run(REPO / "examples" / "test_golden_logs.py", cwd=REPO)
    assert code == 0, out
    assert "2 passed" in out
    # its what-if check (a coarser map) is never re-pinned, even under update
    index = (pins / "expected.json").read_bytes()
    code, out = pytest_run(REPO / "examples" / "test_golden_logs.py", "--sgtool-golden-update",
                           cwd=REPO)
    assert code == 0 and "2 passed" in out, out
    assert (pins / "expected.json").read_bytes() == index


def test_the_fixture_refuses_another_log_of_the_pinned_name(tmp_path, monkeypatch):
    """Pins are named by file name: v2/run.mcap is not v1/run.mcap, pinned as "run", so the
    fixture fails instead of checking v1's log (and re-pins under --sgtool-golden-update)."""
    for v in ("v1", "v2"):
        (tmp_path / v).mkdir()
    shutil.copyfile(GOLDEN / "house10-start.mcap", tmp_path / "v1" / "run.mcap")
    shutil.copyfile(GOLDEN / "house6-tour.mcap", tmp_path / "v2" / "run.mcap")
    pin_logs([tmp_path / "v1" / "run.mcap"], tmp_path / "pins", ReplayOptions(max_frames=20))
    (tmp_path / "test_lab.py").write_text(
        "import os\nfrom pathlib import Path\nHERE = Path(__file__).parent\n\n"
        "def test_run(sgtool_golden):\n"
        "    sgtool_golden.check(HERE / os.environ['WHICH'] / 'run.mcap', HERE / 'pins')\n")
    monkeypatch.setenv("WHICH", "v1")
    code, out = pytest_run("test_lab.py", cwd=tmp_path)
    assert code == 0, out
    monkeypatch.setenv("WHICH", "v3")  # no such log: one line, no traceback
    code, out = pytest_run("test_lab.py", cwd=tmp_path)
    assert code == 1 and "v3/run.mcap: no such log" in out and "Traceback" not in out, out
    monkeypatch.setenv("WHICH", "v2")
    code, out = pytest_run("test_lab.py", cwd=tmp_path)
    assert code == 1 and "is not the log pinned as 'run'" in out, out
    code, out = pytest_run("test_lab.py", "--sgtool-golden-update", cwd=tmp_path)
    assert code == 0, out
    index = json.loads((tmp_path / "pins" / "expected.json").read_text())
    assert index["cases"]["run"]["log"] == "../v2/run.mcap"
    assert index["cases"]["run"]["options"] == {"max_frames": 20}  # kept as pinned
    # a --copy pin of the log given holds the same bytes: it is that log
    pin_logs([tmp_path / "v2" / "run.mcap"], tmp_path / "pins", ReplayOptions(max_frames=20),
             copy=True)
    code, out = pytest_run("test_lab.py", cwd=tmp_path)
    assert code == 0, out


def test_a_log_that_cannot_be_checked_fails_in_one_line_without_the_update_hint(tmp_path):
    """A pinned log deleted: its test fails with the one line naming it; --update cannot
    mend it, so it is not suggested."""
    log = tmp_path / "a.mcap"
    shutil.copyfile(GOLDEN / "house10-start.mcap", log)
    pin_logs([log], tmp_path / "pins", ReplayOptions(max_frames=20))
    log.unlink()
    code, out = pytest_run("--sgtool-golden", tmp_path / "pins", "-rf", cwd=tmp_path)
    assert code == 1 and "a.mcap" in out, out
    assert "--update" not in out and "Traceback" not in out, out


def test_the_fixture_re_pins_a_log_re_recorded_in_its_place_under_update(tmp_path):
    """run.mcap pinned, then recorded again at the same path: the check fails (not the
    pinned log); with --sgtool-golden-update the fixture re-pins it, and it passes after."""
    lab_test(tmp_path, "HERE / 'run.mcap', HERE / 'pins'")
    shutil.copyfile(GOLDEN / "house6-tour.mcap", tmp_path / "run.mcap")
    code, out = pytest_run("test_lab.py", cwd=tmp_path)
    assert code == 1, out
    code, out = pytest_run("test_lab.py", "--sgtool-golden-update", cwd=tmp_path)
    assert code == 0, out
    code, out = pytest_run("test_lab.py", cwd=tmp_path)
    assert code == 0, out


def test_updates_from_parallel_workers_keep_each_others_pins(tmp_path):
    """pytest -n 2 --sgtool-golden-update: each worker re-pins its log under the folder's
    lock and re-reads the index there, so neither drops the other's entry."""
    logs = []
    for name in ("a", "b"):
        logs.append(tmp_path / f"{name}.mcap")
        shutil.copyfile(GOLDEN / "house10-start.mcap", logs[-1])
    folder = tmp_path / "pins"
    pin_logs(logs, folder, ReplayOptions(max_frames=20, voxel_size=0.08), copy=True)
    index = json.loads((folder / "expected.json").read_text())
    for name in ("a", "b"):  # pins of 8 cm voxels that say 5 cm: both changed
        del index["cases"][name]["options"]["voxel_size"]
    (folder / "expected.json").write_text(json.dumps(index))
    code, out = pytest_run("--sgtool-golden", folder, "--sgtool-golden-update", "-n", "2",
                           cwd=tmp_path)
    assert code == 0 and "2 passed" in out, out
    code, out = pytest_run("--sgtool-golden", folder, cwd=tmp_path)
    assert code == 0 and "2 passed" in out, out


def test_fixture_mistakes_and_a_bad_tolerance_are_one_line(tmp_path):
    lab_test(tmp_path, "HERE / 'run.mcap', HERE / 'pins', voxelsize=0.08")
    code, out = pytest_run("test_lab.py", cwd=tmp_path)
    assert code == 1 and "sgtool_golden.check(" in out, out
    assert "no replay option 'voxelsize'; did you mean 'voxel_size'?" in out, out
    assert "Traceback" not in out and "golden_pytest.py" not in out, out
    code, out = pytest_run("--sgtool-golden", tmp_path / "pins", "--sgtool-golden-tolerance",
                           "nan", cwd=tmp_path)
    assert code == 4 and "'nan': give a finite number >= 0" in out, out
