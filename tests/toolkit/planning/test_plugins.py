"""Plug-in planners: ``module:Name`` imported from sys.path, names registered through the
entry-point group ``sgtool.planners`` (a distribution's ``entry_points.txt`` on sys.path),
options passed as keyword arguments (checked against an ``Options`` dataclass when there
is one), and every failure one line naming the plug-in."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest

from sgtool.errors import SgtoolError
from sgtool.planning.option_fields import PlannerOptionError
from sgtool.planning.plugins import GROUP, PluginError, entry_points, file_name
from sgtool.planning.registry import (
    UnknownPlannerError,
    check_planner_name,
    describe_planners,
    make_planner,
    parse_option,
)

PLUGIN = textwrap.dedent('''
    from dataclasses import dataclass, field
    from typing import Any

    from sgtool.planning.option_fields import option
    from sgtool.planning.planners import GreedyPlanner


    class MyPlanner(GreedyPlanner):
        """Greedy under another name, with a knob."""

        def __init__(self, k=1, label="x"):
            super().__init__()
            self.name = "mine"
            self.k, self.label = k, label


    class Annotated(GreedyPlanner):
        def __init__(self, penalty: float = 1.0, weights: tuple[float, float] = (1.0, 0.0),
                     verbose: bool = False, tag: str = "a", mode: Any = 3):
            super().__init__()
            self.penalty, self.weights, self.verbose, self.tag = penalty, weights, verbose, tag
            self.mode = mode


    class Typed(GreedyPlanner):
        @dataclass(frozen=True)
        class Options:
            k: int = field(default=1, metadata=option("a knob", "int", lo=0))

        def __init__(self, k=1):
            super().__init__()
            self.k = k


    class Plain(GreedyPlanner):
        @dataclass
        class Options:  # a lab's own config class, no sgtool metadata
            radius: float = 2.0
            steps: int = 3
            greedy: bool = False
            tag: str = "a"

        def __init__(self, radius=2.0, steps=3, greedy=False, tag="a"):
            super().__init__()
            self.radius, self.steps, self.greedy, self.tag = radius, steps, greedy, tag


    def factory(**kw):
        return MyPlanner(**kw)


    def raises(**kw):
        raise ValueError("no GPU here")


    def not_a_planner(**kw):
        return 42


    class Candidates(GreedyPlanner):
        """Returns the Candidate it picked instead of an Action (a plug-in's mistake)."""

        def decide(self, graph):
            from sgtool.planning.candidates import actionable

            return actionable(graph)[0]


    class GlobalRandom(GreedyPlanner):
        """Draws from Python's and numpy's global generators, not from its seed."""

        def decide(self, graph):
            import random

            import numpy as np
            from sgtool.planning.base import Action
            from sgtool.planning.candidates import actionable

            cands = actionable(graph)
            k = (random.randrange(len(cands)) + int(np.random.randint(len(cands)))) % len(cands)
            return Action("navigate", cands[k].node_id, reason="random")


    class Priored(GreedyPlanner):
        @dataclass(frozen=True)
        class Options:
            weights_dir: str = ""

        def __init__(self, weights_dir=""):
            super().__init__()
            self.weights_dir = weights_dir


    class OddReason(GreedyPlanner):
        def decide(self, graph):
            from dataclasses import replace

            return replace(super().decide(graph), reason=3)


    class Half:
        name = "half"

        def reset(self, query, seed=0):
            pass
''')


@pytest.fixture
def plugin_dir(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    (tmp_path / "mymod_plug.py").write_text(PLUGIN)
    (tmp_path / "broken_plug.py").write_text("import not_installed_anywhere\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    return tmp_path


def test_a_class_gets_its_options_and_carries_its_given_name(plugin_dir: Path) -> None:
    p = make_planner("mymod_plug:MyPlanner", k=3, label="y")
    assert p.name == "mymod_plug:MyPlanner"  # as named: the label of tables and logs
    assert type(p).__name__ == "TimedPlanner"
    assert (p.inner.k, p.inner.label) == (3, "y")  # type: ignore[attr-defined]
    # untimed, a plug-in still carries the name as given (its rows and logs are its own)
    # and its contract is still checked; only the decision time is not measured
    raw = make_planner("mymod_plug:factory", timed=False)
    assert raw.name == "mymod_plug:factory" and raw.inner.name == "mine"  # type: ignore[attr-defined]
    assert raw.k == 1  # type: ignore[attr-defined]


def test_a_plain_options_dataclass_checks_by_its_fields_types(plugin_dir: Path) -> None:
    """An Options dataclass without option() metadata: values are checked and converted
    by each field's default type, unknown keys named, and the options listed."""
    p = make_planner("mymod_plug:Plain", radius="1.5", steps="4", greedy="yes")
    assert (p.inner.radius, p.inner.steps, p.inner.greedy) == (1.5, 4, True)  # type: ignore[attr-defined]
    assert parse_option("mymod_plug:Plain", "tag", "b") == "b"
    with pytest.raises(PlannerOptionError, match="option steps=1.5: must be an integer"):
        make_planner("mymod_plug:Plain", steps="1.5")
    with pytest.raises(UnknownPlannerError, match="did you mean 'radius'"):
        make_planner("mymod_plug:Plain", radios=1.0)
    assert "radius (float, default 2.0)" in describe_planners(["mymod_plug:Plain"])


def test_plain_fields_are_typed_by_their_annotations(tmp_path: Path, monkeypatch) -> None:
    """Annotations as text (``from __future__ import annotations``) are resolved in the
    plug-in's module: ``X | None`` takes None, a ``Literal`` of strings is a choice, a
    ``Path`` a path that arrives as a Path, ``str | Path`` one that arrives as text, a
    ``list[str]`` a list (comma-separated), a dict a Python object (not set by -O); a name
    that does not resolve takes its default's type."""
    (tmp_path / "future_plug.py").write_text(textwrap.dedent('''
        from __future__ import annotations

        from dataclasses import dataclass, field
        from pathlib import Path
        from typing import Literal, Optional

        from sgtool.planning.planners import GreedyPlanner


        class P(GreedyPlanner):
            @dataclass
            class Options:
                tags: list[str] = field(default_factory=list)
                table: dict[str, float] = field(default_factory=dict)
                limit: Optional[int] = None
                cap: int | None = None
                mode: Unknowable = "a"
                speed: Literal["fast", "slow"] = "fast"
                where: str | Path = "x"
                folder: Path = Path(".")
                cache: Path | None = None

            def __init__(self, **kw):
                super().__init__()
                self.kw = kw
    '''))
    monkeypatch.syspath_prepend(str(tmp_path))
    assert parse_option("future_plug:P", "limit", "5") == 5
    assert make_planner("future_plug:P", cap=None).inner.kw == {"cap": None}  # type: ignore[attr-defined]
    assert parse_option("future_plug:P", "tags", "a, b") == ["a", "b"]
    with pytest.raises(PlannerOptionError, match="a Python object, set from Python only"):
        parse_option("future_plug:P", "table", "1.5")
    assert parse_option("future_plug:P", "mode", "b") == "b"
    assert parse_option("future_plug:P", "speed", "slow") == "slow"
    with pytest.raises(PlannerOptionError, match="must be one of fast, slow"):
        parse_option("future_plug:P", "speed", "medium")
    assert parse_option("future_plug:P", "where", "/tmp/x") == "/tmp/x"
    assert parse_option("future_plug:P", "folder", "/tmp/x") == Path("/tmp/x")  # as annotated
    assert parse_option("future_plug:P", "cache", "") is None  # empty: not set, not "."
    with pytest.raises(PlannerOptionError, match="must be an integer"):
        parse_option("future_plug:P", "cap", "x")


def test_an_options_dataclass_checks_like_the_built_ins(plugin_dir: Path) -> None:
    assert make_planner("mymod_plug:Typed", k="4").inner.k == 4  # type: ignore[attr-defined]
    assert parse_option("mymod_plug:Typed", "k", "5") == 5
    with pytest.raises(PlannerOptionError, match="option k=-1: must be >= 0"):
        make_planner("mymod_plug:Typed", k=-1)
    with pytest.raises(UnknownPlannerError, match="does not take option.*did you mean 'k'"):
        make_planner("mymod_plug:Typed", kk=1)
    # without one, -O text is parsed as int, float, true/false or text
    assert parse_option("mymod_plug:MyPlanner", "k", "2") == 2
    assert parse_option("mymod_plug:MyPlanner", "label", "abc") == "abc"


@pytest.mark.parametrize(("name", "message"), [
    ("nosuchmod_plug:X", "planner 'nosuchmod_plug:X': cannot import module 'nosuchmod_plug' "
     "(ModuleNotFoundError: No module named 'nosuchmod_plug'); is its folder on PYTHONPATH?"),
    ("broken_plug:X", "planner 'broken_plug:X': cannot import module 'broken_plug' "
     "(ModuleNotFoundError: No module named 'not_installed_anywhere'); the module was "
     "found and failed while importing: fix it, or install what it imports"),
    ("mymod_plug:Nope", "planner 'mymod_plug:Nope': 'mymod_plug' has no 'Nope'"),
    ("mymod_plug:raises", "planner 'mymod_plug:raises': raised ValueError: no GPU here"),
    ("mymod_plug:not_a_planner", "planner 'mymod_plug:not_a_planner': returned an int, not a "
     "Planner (it lacks name, reset, decide, feedback)"),
    ("mymod_plug:Half", "returned a Half, not a Planner (it lacks decide, feedback)"),
    ("mymod_plug:", "planner 'mymod_plug:': a plug-in is named module:Name"),
])
def test_failures_are_one_line_naming_the_plugin(plugin_dir: Path, name: str,
                                                 message: str) -> None:
    with pytest.raises(PluginError) as e:
        make_planner(name)
    assert message in str(e.value) and "\n" not in str(e.value)


def test_a_bad_option_of_a_plain_plugin_is_its_own_error(plugin_dir: Path) -> None:
    with pytest.raises(SgtoolError, match="planner 'mymod_plug:MyPlanner' does not take "
                                          "option\\(s\\): zz"):
        make_planner("mymod_plug:MyPlanner", zz=1)


def test_text_given_from_python_to_a_plain_plugin_is_converted_as_from_the_cli(
        plugin_dir: Path) -> None:
    """A plug-in without Options given text from Python (a config file's values): converted
    by its parameters' annotations as -O text is ('false' was passed on, and is true);
    other values and text for a str parameter as given; a key it does not take names the
    nearest (it was a TypeError of the call)."""
    p = make_planner("mymod_plug:Annotated", penalty="0.5", weights="1,2", verbose="false",
                     tag="7")
    inner = p.inner  # type: ignore[attr-defined]
    assert (inner.penalty, inner.weights, inner.verbose, inner.tag) == (0.5, (1.0, 2.0),
                                                                         False, "7")
    assert make_planner("mymod_plug:Annotated", penalty=3).inner.penalty == 3  # type: ignore[attr-defined]
    assert make_planner("mymod_plug:Annotated", mode="auto").inner.mode == "auto"  # type: ignore[attr-defined]
    with pytest.raises(SgtoolError, match="option penalty=abc: must be a number"):
        make_planner("mymod_plug:Annotated", penalty="abc")
    with pytest.raises(SgtoolError, match="does not take option\\(s\\): penalt; did you mean "
                                          "'penalty'"):
        make_planner("mymod_plug:Annotated", penalt=1)


def test_entry_points_register_names(plugin_dir: Path) -> None:
    dist = plugin_dir / "sgtool_fake_planners-1.0.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: sgtool-fake-planners\n"
                                   "Version: 1.0\n")
    (dist / "entry_points.txt").write_text(
        f"[{GROUP}]\nfake-greedy = mymod_plug:MyPlanner\nfake-broken = broken_plug:X\n"
        "scout = mymod_plug:MyPlanner\n")
    found = entry_points()
    assert found["fake-greedy"].value == "mymod_plug:MyPlanner"
    check_planner_name("fake-greedy")
    p = make_planner("fake-greedy", k=2)
    assert p.name == "fake-greedy" and p.inner.k == 2  # type: ignore[attr-defined]
    with pytest.raises(PluginError, match="planner 'fake-broken': cannot load entry point "
                                          "'broken_plug:X' of sgtool.planners"):
        make_planner("fake-broken")
    assert make_planner("scout", timed=False).name == "scout"  # the built-in wins
    text = describe_planners()
    assert "    fake-greedy = mymod_plug:MyPlanner\n" in text
    assert "    scout = mymod_plug:MyPlanner (shadowed by the built-in planner)" in text
    with pytest.raises(UnknownPlannerError) as e:  # a shadowed name is listed once
        check_planner_name("astar")
    assert str(e.value).count(" scout,") == 1 and "fake-greedy" in str(e.value)


def test_unknown_names_and_file_names() -> None:
    with pytest.raises(UnknownPlannerError, match="unknown planner 'astar'; choose one of: "
                                                  "random, .*or module:Name"):
        check_planner_name("astar")
    with pytest.raises(UnknownPlannerError, match="unknown planner 'scuot'; did you mean "
                                                  "'scout'\\? choose one of"):
        check_planner_name("scuot")
    check_planner_name("pkg.sub:Cls.Inner")  # written right: not imported by the check
    assert file_name("pkg.sub:Cls") == "pkg.sub__Cls" and file_name("scout") == "scout"


def test_a_decision_that_is_no_action_is_one_line_naming_the_plugin(plugin_dir: Path) -> None:
    from support.planning_world import World

    from sgtool.planning.timing import PlannerContractError

    planner = make_planner("mymod_plug:Candidates")
    graph = World(0).graph()
    planner.reset("mug")
    with pytest.raises(PlannerContractError) as e:
        planner.decide(graph)
    assert str(e.value) == ("planner 'mymod_plug:Candidates': decide() returned a Candidate, "
                            "not an sgtool.Action (e.g. Action('navigate', node_id))")


def test_options_compared_as_the_planner_takes_them(plugin_dir: Path) -> None:
    """effective_options: text and numbers alike, an option at its default (timed too) is
    no option, a key the planner does not take is kept as given, a path is a path; and a
    path option is recorded in a log as its text (so a resume compares it)."""
    from sgtool.planning.registry import effective_options
    from sgtool.redact import recorded_options

    assert effective_options("scout", {"delta": "0.10", "timed": True}) == {}
    assert effective_options("scout", {"delta": 0.2, "bogus": 1}) == {"delta": 0.2,
                                                                      "bogus": 1}
    assert effective_options("nomod_plug:X", {"k": "1"}) == {"k": "1"}  # cannot be asked
    # ... and compared as -O text: a log's typed values and a command's text alike
    assert effective_options("nomod_plug:X", {"w": [0.5, 0.5], "b": True, "x": 0.3}) == \
        effective_options("nomod_plug:X", {"w": "0.5,0.5", "b": "true", "x": "0.3"})
    # a float logged 1.0 given as "1" or "1.0", a bool logged true given as yes or on
    for text in ("1", "1.0", "1.00"):
        assert effective_options("nomod_plug:X", {"a": 1.0, "f": True, "w": [1.0, 2]}) == \
            effective_options("nomod_plug:X", {"a": text, "f": "yes", "w": f"{text},2.0"})
    assert effective_options("nomod_plug:X", {"a": 1.5}) != \
        effective_options("nomod_plug:X", {"a": "1"})
    # a plug-in without an Options class: its __init__'s defaults are its defaults
    assert effective_options("mymod_plug:MyPlanner", {"k": "1", "label": "y"}) == {
        "label": "y"}
    assert recorded_options({"folder": Path("/tmp/x"), "obj": object()}) == {
        "folder": "/tmp/x"}


def test_a_plug_ins_global_randomness_follows_the_episode_seed(plugin_dir: Path) -> None:
    """A plug-in drawing from random/np.random decides the same for the same episode
    seed whatever ran before, and leaves the caller's global generators as they were."""
    import random

    import numpy as np
    from support.planning_world import World

    graph = World(0).graph()

    def targets(seed: int) -> list[str | None]:
        planner = make_planner("mymod_plug:GlobalRandom")
        planner.reset("mug", seed)
        return [planner.decide(graph).target for _ in range(6)]

    random.seed(1)
    np.random.seed(1)
    first = targets(5)
    after = random.random(), float(np.random.random_sample())
    random.seed(99)
    np.random.seed(99)  # other global states before the same episode
    assert targets(5) == first
    random.seed(1)
    np.random.seed(1)
    targets(5)
    assert (random.random(), float(np.random.random_sample())) == after  # untouched
    assert any(targets(s) != first for s in range(6, 12))  # another seed, other draws
    # two threads deciding at once: each draws as alone, the caller's state untouched
    import threading

    random.seed(1)
    got: list[list[str | None]] = []
    runs = [threading.Thread(target=lambda: got.append(targets(5))) for _ in range(2)]
    for t in runs:
        t.start()
    for t in runs:
        t.join()
    assert got == [first, first] and random.random() == after[0]


def test_an_action_whose_reason_is_no_text_is_one_line(plugin_dir: Path) -> None:
    from support.planning_world import World

    from sgtool.planning.timing import PlannerContractError

    planner = make_planner("mymod_plug:OddReason")
    planner.reset("mug")
    with pytest.raises(PlannerContractError, match="an Action whose reason is 3 .int.; a "
                                                   "reason is text"):
        planner.decide(World(0).graph())


def test_priors_reach_a_plug_in_whose_options_name_weights(plugin_dir: Path) -> None:
    """bench --priors DIR reaches a plug-in with a weights_dir option as it reaches scout
    (it kept the shipped priors, with the tables labelled by DIR); -O still wins."""
    from sgtool.analysis.bench import BenchConfig
    from sgtool.analysis.bench_priors import planner_options_for

    cfg = BenchConfig(planners=("scout", "mymod_plug:Priored", "mymod_plug:Typed"),
                      priors_dir="blend")
    assert planner_options_for(cfg, "scout") == {"weights_dir": "blend"}
    assert planner_options_for(cfg, "mymod_plug:Priored") == {"weights_dir": "blend"}
    assert planner_options_for(cfg, "mymod_plug:Typed") == {}
    given = BenchConfig(planners=("mymod_plug:Priored",), priors_dir="blend",
                        planner_options={"mymod_plug:Priored": {"weights_dir": "mine"}})
    assert planner_options_for(given, "mymod_plug:Priored") == {"weights_dir": "mine"}


def test_a_plug_in_constructor_drawing_from_random_draws_the_same_every_run(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A plug-in that seeds itself from the global generators in its constructor (a
    common pattern) is built with them seeded, so a bench of it is the same in every run
    and process; the caller's generators are left as they were."""
    import random

    import numpy as np

    (tmp_path / "initrand_plug.py").write_text(textwrap.dedent('''
        import random

        import numpy as np

        from sgtool.planning.planners import GreedyPlanner


        class Drawn(GreedyPlanner):
            def __init__(self):
                super().__init__()
                self.drawn = (random.random(), float(np.random.random_sample()))
    '''))
    monkeypatch.syspath_prepend(str(tmp_path))
    random.seed(1)
    np.random.seed(1)
    first = make_planner("initrand_plug:Drawn").drawn
    after = random.random(), float(np.random.random_sample())
    random.seed(2)
    np.random.seed(2)
    assert make_planner("initrand_plug:Drawn").drawn == first
    random.seed(1)
    np.random.seed(1)
    make_planner("initrand_plug:Drawn")
    assert (random.random(), float(np.random.random_sample())) == after  # untouched


def test_a_name_two_packages_register_is_refused_naming_both(plugin_dir: Path) -> None:
    """Two installed packages register `fake-twice` as different classes: which one a
    lookup finds depends on the install order, so neither is taken (it was the first,
    silently); the listing shows both. The same value registered twice is one."""
    for pkg, value in (("alpha", "mymod_plug:MyPlanner"), ("beta", "mymod_plug:Half")):
        dist = plugin_dir / f"sgtool_{pkg}-1.0.dist-info"
        dist.mkdir()
        (dist / "METADATA").write_text(f"Metadata-Version: 2.1\nName: sgtool-{pkg}\n"
                                       "Version: 1.0\n")
        (dist / "entry_points.txt").write_text(
            f"[{GROUP}]\nfake-twice = {value}\nfake-once = mymod_plug:MyPlanner\n")
    with pytest.raises(PluginError, match=r"planner 'fake-twice': two installed packages "
                                          r"register it in sgtool.planners \(mymod_plug:"):
        make_planner("fake-twice")
    assert make_planner("fake-once").name == "fake-once"
    assert "fake-twice = mymod_plug:" in describe_planners()
    assert "(registered by two packages: name one as module:Name)" in describe_planners()


def test_a_required_option_of_a_plug_in_is_named_when_left_out(tmp_path: Path,
                                                              monkeypatch) -> None:
    """An Options field without a default: --list-planners says it is required, and
    leaving it out is one line naming it (it was the constructor's TypeError)."""
    (tmp_path / "req_plug.py").write_text(textwrap.dedent('''
        from dataclasses import dataclass

        from sgtool.planning.planners import GreedyPlanner


        class Needs(GreedyPlanner):
            @dataclass
            class Options:
                model_path: str
                k: int = 2

            def __init__(self, model_path, k=2):
                super().__init__()
                self.model_path = model_path
    '''))
    monkeypatch.syspath_prepend(str(tmp_path))
    from sgtool.planning.option_fields import PlannerOptionError

    with pytest.raises(PlannerOptionError, match=r"planner 'req_plug:Needs': option model_path is "
                                          r"required \(-O req_plug:Needs.model_path=\.\.\.\)"):
        make_planner("req_plug:Needs")
    made = make_planner("req_plug:Needs", model_path="m.gguf")
    assert made.inner.model_path == "m.gguf"  # type: ignore[attr-defined]
    assert "model_path (str, required)" in describe_planners(["req_plug:Needs"])
    # -O converts one option at a time: another one given alone is no missing option
    from sgtool.planning.registry import parse_option

    assert parse_option("req_plug:Needs", "k", "3") == 3


def test_a_plug_in_module_drawing_at_import_draws_the_same_in_any_process(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A module that draws from the global generators at import (a table of random
    features) drew other numbers in the driver and in each worker: it is imported with
    them seeded, the caller's put back."""
    import importlib
    import random
    import sys

    (tmp_path / "importrand_plug.py").write_text(textwrap.dedent('''
        import random

        from sgtool.planning.planners import GreedyPlanner

        TABLE = [random.random() for _ in range(3)]


        class Drawn(GreedyPlanner):
            pass
    '''))
    monkeypatch.syspath_prepend(str(tmp_path))
    tables = []
    for seed in (1, 2):
        sys.modules.pop("importrand_plug", None)  # a fresh process imports it anew
        random.seed(seed)
        make_planner("importrand_plug:Drawn")
        after = random.random()
        random.seed(seed)
        assert after == random.random()  # the caller's stream as if nothing was imported
        tables.append(importlib.import_module("importrand_plug").TABLE)
    assert tables[0] == tables[1]


def test_list_options_from_the_command_line(tmp_path: Path, monkeypatch) -> None:
    """A ``tuple[float, float]``, ``tuple[str, ...]`` or ``list[int]`` option (an Options
    field, or a parameter of a plug-in without Options) takes comma-separated -O text: each
    item converted and checked, a fixed length counted; a log's list is the tuple -O gives.
    (A tuple parameter of a plug-in without Options got the text "0.3,0.7" before.)"""
    from sgtool.planning.registry import effective_options, typed_options

    (tmp_path / "list_plug.py").write_text(textwrap.dedent('''
        from __future__ import annotations

        from dataclasses import dataclass, field

        from sgtool.planning.option_fields import option
        from sgtool.planning.planners import GreedyPlanner


        class WithOptions(GreedyPlanner):
            @dataclass(frozen=True)
            class Options:
                weights: tuple[float, float] = (0.5, 0.5)
                shares: tuple[float, ...] = field(default=(), metadata=option(
                    "shares", "list", item="float", lo=0.0, hi=1.0))

            def __init__(self, **kw):
                super().__init__()
                self.kw = kw


        class Signature(GreedyPlanner):
            def __init__(self, weights: tuple[float, float] = (0.5, 0.5),
                         rooms: tuple[str, ...] = (), counts: list[int] | None = None,
                         k: int = 1, anything=None):
                super().__init__()
                self.kw = dict(weights=weights, rooms=rooms, counts=counts, k=k,
                               anything=anything)
    '''))
    monkeypatch.syspath_prepend(str(tmp_path))
    for name in ("list_plug:WithOptions", "list_plug:Signature"):
        assert parse_option(name, "weights", "0.3, 0.7") == (0.3, 0.7)
        with pytest.raises(PlannerOptionError, match="must be 2 comma-separated numbers, "
                                                     "not 3"):
            parse_option(name, "weights", "1,2,3")
        with pytest.raises(PlannerOptionError, match=r"option weights\[1\]=x: must be a "
                                                     "number"):
            parse_option(name, "weights", "1,x")
        # a log records the list; compared as -O gives it
        assert typed_options(name, {"weights": [0.3, 0.7]}) == {"weights": (0.3, 0.7)}
        assert effective_options(name, {"weights": [0.5, 0.5]}) == {}
    with pytest.raises(PlannerOptionError, match=r"shares\[0\]=2: must be 0..1"):
        parse_option("list_plug:WithOptions", "shares", "2")
    assert parse_option("list_plug:WithOptions", "shares", "") == ()
    assert make_planner("list_plug:WithOptions", weights=[1, 2]).inner.kw == {  # type: ignore[attr-defined]
        "weights": (1.0, 2.0)}
    sig = "list_plug:Signature"
    assert parse_option(sig, "rooms", "kitchen, bath room") == ("kitchen", "bath room")
    assert parse_option(sig, "counts", "1,2") == [1, 2]
    with pytest.raises(PlannerOptionError, match="option k=2.5: must be an integer"):
        parse_option(sig, "k", "2.5")
    assert parse_option(sig, "anything", "2.5") == 2.5  # not annotated: parsed as before
    lines = describe_planners([sig])
    assert "weights (float list, default 0.5,0.5): a field of tuple[float, float] " \
        "[2 comma-separated numbers]" in lines
    assert "rooms (str list, default none)" in lines


def test_list_options_keep_their_items_defaults_and_none(tmp_path: Path, monkeypatch) -> None:
    """A review's cases: a logged text item holding a comma stays one item (it was joined
    and split again), a list field's default_factory is its default (giving it was "other
    settings"), `-O k=` sets an optional list to None, and one annotation that does not
    evaluate leaves the others typed (it left every parameter untyped)."""
    from sgtool.planning.registry import effective_options, typed_options

    (tmp_path / "lists_plug.py").write_text(textwrap.dedent('''
        from __future__ import annotations

        from dataclasses import dataclass, field
        from typing import TYPE_CHECKING

        from sgtool.planning.planners import GreedyPlanner

        if TYPE_CHECKING:
            from nowhere import Missing


        class WithOptions(GreedyPlanner):
            @dataclass(frozen=True)
            class Options:
                tags: list[str] = field(default_factory=lambda: ["a", "b"])
                pair: tuple[float, float] | None = None

            def __init__(self, **kw):
                super().__init__()


        class Broken(GreedyPlanner):
            def __init__(self, weights: tuple[float, float] = (0.5, 0.5),
                         m: Missing | None = None):
                super().__init__()
    '''))
    monkeypatch.syspath_prepend(str(tmp_path))
    name = "lists_plug:WithOptions"
    assert typed_options(name, {"tags": ["kitchen, north", " bath"]}) == {
        "tags": ["kitchen, north", " bath"]}
    assert effective_options(name, {"tags": ["a", "b"]}) == {}
    assert "tags (str list, default a,b)" in describe_planners([name])
    assert parse_option(name, "pair", "") is None
    assert parse_option("lists_plug:Broken", "weights", "0.3,0.7") == (0.3, 0.7)
