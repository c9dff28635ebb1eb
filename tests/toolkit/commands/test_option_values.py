"""Option values a user can get wrong are one line with exit 2, before any work and with no
output: planner options (-O) of the wrong type, out of range or for a planner not run,
AUC-E budgets, worker counts, damaged priors, distill options of another source; and a
message with NAME=VALUE in it is not taken for a secret."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

from sgtool.cli import cli
from sgtool.semantics.priors import WEIGHTS_DIR

BENCH = ["bench", "--houses", "1", "--episodes", "2", "--seeds", "1", "--rooms", "4-5"]


def _one_line_error(args: list[str], tmp_path: Path, expect: str) -> None:
    out = tmp_path / "out"
    r = CliRunner().invoke(cli, [*args, "-o", str(out)])
    lines = [ln for ln in r.output.splitlines() if ln.strip()]
    assert r.exit_code == 2, r.output
    assert len(lines) == 1 and expect in lines[0], r.output
    assert not out.exists() or not any(out.rglob("*.*"))


@pytest.mark.parametrize(("option", "expect"), [
    ("scout.delta=abc", "planner 'scout': option delta=abc: must be a number"),
    ("scout.delta=nan", "planner 'scout': option delta=nan: must be a finite number >= 0"),
    ("scout.delta=-5", "planner 'scout': option delta=-5: must be >= 0"),
    ("scout.default_room=1.5", "planner 'scout': option default_room=1.5: must be 0..1"),
    ("random.max_failures=abc", "planner 'random': option max_failures=abc: must be an "
     "integer"),
    ("random.max_failures=0", "planner 'random': option max_failures=0: must be >= 1"),
    ("random.max_failures=2.5", "option max_failures=2.5: must be an integer"),
    ("scout.encoder=foo", "planner 'scout': option encoder=foo: a Python object, set from "
     "Python only"),
    ("scout.dleta=0.2", "planner 'scout' does not take option(s): dleta; did you mean "
     "'delta'?"),
    ("random.timed=maybe", "planner 'random': option timed=maybe: must be true or false"),
    ("scout.weights_dir=/nonexistent", "relational model weights not found: /nonexistent"),
    ("sout.delta=0.2", "'sout' is no planner (those run: random, scout)"),
])
def test_bad_planner_options(tmp_path: Path, option: str, expect: str) -> None:
    _one_line_error([*BENCH, "--planners", "random,scout", "-O", option], tmp_path, expect)


@pytest.mark.parametrize(("args", "expect"), [
    (["--distance-budget", "0"], "Invalid value for '--distance-budget'"),
    (["--step-budget", "-5"], "Invalid value for '--step-budget'"),
    (["--distance-budget", "nan"], "'--distance-budget': 'nan' is not a finite number"),
    (["--step-budget", "inf"], "'--step-budget': 'inf' is not a finite number"),
    (["-w", "0"], "Invalid value for '--workers'"),
])
def test_bad_bench_values(tmp_path: Path, args: list[str], expect: str) -> None:
    _one_line_error([*BENCH, "--planners", "random", *args], tmp_path, expect)


def test_an_option_of_a_planner_not_run_is_a_note(tmp_path: Path) -> None:
    from sgtool.commands.options import planner_options

    assert planner_options(("greedy.x=1",), ("random",)) == {"greedy": {"x": 1}}


def test_priors_of_a_planners_own_are_noted_and_fingerprinted(tmp_path: Path) -> None:
    """-O scout.weights_dir=DIR loads other priors than the bench's --priors: the tables'
    priors id and seen/unseen split are --priors', so a note says so; the id covers a
    folder's room blend (its episodes differ with it)."""
    from sgtool.analysis.bench_priors import priors_fingerprint
    from sgtool.semantics.priors import weights_folder

    r = CliRunner().invoke(cli, [*BENCH, "--planners", "scout", "-O",
                                 "scout.weights_dir=blend", "--no-progress", "-o",
                                 str(tmp_path / "b")])
    assert r.exit_code == 0, r.output
    assert ("sgtool: note: -O scout.weights_dir=blend: scout loads those priors, but the "
            "summary's priors id and seen/unseen split are those of the shipped priors"
            ) in r.stderr
    bare = tmp_path / "bare"
    shutil.copytree(weights_folder("blend"), bare)
    for name in ("room_blend.json", "room_blend_vectors.npy"):
        (bare / name).unlink()
    assert priors_fingerprint("blend") != priors_fingerprint(bare)
    assert priors_fingerprint(None) == priors_fingerprint(WEIGHTS_DIR)


def test_an_option_of_a_name_close_to_a_planner_run_is_an_error() -> None:
    """``lab:Labplanner.k`` with ``lab:LabPlanner`` run is a typo, not another planner."""
    from sgtool.commands.options import planner_options
    from sgtool.errors import SgtoolError

    with pytest.raises(SgtoolError, match=r"'lab:Labplanner' is not run; did you mean "
                                          r"'lab:LabPlanner'\?"):
        planner_options(("lab:Labplanner.k=2",), ("lab:LabPlanner",))
    assert planner_options(("other:Planner.k=2",), ("lab:LabPlanner",)) == \
        {"other:Planner": {"k": 2}}  # another planner not run: a note, as before


def test_run_bench_workers_must_be_positive(tmp_path: Path) -> None:
    _one_line_error(["run-bench", "--planners", "random", "--houses", "1", "--episodes", "1",
                     "-w", "-1"], tmp_path, "Invalid value for '--workers'")


def test_damaged_priors_are_one_line(tmp_path: Path) -> None:
    pri = tmp_path / "pri"
    shutil.copytree(WEIGHTS_DIR, pri, ignore=shutil.ignore_patterns("__*"))
    (pri / "containment.safetensors").write_bytes(b"\xff" * 64)
    expect = f"{pri / 'containment.safetensors'}: not readable relational model weights"
    _one_line_error([*BENCH, "--planners", "scout", "--priors", str(pri)], tmp_path, expect)
    r = CliRunner().invoke(cli, ["distill", "--report", "--weights", str(pri)])
    assert r.exit_code == 2 and expect in r.output
    (pri / "metadata.json").write_text("not json")
    r = CliRunner().invoke(cli, ["distill", "--report", "--weights", str(pri)])
    assert r.exit_code == 2 and "metadata.json: not the metadata `sgtool distill` writes" \
        in r.output


def test_distill_llm_slice_needs_the_llm_source(tmp_path: Path) -> None:
    r = CliRunner().invoke(cli, ["distill", "--out", str(tmp_path / "w"), "--llm-slice",
                                 "a,b,c"])
    assert r.exit_code == 2 and "--llm-slice is for --source llm" in r.output
    # the other LLM options did nothing without it, and said nothing
    for args in (["--out", str(tmp_path / "w"), "--llm-runs", "5"], ["--report", "--llm-runs",
                                                                      "3"]):
        r = CliRunner().invoke(cli, ["distill", *args])
        assert r.exit_code == 2 and "--llm-runs: for --source llm" in r.output, r.output
    assert not (tmp_path / "w").exists()
    assert not (tmp_path / "w").exists()


def test_noise_message_shows_name_value_unredacted() -> None:
    from sgtool.errors import SgtoolError
    from sgtool.recorders.sim.noise import parse_noise
    from sgtool.redact import redact_text

    with pytest.raises(SgtoolError) as e:
        parse_noise("bogus")
    assert "NAME=VALUE overrides" in redact_text(str(e.value))


@pytest.mark.parametrize("args, flag", [
    (["record", "--speed", "nan", "--frames", "5"], "--speed"),
    (["record", "--speed", "inf", "--frames", "5"], "--speed"),
    (["record", "--noise", "mild", "--noise-seed", "-1", "--frames", "5"], "--noise-seed"),
    (["scenes", "episodes", "h.json", "--reach", "nan"], "--reach"),
    (["scenes", "episodes", "h.json", "--reach", "0.2"], "--reach"),  # nothing reachable
    (["scenes", "stats", "-n", "99999999999999999999"], "-n"),  # (an OverflowError)
    (["diff", "a.mcap", "b.mcap", "--tolerance", "nan"], "--tolerance"),
    (["distill", "--holdout", "nan"], "--holdout"),
    (["distill", "--seed", "-1"], "--seed"),
])
def test_non_finite_and_negative_values_are_usage_errors(tmp_path: Path, args: list[str],
                                                         flag: str) -> None:
    """A NaN passes every bound check (--tolerance nan would mean no tolerance): every
    float option of the commands refuses nan and inf, a seed refuses negatives."""
    r = CliRunner().invoke(cli, [*args, "-o", str(tmp_path / "out")] if args[0] == "record"
                           else args)
    assert r.exit_code == 2, r.output
    assert f"'{flag}'" in r.output and "Traceback" not in r.output
    assert not (tmp_path / "out").exists()


def test_an_option_reaches_a_planner_spelled_in_another_case() -> None:
    """`--planners SCOUT -O SCOUT.delta=0.9` sets scout's delta (the run lower-cases a
    built-in name; the option was a note about a planner not run, and scout ran with its
    defaults), and a bad value in any spelling is refused."""
    from sgtool.commands.options import planner_options
    from sgtool.errors import SgtoolError

    assert planner_options(("SCOUT.delta=0.9",), ("scout",)) == {"scout": {"delta": 0.9}}
    assert planner_options(("scout.delta=0.9",), ("Scout",)) == {"scout": {"delta": 0.9}}
    with pytest.raises(SgtoolError, match="must be a number"):
        planner_options(("Scout.delta=abc",), ("scout",))


@pytest.mark.parametrize("args, says", [
    (["study", "noise", "--fps", "1e9", "--houses", "1"], "--fps 1000000000.0: must be 0.1..1000"),
    (["distill", "--report", "--out", "w1"], "--report trains nothing"),
    (["distill", "--report", "--seed", "5"], "--report trains nothing: --seed would do"),
    (["distill", "--weights", ".", "--out", "w1"], "--weights . is the folder --report reads"),
])
def test_options_refused_before_any_work(tmp_path: Path, args: list[str], says: str) -> None:
    """A frame rate no simulation runs at (it was retried per recording first), --out with
    --report (it was ignored): one line at once, nothing written."""
    r = CliRunner().invoke(cli, [*args, "-o", str(tmp_path / "out")] if args[0] == "study"
                           else args)
    assert r.exit_code == 2, r.output
    assert says in r.output and "Traceback" not in r.output
    assert not (tmp_path / "out").exists() and not Path("w1").exists()


def test_run_help_names_no_option_it_lacks() -> None:
    """`run` has no --executor: its planner help does not send plug-ins to Ray."""
    r = CliRunner().invoke(cli, ["run", "-h"])
    assert r.exit_code == 0 and "--executor" not in r.output


def test_distill_report_refuses_weights_it_cannot_score(tmp_path: Path) -> None:
    """Weights of another layer size (a traceback before), metadata without its held-out
    list (a KeyError traceback): one line each, naming the file."""
    import json
    import shutil

    import numpy as np

    from sgtool.semantics.mlp import save_mlp
    from sgtool.semantics.priors import WEIGHTS_DIR

    meta = tmp_path / "meta"
    shutil.copytree(WEIGHTS_DIR, meta)
    doc = json.loads((meta / "metadata.json").read_text())
    del doc["heldout_queries"]
    (meta / "metadata.json").write_text(json.dumps(doc))
    r = CliRunner().invoke(cli, ["distill", "--report", "--weights", str(meta)])
    assert r.exit_code == 2 and "not the metadata `sgtool distill` writes" in r.output
    assert "Traceback" not in r.output
    wide = tmp_path / "wide"
    shutil.copytree(WEIGHTS_DIR, wide)
    sizes = [1024, 512, 256, 128, 1]
    save_mlp(wide / "containment.safetensors",
             [np.zeros((b, a), np.float32) for a, b in zip(sizes[:-1], sizes[1:], strict=True)],
             [np.zeros(b, np.float32) for b in sizes[1:]], {"relation": "containment"})
    r = CliRunner().invoke(cli, ["distill", "--report", "--weights", str(wide)])
    assert r.exit_code == 2 and "containment.safetensors: containment: layer sizes" in r.output
    assert "Traceback" not in r.output


def test_a_report_checks_a_built_in_planners_options() -> None:
    """A report (``typed=False``: plug-ins need not import) still asks a built-in planner:
    a misspelt key is the planner's own error (it was "run with other settings"), a value
    is converted as the run converted it; a plug-in's value is read as text would be."""
    from sgtool.commands.options import planner_options
    from sgtool.errors import SgtoolError

    with pytest.raises(SgtoolError, match="does not take option"):
        planner_options(("scout.dleta=0.2",), ("scout",), typed=False)
    assert planner_options(("scout.delta=1",), ("scout",), typed=False) == \
        {"scout": {"delta": 1.0}}
    got = planner_options(("nolab:Missing.k=2",), ("nolab:Missing",), typed=False)
    assert got == {"nolab:Missing": {"k": 2}}


def test_record_and_run_generate_a_house_of_either_preset(tmp_path: Path) -> None:
    """`record --seed N --preset symsearch` records the house `scenes generate` writes with
    those options (it needed a house file); --preset without --seed is one line."""
    pytest.importorskip("pybullet")
    from sgtool.datasets.generator import generate_house
    from sgtool.log import LogReader

    out = tmp_path / "r.mcap"
    r = CliRunner().invoke(cli, ["record", "--seed", "9150", "--rooms", "4-4", "--preset",
                                 "symsearch", "--frames", "3", "--resolution", "96x72",
                                 "--quiet", "-o", str(out)])
    assert r.exit_code == 0, r.output
    with LogReader(out) as log:
        house = log.house_spec()
    assert house == generate_house(9150, rooms=(4, 4), preset="symsearch")
    assert house != generate_house(9150, rooms=(4, 4))
    for command in (["record"], ["run", "--planner", "greedy"]):
        r = CliRunner().invoke(cli, [*command, "--preset", "symsearch", "-o",
                                     str(tmp_path / "x.mcap")])
        assert r.exit_code == 2 and "--preset symsearch: for a house generated with --seed" \
            in r.output, r.output
    assert not (tmp_path / "x.mcap").exists()
