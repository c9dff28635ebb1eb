"""The registry's table: every planner's options dataclass has the planners' own defaults,
values are checked (type, range, unknown key with the nearest known one), planners built
through the table are those built by hand, and ``describe_planners`` lists the options."""

from __future__ import annotations

import dataclasses
from typing import Literal

import pytest

from sgtool.planning.option_fields import (
    PlannerOptionError,
    UnknownPlannerError,
    convert_options,
    option,
    option_infos,
)
from sgtool.planning.planner_options import (
    BayesSearchOptions,
    EscOptions,
    GodhsOptions,
    LlmEndpointOptions,
    MomaOptions,
    SbertOptions,
    ScoutOptions,
)
from sgtool.planning.registry import (
    PLANNER_NAMES,
    REGISTRY,
    describe_planners,
    is_llm_planner,
    make_planner,
    parse_option,
)


def _defaults(cls: type) -> dict[str, object]:
    return {f.name: f.default for f in dataclasses.fields(cls)
            if f.default is not dataclasses.MISSING}


def test_defaults_are_the_planners_own() -> None:
    """The dataclasses repeat the parameter classes' defaults: each pair is compared."""
    from sgtool.llm.client import DEFAULT_TIMEOUT_S
    from sgtool.llm.constraints import REASON_CHARS
    from sgtool.planning.belief import BeliefParams
    from sgtool.planning.esc import EscParams
    from sgtool.planning.moma.planner import DECISION_TIMEOUT_S, MomaLlmPlanner
    from sgtool.planning.search_theory import SearchParams
    from sgtool.planning.utility import UtilityParams

    scout = UtilityParams.scout()
    sbert = UtilityParams.sbert()
    for opts, params in ((ScoutOptions(), scout), (SbertOptions(), sbert)):
        for k in ("default_room", "default_frontier", "delta", "room_weight",
                  "frontier_radius"):
            assert getattr(opts, k) == getattr(params, k), k
    search, belief = SearchParams(), BeliefParams()
    bayes = BayesSearchOptions()
    for k in ("step_cost", "open_cost", "reveal_cost", "top_k", "horizon", "step_budget"):
        assert getattr(bayes, k) == getattr(search, k), k
    for k in ("room_floor", "object_floor", "sharpness", "object_sharpness", "beyond", "miss",
              "region_weight"):
        assert getattr(bayes, k) == getattr(belief, k), k
    assert dataclasses.asdict(EscParams()) == {
        k: getattr(EscOptions(), k) for k in ("w_obj", "w_room", "w_dist", "radius")}
    import inspect

    sig = inspect.signature(MomaLlmPlanner.__init__).parameters
    moma = MomaOptions()
    for k in ("max_attempts", "stuck_repeats", "history_limit"):
        assert getattr(moma, k) == sig[k].default, k
    assert (moma.decision_timeout_s, moma.reason_chars) == (DECISION_TIMEOUT_S, REASON_CHARS)
    assert LlmEndpointOptions().timeout_s == DEFAULT_TIMEOUT_S
    assert GodhsOptions().carrier_threshold == 0.1
    assert all(d.max_failures == 2 for d in (ScoutOptions(), GodhsOptions(), EscOptions()))


def test_the_table_covers_every_name_with_frozen_dataclasses() -> None:
    assert PLANNER_NAMES == tuple(REGISTRY)
    for name, entry in REGISTRY.items():
        assert dataclasses.is_dataclass(entry.options) and entry.summary, name
        assert entry.options.__dataclass_params__.frozen, name  # type: ignore[attr-defined]
        assert option_infos(entry.options), name  # every field carries option() metadata
    assert [n for n in PLANNER_NAMES if is_llm_planner(n)] == [
        "moma-llm", "unstructured-llm", "godhs-llm"]


@pytest.mark.parametrize(("given", "expect"), [
    ({"delta": "0.2"}, {"delta": 0.2}),
    ({"delta": 1}, {"delta": 1.0}),
    ({"max_failures": "3"}, {"max_failures": 3}),
    ({"max_failures": 3.0}, {"max_failures": 3}),
    ({"weights_dir": "/w"}, {"weights_dir": "/w"}),
])
def test_values_are_converted_to_their_kind(given: dict[str, object],
                                            expect: dict[str, object]) -> None:
    out = convert_options("scout", ScoutOptions, given)
    assert out == expect
    assert [type(v) for v in out.values()] == [type(v) for v in expect.values()]


@pytest.mark.parametrize(("cls", "given", "message"), [
    (ScoutOptions, {"delta": "x"}, "option delta=x: must be a number"),
    (ScoutOptions, {"delta": float("inf")}, "option delta=inf: must be a finite number >= 0"),
    (ScoutOptions, {"room_weight": -0.1}, "option room_weight=-0.1: must be 0..1"),
    (ScoutOptions, {"max_failures": True}, "option max_failures=true: must be an integer"),
    (ScoutOptions, {"max_failures": [1]}, "option max_failures=[1]: must be an integer"),
    (BayesSearchOptions, {"blend": "perhaps"}, "option blend=perhaps: must be true or false"),
    (BayesSearchOptions, {"top_k": 0}, "option top_k=0: must be >= 1"),
    (MomaOptions, {"constraint": "xml"},
     "option constraint=xml: must be one of auto, grammar, json_schema, none"),
    (MomaOptions, {"timeout_s": 0}, "option timeout_s=0: must be > 0"),
    (MomaOptions, {"temperature": 3}, "option temperature=3: must be 0..2"),
])
def test_bad_values_are_one_line(cls: type, given: dict[str, object], message: str) -> None:
    with pytest.raises(PlannerOptionError) as e:
        convert_options("p", cls, given)
    assert message in str(e.value) and "\n" not in str(e.value)


def test_an_unknown_key_names_the_nearest_or_the_known_ones() -> None:
    with pytest.raises(UnknownPlannerError, match="does not take option.*did you mean "
                                                  "'carrier_threshold'"):
        make_planner("godhs", carrier_treshold=0.2)
    with pytest.raises(UnknownPlannerError, match="zzz; it takes: max_failures$"):
        make_planner("greedy", zzz=1)


def test_python_objects_pass_from_python_but_not_from_the_command_line() -> None:
    marker = object()
    assert convert_options("scout", ScoutOptions, {"encoder": marker}) == {"encoder": marker}
    with pytest.raises(PlannerOptionError, match="set from Python only"):
        convert_options("scout", ScoutOptions, {"encoder": "x"}, from_cli=True)
    # a path option that also takes objects: a mapping from Python, text from -O
    table = {"sofa": 0.5}
    assert convert_options("b", BayesSearchOptions, {"furniture_levels": table}) == {
        "furniture_levels": table}
    assert parse_option("bayes-search", "furniture_levels", "none") == "none"


def test_parse_option_checks_the_field_and_the_fixed_ones() -> None:
    assert parse_option("scout", "delta", "0.25") == 0.25
    assert parse_option("bayes-search", "blend", "no") is False
    assert parse_option("moma-llm", "model", "1e3") == "1e3"  # text stays text
    assert parse_option("greedy", "timed", "false") is False
    with pytest.raises(PlannerOptionError, match="delta is fixed at 0.0"):
        parse_option("scout-delta0", "delta", "0.2")
    with pytest.raises(PlannerOptionError, match="delta is fixed at 0.0"):
        make_planner("scout-delta0", delta=0.2)


def test_table_built_planners_equal_hand_built_ones() -> None:
    """What the factories build is the planner of the parameters (bit for bit: the same
    parameter objects)."""
    from support.semantics_fixtures import encoder

    from sgtool.planning.utility import UtilityParams

    scout = make_planner("scout", encoder=encoder(), timed=False)
    assert scout.params == UtilityParams.scout()  # type: ignore[attr-defined]
    sb = make_planner("sbert-noroom", encoder=encoder(), delta=0.2, timed=False)
    assert sb.params == UtilityParams.sbert(  # type: ignore[attr-defined]
        delta=0.2, room_influence=False)
    d0 = make_planner("scout-delta0", encoder=encoder(), timed=False)
    assert d0.params == UtilityParams.scout(delta=0.0)  # type: ignore[attr-defined]
    esc = make_planner("esc", encoder=encoder(), w_dist="0.25", timed=False)
    assert esc.params.w_dist == 0.25  # type: ignore[attr-defined]
    g = make_planner("godhs", encoder=encoder(), carrier_threshold=0.3, max_failures=4,
                     timed=False)
    assert (g.carrier_threshold, g.memory.max_failures) == (0.3, 4)  # type: ignore[attr-defined]


def test_describe_lists_every_planner_and_its_options() -> None:
    text = describe_planners()
    for name in PLANNER_NAMES:
        assert f"\n{name}: " in text
    assert "    delta (float, default 0.1): utility margin" in text
    assert "    delta (float, default 0.05): utility margin" in text  # sbert's
    assert "    delta: fixed at 0.0" in text
    assert "    encoder (Python only): " in text
    assert "    constraint (choice, default auto): " in text and \
        "[one of auto, grammar, json_schema, none]" in text
    assert "    top_k (int, default 5): " in text and "[>= 1]" in text
    assert "Every planner: timed (bool, default true)" in text
    assert "entry-point group sgtool.planners" in text


def test_a_plug_ins_choices_keep_their_case_and_an_empty_optional_is_none() -> None:
    """A Literal["Fast", "Slow"] option takes either spelling from -O and gives the choice
    as declared; `-O NAME.k=` sets an Optional[int] to None, as an empty path does."""
    @dataclasses.dataclass(frozen=True)
    class Opts:
        mode: Literal["Fast", "Slow"] = "Fast"
        n: int | None = 3

    for given in ("Fast", "fast", " SLOW "):
        got = convert_options("lab:P", Opts, {"mode": given}, from_cli=True)
        assert got == {"mode": given.strip().capitalize()}
    with pytest.raises(PlannerOptionError, match="mode=Medium: must be one of Fast, Slow"):
        convert_options("lab:P", Opts, {"mode": "Medium"}, from_cli=True)
    assert convert_options("lab:P", Opts, {"n": ""}, from_cli=True) == {"n": None}
    with pytest.raises(PlannerOptionError, match="must be an integer"):
        convert_options("lab:P", Opts, {"n": "x"}, from_cli=True)


def test_a_choice_needs_its_choices_and_only_a_choice_has_them() -> None:
    """`option(help, "choice")` without choices could never be set ("must be one of ");
    choices on another kind would be ignored: both are the plug-in author's error."""
    with pytest.raises(ValueError, match="a choice needs its choices"):
        option("mode", "choice")
    with pytest.raises(ValueError, match="only a choice has them"):
        option("n", "int", choices=("a", "b"))
    assert option("mode", "choice", choices=("a", "b"))
