"""The public Python API (``import sgtool``): light, complete, documented, typed.

``sgtool/__init__.py`` is a facade: each public name is imported from its module on first
use (PEP 562), by the ``from M import A as NAME`` lines of the stub ``__init__.pyi``, which
type checkers read. These tests keep the stub, ``__all__`` and the objects behind them in
step.
"""

from __future__ import annotations

import ast
import importlib
import importlib.metadata
import inspect
import json
import subprocess
import sys
import typing
from collections.abc import Callable
from pathlib import Path

import pytest

import sgtool

REPO = Path(__file__).resolve().parents[1]
INIT = REPO / "toolkit" / "__init__.py"

# What a user needs without the CLI (issue 27): each group must stay in __all__.
REQUIRED = {
    "logs": ("LogReader", "LogWriter", "EpisodeRecord", "ActionRecord", "Instances",
             "InstanceItem", "SceneGraphRecord", "LlmExchange"),
    "replay": ("replay", "ReplayOptions", "SceneGraphStream", "Refresh"),
    "scene graph": ("SceneGraph", "RoomNode", "RegionNode", "ObjectNode", "DoorNode",
                    "RobotState"),
    "planners": ("Planner", "Action", "Feedback", "make_planner", "planner_names"),
    "symbolic episode": ("run_one", "EpisodeResult"),
    "benchmark": ("BenchConfig", "run_benchmark", "BenchResult"),
    "closed loop": ("run_closed_loop", "ClosedLoopOptions"),
    "recording": ("record_house", "RecordOptions", "RecordReport"),
    "metrics": ("success_rate", "spl", "auc_e", "summarize"),
    "houses": ("HouseSpec", "load_house"),
    "errors": ("SgtoolError",),
}

# Public signatures whose annotation is a bare ``Any`` today, each with why it is left.
# A new one fails the test; fixing one needs no change here.
KNOWN_ANY = {
    # the registry: options differ per planner (and plug-ins take any keywords); they
    # are checked at run time against the planner's options dataclass
    "make_planner:options": "keyword options of the named planner, checked at run time",
    "LogReader.decode:return": "a protobuf message, a JSON dict or bytes, by the schema",
}


def _public() -> list[tuple[str, object]]:
    return [(name, getattr(sgtool, name)) for name in sgtool.__all__]


def test_import_sgtool_is_light() -> None:
    """A fresh interpreter: ``import sgtool`` loads the version module and nothing heavy."""
    code = ("import json, sys, sgtool; print(json.dumps(sorted(m for m in sys.modules if "
            "m.split('.')[0] in ('sgtool', 'numpy', 'torch', 'pybullet', 'open3d', 'mcap'))))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, cwd=REPO).stdout
    assert json.loads(out) == ["sgtool", "sgtool.version"]


def test_the_names_a_user_needs_are_public() -> None:
    missing = {group: [n for n in names if n not in sgtool.__all__]
               for group, names in REQUIRED.items()}
    assert not any(missing.values()), missing
    assert len(set(sgtool.__all__)) == len(sgtool.__all__)


def test_every_public_name_resolves_to_its_table_entry() -> None:
    table = sgtool._EXPORTS
    assert set(sgtool.__all__) == {*table, "planner_names"}
    for name, target in table.items():
        module, _, attribute = target.partition(":")
        assert getattr(sgtool, name) is getattr(importlib.import_module(module), attribute), name


def test_the_stub_declares_what_run_time_gives() -> None:
    """What mypy and IDEs see (the stub's imports and ``__all__``) is what run time gives."""
    tree = ast.parse((INIT.parent / "__init__.pyi").read_text())
    seen: dict[str, str] = {}
    declared: list[str] = []
    for node in tree.body:
        if isinstance(node, ast.ImportFrom) and node.module != "sgtool.version":
            assert node.module is not None
            for alias in node.names:
                assert alias.asname is not None, f"{alias.name}: write 'import A as NAME'"
                seen[alias.asname] = f"{node.module}:{alias.name}"
        elif isinstance(node, ast.Assign) and getattr(node.targets[0], "id", "") == "__all__":
            declared = list(ast.literal_eval(node.value))
    assert seen == sgtool._EXPORTS
    assert declared == sgtool.__all__  # static tools read the stub's list


def _own_doc(obj: object) -> str:
    """The object's own docstring: not a dataclass's generated signature, not inherited."""
    doc = obj.__doc__ if (inspect.isclass(obj) or callable(obj)) else None
    if inspect.isclass(obj) and doc and doc.startswith(f"{obj.__name__}("):
        return ""  # dataclasses write "Name(field: type, ...)" when there is no docstring
    return (doc or "").strip()


def test_every_public_name_is_documented() -> None:
    undocumented = [name for name, obj in _public() if not _own_doc(obj)]
    assert not undocumented, f"public names without a docstring: {undocumented}"
    foreign = [name for name, obj in _public()
               if not getattr(obj, "__module__", "").startswith("sgtool")]
    assert not foreign, f"public names defined outside sgtool: {foreign}"


def test_help_lists_every_public_name_by_topic() -> None:
    """help(sgtool)'s topic table names every public name and no other."""
    import re

    named = set(re.findall(r":(?:func|class):`([A-Za-z_]+)`", sgtool.__doc__ or ""))
    assert named == set(sgtool.__all__)


def test_docs_api_lists_every_public_name() -> None:
    """docs/api.md's "Every public name" section is what tools/api_reference.py prints
    (run it with --write after changing the public names or their first sentences)."""
    import importlib.util

    tool = Path(__file__).resolve().parents[1] / "tools" / "api_reference.py"
    spec = importlib.util.spec_from_file_location("api_reference", tool)
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    assert mod.section() in mod.DOC.read_text(encoding="utf-8")
    assert sorted(n for _, names in mod.topics() for n in names) == sorted(sgtool.__all__)
    # no first sentence cut inside a code span (a name wrapped after one of its dots)
    cut = [line for line in mod.section().splitlines() if line.count("`") % 2]
    assert cut == []
    import re

    spans = re.findall(r"`([^`\n]+)`", mod.section())
    assert [x for x in spans if ". " in x] == []  # no name wrapped after one of its dots


def test_dir_and_unknown_names() -> None:
    assert set(sgtool.__all__) <= set(dir(sgtool))
    assert "__version__" in dir(sgtool)
    assert not hasattr(sgtool, "no_such_name")
    with pytest.raises(AttributeError, match="no_such_name"):
        sgtool.no_such_name  # noqa: B018
    from sgtool import cli  # a submodule still imports through the facade

    assert cli.__name__ == "sgtool.cli"


def test_a_name_whose_extra_is_missing_is_one_line(monkeypatch: pytest.MonkeyPatch) -> None:
    """A public name whose module needs an extra that is not installed is one
    SgtoolError line naming the extra; a module missing for another reason (a bug) is the
    plain ModuleNotFoundError. Neither is cached in the package."""
    monkeypatch.setitem(sys.modules, "pybullet", None)  # as if sgtool[sim] were absent
    monkeypatch.setitem(sgtool._EXPORTS, "probe_sim", "pybullet:connect")
    monkeypatch.setitem(sgtool._EXPORTS, "probe_bug", "sgtool.no_such_module:thing")
    with pytest.raises(sgtool.SgtoolError) as missing:
        sgtool.probe_sim  # noqa: B018
    assert str(missing.value) == "sgtool.probe_sim needs PyBullet: pip install 'sgtool[sim]'"
    with pytest.raises(ModuleNotFoundError, match="sgtool.no_such_module"):
        sgtool.probe_bug  # noqa: B018
    assert "probe_sim" not in vars(sgtool) and "probe_bug" not in vars(sgtool)


def test_a_call_whose_extra_is_missing_is_one_line(monkeypatch: pytest.MonkeyPatch,
                                                    tmp_path) -> None:
    """Public functions whose stage imports an extra on call (the closed loop, the Rerun
    view, an RGB-D import) say which, in one SgtoolError line naming the function, before
    they write anything; their types and options still load (a core install's
    ``from sgtool import *`` works)."""
    for module in ("pybullet", "rerun", "cv2"):
        monkeypatch.setitem(sys.modules, module, None)
    house = sgtool.generate_house(0, rooms=(4, 4))
    _, episode = sgtool.pick_episode(house)
    calls = {
        "sgtool.run_closed_loop needs PyBullet": lambda: sgtool.run_closed_loop(
            house, episode, sgtool.make_planner("greedy"), tmp_path / "ep.mcap"),
        "sgtool.record_house needs PyBullet": lambda: sgtool.record_house(
            house, tmp_path / "rec.mcap", sgtool.RecordOptions(frames=3)),
        "sgtool.run_closed_loop_bench needs PyBullet": lambda: sgtool.run_closed_loop_bench(
            sgtool.ClosedLoopBenchConfig(planners=("random",), houses=1, episodes=1),
            tmp_path / "rb"),
        "sgtool.write_rerun needs Rerun": lambda: sgtool.write_rerun(
            tmp_path / "a.mcap", tmp_path / "a.rrd"),
        "sgtool.import_rgbd needs OpenCV": lambda: sgtool.import_rgbd(
            tmp_path, tmp_path / "b.mcap", sgtool.RgbdOptions()),
    }
    for said, call in calls.items():
        with pytest.raises(sgtool.SgtoolError) as e:
            call()
        assert str(e.value).startswith(said + ": pip install"), str(e.value)
    assert not list(tmp_path.iterdir())
    namespace: dict[str, object] = {}
    exec("from sgtool import *", namespace)  # noqa: S102
    assert "RgbdOptions" in namespace and "ImportReport" in namespace


def test_version_is_one_string() -> None:
    from sgtool.version import __version__

    assert sgtool.__version__ == __version__ == importlib.metadata.version("sgtool")


def test_python_dash_m_sgtool_is_the_command() -> None:
    """`python -m sgtool`, for an environment whose scripts lack `sgtool`."""
    out = subprocess.run([sys.executable, "-m", "sgtool", "--version"], capture_output=True,
                         text=True, timeout=120)
    assert out.returncode == 0 and sgtool.__version__ in out.stdout, out


def test_planner_names_build_planners() -> None:
    names = sgtool.planner_names()
    assert {"random", "greedy", "scout"} <= set(names)
    for name in ("random", "greedy"):
        planner = sgtool.make_planner(name)
        assert all(callable(getattr(planner, m)) for m in ("reset", "decide", "feedback"))
        assert planner.name == name


def _signatures(name: str, obj: object) -> list[tuple[str, Callable[..., object]]]:
    """(label, function) of a public function, or of a public class's own public methods
    and its constructor; an overloaded function is checked by its overloads."""
    out: list[tuple[str, Callable[..., object]]] = []
    if inspect.isclass(obj):
        for attr, raw in vars(obj).items():
            if attr.startswith("_") and attr != "__init__":
                continue
            f = raw.__func__ if isinstance(raw, (classmethod, staticmethod)) else raw
            f = f.fget if isinstance(f, property) else f
            # functions sgtool defines (a dataclass's generated __init__ too; not the
            # placeholder __init__ of typing.Protocol)
            if inspect.isfunction(f) and f.__module__.startswith("sgtool"):
                out.append((f"{name}.{attr}", f))
    elif inspect.isfunction(obj):
        out.append((name, obj))
    return [(label, g) for label, f in out for g in (typing.get_overloads(f) or [f])]


def _bare_any(f: Callable[..., object]) -> list[str]:
    """Parameters (and ``return``) annotated with exactly ``Any``."""
    return [k for k, v in getattr(f, "__annotations__", {}).items()
            if v is typing.Any or v in ("Any", "typing.Any")]


def test_no_bare_any_in_public_signatures() -> None:
    found = {f"{label}:{param}" for name, obj in _public()
             for label, f in _signatures(name, obj) for param in _bare_any(f)}
    new = sorted(found - set(KNOWN_ANY))
    assert not new, f"bare Any in public signatures: {new}"
    # the check sees what it should: a known case is found while it is still there
    checked = {label for name, obj in _public() for label, _ in _signatures(name, obj)}
    assert {"replay", "LogReader.records", "SceneGraph.objects_in", "run_one",
            "BenchConfig.__init__", "Planner.decide"} <= checked


def test_public_names_annotate_every_parameter() -> None:
    """Every parameter of the public functions and methods has an annotation (mypy checks
    that they are right)."""
    bare = []
    for name, obj in _public():
        for label, f in _signatures(name, obj):
            for p in inspect.signature(f).parameters.values():
                if p.name not in ("self", "cls") and p.annotation is inspect.Parameter.empty:
                    bare.append(f"{label}({p.name})")
    assert not bare, f"parameters without annotations: {bare}"


def test_a_log_round_trip_through_the_public_names(tmp_path: Path) -> None:
    """Write typed records with sgtool.LogWriter, read them back with sgtool.LogReader."""
    path = tmp_path / "run.mcap"
    opened = sgtool.EpisodeRecord(kind="search", status="started", query="mug", planner="me")
    act = sgtool.ActionRecord(skill="navigate", target="room:1", outcome="success",
                              travelled_m=1.23456789)
    with sgtool.LogWriter(path, seed=7) as log:
        log.write_record(opened, 0)
        log.write_record(act, 1_000_000_000)
    with sgtool.LogReader(path) as log:
        assert log.seed == 7
        assert list(log.records(sgtool.EpisodeRecord)) == [(0, opened)]
        [(t, back)] = list(log.records(sgtool.ActionRecord))
    assert t == 1_000_000_000 and back.target == "room:1"
    assert back.travelled_m == 1.2346  # distances are rounded to 0.1 mm by the record


def test_api_mistakes_are_one_line_errors(tmp_path) -> None:
    """What a notebook gets wrong most: one name where a list goes, a list where a tuple
    goes, a profile by name, options of another type, a planner returning nothing."""
    import sgtool

    cfg = sgtool.BenchConfig(planners="scout", houses=1, episodes=1, seeds=1, rooms=[4, 5])
    assert cfg.planners == ("scout",) and cfg.rooms == (4, 5)
    with pytest.raises(sgtool.SgtoolError, match=r"missing\.mcap: no such file"):
        sgtool.load_results(str(tmp_path / "missing.mcap"))  # one path, not its letters
    with pytest.raises(sgtool.SgtoolError, match=r"missing\.mcap: no such log"):
        sgtool.pin_logs(str(tmp_path / "missing.mcap"), tmp_path / "g")
    assert sgtool.ClosedLoopOptions(noise="strong").noise == sgtool.parse_noise("strong")
    with pytest.raises(sgtool.SgtoolError,
                       match="noise: a NoiseProfile or a profile's text, got int"):
        sgtool.ClosedLoopOptions(noise=3)  # type: ignore[arg-type]
    for bad, said in ((dict(max_steps=0), "--max-steps 0: must be >= 1"),
                      (dict(frames=0), "--frames 0: must be >= 1"),
                      (dict(voxel_size=5.0), "voxel size 5.0 m: must be 0.01..0.5"),
                      (dict(navigation="map"), "navigation 'map': one of live, house")):
        with pytest.raises(sgtool.SgtoolError) as e:  # when built, not when an episode runs
            sgtool.ClosedLoopOptions(**bad)  # type: ignore[arg-type]
        assert str(e.value) == said
    with pytest.raises(sgtool.SgtoolError, match="options: a ReplayOptions, got str"):
        sgtool.replay("any.mcap", options="every=5")  # type: ignore[arg-type]
    with pytest.raises(sgtool.SgtoolError, match=r"__main__.*workers=1"):
        sgtool.BenchConfig(planners=("__main__:Mine",), workers=2).check()

    class Nothing:
        name = "nothing"

        def reset(self, query: str, seed: int = 0) -> None: ...
        def decide(self, graph: object) -> None: ...
        def feedback(self, fb: object) -> None: ...

    with pytest.raises(sgtool.SgtoolError, match=r"explore 'walk' \(--explore\): one of"):
        sgtool.RecordOptions(explore="walk")
    with pytest.raises(sgtool.SgtoolError, match=r"frames 0 \(--frames\): must be >= 1"):
        sgtool.RecordOptions(frames=0)
    assert sgtool.RecordOptions(noise="mild").noise == sgtool.parse_noise("mild")
    for bad, said in ((dict(noise=None), "noise: a NoiseProfile, got NoneType"),
                      (dict(fps="4"), "fps '4' (--fps): must be a number 0.1..1000"),
                      (dict(frames=2.5), "frames=2.5: a whole number, or None"),
                      (dict(camera=None), "camera: a CameraConfig, got NoneType"),
                      (dict(compression="gzip"), "compression 'gzip' (--compression): one of "
                                                 "zstd, lz4, none")):
        with pytest.raises(sgtool.SgtoolError) as e:
            sgtool.RecordOptions(**bad)  # type: ignore[arg-type]
        assert str(e.value) == said
    with pytest.raises(sgtool.SgtoolError, match=r"out\.txt: the output is an MCAP log"):
        sgtool.record_house(sgtool.generate_house(3, rooms=(4, 4)), tmp_path / "out.txt")
    assert not list(tmp_path.iterdir())
    house = sgtool.generate_house(3, rooms=(4, 5))
    with pytest.raises(sgtool.SgtoolError, match=r"'nothing': decide\(\) returned None, not"):
        sgtool.run_one(house, Nothing(), sgtool.list_episodes(house)[0].query)
    with pytest.raises(sgtool.SgtoolError, match=r"query: a category name \(an episode number "
                                                 r"is index=\), got int"):
        sgtool.pick_episode(house, 2)  # type: ignore[arg-type]


def test_bench_config_shapes(tmp_path) -> None:
    """A set has no order (digests would vary with the hash seed); a path is a list of
    one; rooms are a pair."""
    import sgtool

    with pytest.raises(sgtool.SgtoolError, match="a set has no order"):
        sgtool.BenchConfig(planners={"scout", "random"})
    cfg = sgtool.BenchConfig(planners=("scout",), house_files=tmp_path / "h.json")
    assert cfg.house_files == (str(tmp_path / "h.json"),)
    for rooms in (5, (12, 16, 3)):
        with pytest.raises(sgtool.SgtoolError, match="rooms: give"):
            sgtool.BenchConfig(planners=("scout",), rooms=rooms)  # type: ignore[arg-type]


def test_results_a_user_sends_to_a_pool_pickle(tmp_path) -> None:
    """A cost model, an interrupted write and the embedding cache survive pickling (a
    pool's arguments and results): the cache's copy opens its own connection."""
    import pickle

    import numpy as np

    from sgtool.log.writer import InterruptedWrite
    from sgtool.results import EpisodeResult
    from sgtool.semantics.cache import EmbeddingCache

    dist, steps = sgtool.cost_models(step_m=0.5)
    r = EpisodeResult("greedy", 0, "h", 0, "mug", True, 3, 2.0, 1.0, n_open=1)
    assert pickle.loads(pickle.dumps(dist)).cost(r) == dist.cost(r)
    assert pickle.loads(pickle.dumps(steps)).cost(r) == 3.0
    back = pickle.loads(pickle.dumps(InterruptedWrite("kept x.partial", Path("x.partial"))))
    assert (str(back), back.partial) == ("kept x.partial", Path("x.partial"))
    cache = EmbeddingCache(tmp_path / "e.sqlite")
    cache.put_many("m", [("mug", np.ones(3, np.float32))])
    copy = pickle.loads(pickle.dumps(cache))
    assert list(copy.get_many("m", ["mug"])["mug"]) == [1.0, 1.0, 1.0]
