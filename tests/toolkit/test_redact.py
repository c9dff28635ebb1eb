"""Secrets given as options never reach an output."""

from __future__ import annotations

import pytest

from sgtool.redact import REDACTED, is_secret_name, redact_options, redact_text, secret_values


@pytest.mark.parametrize("name", ["api_key", "API_KEY", "apiKey", "key", "token", "hf_token",
                                  "client_secret", "db.password", "passwd", "auth",
                                  "x-api-key"])
def test_secret_names(name):
    assert is_secret_name(name)


@pytest.mark.parametrize("name", ["model", "base_url", "timeout_s", "max_tokens", "monkey",
                                  "keyboard", "replay", "transcript"])
def test_ordinary_names(name):
    assert not is_secret_name(name)


def test_options_are_redacted_at_any_depth_and_not_changed_in_place():
    opts = {"moma-llm": {"api_key": "sk-1", "model": "m", "nested": [{"token": "t-2"}]},
            "scout": {"delta": 0.2}}
    out = redact_options(opts)
    assert out == {"moma-llm": {"api_key": REDACTED, "model": "m",
                                "nested": [{"token": REDACTED}]},
                   "scout": {"delta": 0.2}}
    assert opts["moma-llm"]["api_key"] == "sk-1"
    assert secret_values(opts) == ["sk-1", "t-2"]


def test_url_passwords_in_option_values_are_redacted():
    """A password in a base URL reached summary.json and the episode records (a review
    helper's "http://labuser:SECRETPW@host/v1")."""
    from sgtool.recorders.sim.episode_extras import recorded_options

    opts = {"base_url": "http://labuser:SECRETPW@127.0.0.1:8080/v1", "model": "m"}
    assert redact_options(opts)["base_url"] == f"http://labuser:{REDACTED}@127.0.0.1:8080/v1"
    assert "SECRETPW" not in str(recorded_options(opts))
    assert redact_options({"base_url": "http://127.0.0.1:8080/v1"}) == \
        {"base_url": "http://127.0.0.1:8080/v1"}


def test_text_loses_known_secrets_and_url_passwords():
    text = "sgtool bench -O moma-llm.api_key=sk-abcdef -O x.base_url=http://u:hunter2@h:1/v1"
    assert redact_text(text, ["sk-abcdef", None, "ab"]) == (
        f"sgtool bench -O moma-llm.api_key={REDACTED} -O x.base_url=http://u:{REDACTED}@h:1/v1")


def test_secret_assignments_in_messages_lose_their_values():
    text = "got 'api_key=sk-123' moma-llm.token=abc model=gpt max_tokens=5 PLANNER.KEY=VALUE"
    assert redact_text(text) == (f"got 'api_key={REDACTED}' moma-llm.token={REDACTED} "
                                 "model=gpt max_tokens=5 PLANNER.KEY=VALUE")


def test_a_user_error_never_echoes_a_secret():
    from click.testing import CliRunner

    from sgtool.cli import cli

    r = CliRunner().invoke(cli, ["bench", "--planners", "random", "-O", "api_key=sk-LEAK99"])
    assert r.exit_code == 2 and "sk-LEAK99" not in r.output and REDACTED in r.output


def test_list_options_are_recorded_as_the_o_text_that_gives_them():
    """A run's settings keep option values as text; a list's is what -O takes (so the
    text parses back to the same value: an explicit default compares equal to none)."""
    from sgtool.redact import options_as_text

    assert options_as_text({"p": {"w": (0.3, 0.7), "names": ["a", "b"], "on": True}}) == {
        "p": {"names": "a,b", "on": "True", "w": "0.3,0.7"}}
