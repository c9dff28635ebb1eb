"""The LLM baselines: Unstructured LLM (raw JSON scene graph in the prompt) and GODHS with an
LLM ranker, against scripted endpoints on hand-made scene graphs."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
from support.semantics_fixtures import ChatServer, answer, encoder, house

from sgtool.llm.client import ChatResult
from sgtool.planning.llm_ranker import LlmRanker, read_likelihoods
from sgtool.planning.moma.unstructured import JSON_INTRO
from sgtool.planning.registry import make_planner


def test_unstructured_prompt_holds_the_raw_json() -> None:
    g = house()
    with ChatServer([answer("explore(kitchen)")]) as srv:
        p = make_planner("unstructured-llm", base_url=srv.base_url, model="m", api_key="k",
                         timeout_s=5.0, constraint="none")
        p.reset("milk")
        a = p.decide(g)
    assert p.name == "unstructured-llm"
    assert (a.skill, a.target) == ("explore", "frontier:1")
    user = srv.requests[0]["messages"][1]["content"]
    assert user.startswith(JSON_INTRO + "\n")
    shown = user[len(JSON_INTRO) + 1:].split("\n\nPrevious actions:")[0]
    assert json.loads(shown) == json.loads(g.to_json())
    assert "Observed rooms and their objects" not in user
    # the system prompt (skills, format) is MoMa-LLM's
    assert "go_to_and_open(room, object)" in srv.requests[0]["messages"][0]["content"]
    assert p.exchanges[0]["verdict"] == "ok"


def explored_house():
    """The test house with nothing left to explore: rooms 1-3, their objects, no door."""
    g = house()
    return dataclasses.replace(g, rooms=g.rooms[:3],
                               regions=tuple(r for r in g.regions if r.kind != "frontier"),
                               doors=())


class Script:
    """Likelihood answers by what is asked (rooms or carriers)."""

    model = "script"

    def __init__(self, rooms: dict, carriers: dict | str) -> None:
        self.answers = {"rooms": rooms, "carriers": carriers}
        self.asked: list[str] = []

    def complete(self, messages):
        what = "rooms" if "these rooms" in messages[1]["content"] else "carriers"
        self.asked.append(what)
        a = self.answers[what]
        return ChatResult(a if isinstance(a, str) else json.dumps(a), self.model, 0.01)


def test_the_llm_ranking_chooses_room_and_carrier() -> None:
    g = explored_house()
    kitchen_first = Script({"kitchen": 0.9, "bathroom": 0.1, "living room": 0.2},
                           {"fridge": 0.9, "bottom cabinet": 0.3, "countertop": 0.2})
    p = make_planner("godhs-llm", client=kitchen_first, encoder=encoder())
    p.reset("milk")
    a = p.decide(g)
    assert (a.skill, a.target) == ("open", "obj:10")  # the fridge of the kitchen
    assert p.name == "godhs-llm"
    bathroom_first = Script({"kitchen": 0.1, "bathroom": 0.9},  # living room left out: mean
                            {"bottom cabinet": 0.8, "sink": 0.5, "fridge": 0.1})
    q = make_planner("godhs-llm", client=bathroom_first, encoder=encoder())
    q.reset("soap")
    assert q.decide(g).target == "obj:21"  # the bathroom's cabinet
    q.decide(g)
    # asked once per set of names: the second decision is answered from the memo
    assert bathroom_first.asked == ["rooms", "carriers"]
    ex = q.inner.ranker.exchanges
    assert [e["purpose"] for e in ex] == ["godhs_rooms", "godhs_carriers"]
    assert {e["verdict"] for e in ex} == {"ok"}


def test_unusable_answers_fall_back_to_the_priors() -> None:
    g = explored_house()
    bad = Script("I think the kitchen.", "no idea")
    ranker = LlmRanker(bad, fallback=None)
    rooms = ranker.rooms(g, "milk")
    assert rooms == {"room:1": 0.5, "room:2": 0.5, "room:3": 0.5}
    assert np.array_equal(ranker.carriers(["fridge", "sink"], "milk"), [0.5, 0.5])
    assert [e["verdict"] for e in ranker.exchanges] == ["invalid: no likelihoods"] * 2
    p = make_planner("godhs-llm", client=Script("?", "?"), encoder=encoder())
    p.reset("milk")
    prior = make_planner("godhs", encoder=encoder())
    prior.reset("milk")
    assert p.decide(g).target == prior.decide(g).target  # the priors decide instead


def test_read_likelihoods() -> None:
    names = ("living room", "kitchen", "bedroom 2")
    got = read_likelihoods('Sure: {"Living_Room": 0.7, "kitchen": "1.4", "garage": 1}', names)
    assert got == {"living room": 0.7, "kitchen": 1.0}
    assert read_likelihoods("[0.1, 0.2]", names) is None
    assert read_likelihoods('{"garage": 1}', names) is None


def test_godhs_llm_exchanges_reach_the_episode_log(tmp_path) -> None:
    """godhs-llm exposes its ranker's exchanges like moma-llm, so a bench log holds them on
    /sgtool/llm, each at the time of the decision that asked."""
    from support.symbolic_fixtures import three_rooms

    from sgtool.house.io import load_house
    from sgtool.log.reader import LogReader
    from sgtool.log.records import LlmExchange
    from sgtool.log.writer import LogWriter
    from sgtool.recorders.symbolic_environment import SymbolicHouse, run_episode

    script = Script({"kitchen": 0.9, "bathroom": 0.1, "living room": 0.2},
                    {"wardrobe": 0.9, "bed": 0.1})
    planner = make_planner("godhs-llm", client=script, encoder=encoder())
    path = tmp_path / "godhs.mcap"
    with LogWriter(path, seed=0) as log:
        run_episode(SymbolicHouse(load_house(three_rooms())), planner, "sweater", ["obj_5"],
                    seed=0, house_id="three", log=log, max_steps=12)
    with LogReader(path) as r:
        logged = [rec for _, rec in r.records(LlmExchange)]
    assert script.asked  # the ranker was asked (the house was explored first)
    assert len(logged) == len(script.asked)
    assert [x.to_json()["purpose"] for x in logged] == \
        [f"godhs_{w}" for w in script.asked]
    # drained once for a closed-loop writer, then empty
    assert len(planner.drain_exchanges()) == len(script.asked)
    assert planner.drain_exchanges() == []
    assert make_planner("godhs", encoder=encoder()).exchanges is None
