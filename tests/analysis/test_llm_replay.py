"""An LLM planner's symbolic episode replayed from its own log: every decision matched.

The "model" is a deterministic script that answers with one of the commands the grammar
allows (a real server would be constrained the same way), once with a command outside the
scene (rejected and retried). The episode is logged as the bench logs it (``--log-dir``:
graph, LLM exchanges on /sgtool/llm, action with the executor's message); ``sgtool eval``
then replays the moma-llm planner against the log, answering from the log's own exchanges.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math

import pytest
from click.testing import CliRunner
from support.symbolic_fixtures import three_rooms

from sgtool.analysis.offline import (
    load_results,
    log_exchanges,
    read_log_episodes,
    replay_decisions,
    with_success_rule,
)
from sgtool.cli import cli
from sgtool.house.io import load_house
from sgtool.llm.client import ChatResult
from sgtool.llm.stats import answer_stats
from sgtool.log.writer import LogWriter
from sgtool.planning.episode import NOT_CONFIRMED
from sgtool.planning.registry import make_planner
from sgtool.recorders.symbolic_environment import SymbolicHouse, run_episode
from sgtool.results import Step


class GrammarScript:
    """Answers with a command of the constraint (done() when allowed, else an open or an
    explore, chosen by the prompt's hash); the second request is answered outside the
    scene."""

    model = "grammar-script"
    takes_constraint = True

    def __init__(self) -> None:
        self.calls = 0

    def complete(self, messages, constraint=None) -> ChatResult:
        self.calls += 1
        cmds = list(constraint.commands)
        if self.calls == 2:
            cmd = "explore(garage)"
        elif "done()" in cmds:
            cmd = "done()"
        else:  # open what can be opened, else explore, the pick by the prompt's hash
            pick = [c for c in cmds if c.startswith("go_to_and_open") and "door" not in c] \
                or [c for c in cmds if c.startswith("explore")] or cmds
            key = hashlib.sha256(json.dumps(messages).encode()).digest()[0]
            cmd = pick[key % len(pick)]
        return ChatResult(f"Analysis: a\nReasoning: step {self.calls}\nCommand: {cmd}",
                          self.model, 0.001, 100, 10)


@pytest.fixture(scope="module")
def llm_log(tmp_path_factory):
    house = SymbolicHouse(load_house(three_rooms()))
    path = tmp_path_factory.mktemp("logs") / "moma.mcap"
    planner = make_planner("moma-llm", client=GrammarScript(), constraint="grammar")
    with LogWriter(path, seed=0) as log:
        res = run_episode(house, planner, "sweater", ["obj_5"], seed=0, episode_index=0,
                          house_id="three", log=log, success="done", max_steps=12)
    return path, res


def test_the_log_holds_the_exchanges_and_the_executor_messages(llm_log) -> None:
    path, res = llm_log
    (ep,) = read_log_episodes(path)
    assert len(ep.decisions) >= 3  # a multi-decision episode
    msgs = [d.action.unknown.get("message") for d in ep.decisions]
    reasons = [d.action.reason for d in ep.decisions]
    assert all(isinstance(m, str) for m in msgs) and msgs != reasons
    ex = log_exchanges([path])
    stats = answer_stats(ex)
    assert stats.invalid == 1 and stats.valid == len(ep.decisions)
    assert stats.requests == len(ep.decisions) + 1 and stats.decisions == len(ep.decisions)
    # the same records as a replay serves them: counted alike, but a replay's latency (the
    # time to look an answer up) is no generation speed
    replayed = answer_stats((src, {**r, "source": "replay"}) for src, r in ex)
    assert (replayed.requests, replayed.valid, replayed.invalid) == \
        (stats.requests, stats.valid, stats.invalid)
    assert replayed.latency_s == 0.0 and math.isnan(replayed.tokens_per_s)


def test_every_decision_replays_from_the_log(llm_log) -> None:
    path, res = llm_log
    eps = read_log_episodes(path)
    report = replay_decisions(make_planner("moma-llm", replay=[path]), eps, name="moma-llm")
    assert report.decisions == len(eps[0].decisions) >= 3
    assert report.rate("agree") == 1.0 and report.skipped == 0


def test_eval_cli_replays_from_the_mcap_and_reports_answers(llm_log) -> None:
    path, res = llm_log
    r = CliRunner().invoke(cli, ["eval", str(path), "-p", "moma-llm", "--json"])
    assert r.exit_code == 0, r.output
    doc = json.loads(r.output)
    assert doc["offline"]["moma-llm"]["same_action"] == 1.0
    assert doc["offline"]["moma-llm"]["decisions"] >= 3
    assert doc["llm_answers"]["invalid"] == 1


def test_eval_with_another_runs_transcript_is_an_error(llm_log, tmp_path) -> None:
    """A transcript that does not hold the logs' prompts is no replay of them: one error
    line naming the log and the decision, not a table of give-ups."""
    path, _ = llm_log
    other = tmp_path / "other.jsonl"
    _, rec = log_exchanges([path])[0]
    rec = {**rec, "messages": [{"role": "user", "content": "another run's prompt"}]}
    rec.pop("prompt_sha256", None)
    other.write_text(json.dumps(rec) + "\n")
    r = CliRunner().invoke(cli, ["eval", str(path), "-p", "moma-llm", "--llm-replay",
                                 str(other)])
    assert r.exit_code == 2, r.output
    assert "holds no (more) responses for this prompt" in r.output
    assert f"({path}, decision 0)" in r.output


def test_success_rules_in_eval(llm_log) -> None:
    path, res = llm_log
    (r,) = load_results([path])[0]
    assert (r.success, r.end) == (res.success, res.end)
    base = dataclasses.replace(r, success=True, end="found")
    on_sight = dataclasses.replace(base, trace=(Step("open", "obj:1", "success", 1.0),))
    confirmed = dataclasses.replace(base, trace=(*on_sight.trace,
                                                 Step("done", "obj:5", "success", 0.0)))
    # observed: as recorded; done: only the confirmed one succeeds
    assert with_success_rule(on_sight, "observed") == on_sight
    assert (with_success_rule(on_sight, "done").success,
            with_success_rule(on_sight, "done").end) == (False, NOT_CONFIRMED)
    assert with_success_rule(confirmed, "done") == confirmed
    # an episode that ended unconfirmed under done still saw the target
    back = with_success_rule(with_success_rule(on_sight, "done"), "observed")
    assert (back.success, back.end) == (True, "found")
    assert with_success_rule(on_sight, None) == on_sight
