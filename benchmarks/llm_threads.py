"""Local llama.cpp server speed at 1 vs 2 threads: tokens/s and seconds per MoMa-LLM decision.

Run by hand: ``.venv/bin/python benchmarks/llm_threads.py [--model GGUF] [--rounds 2]
[--json PATH]``. Each round starts a server with 1 thread and one with 2, the order reversed
every other round (:func:`harness.round_order`, so both see the same machine load), and
measures per server: its start-up (wall seconds, :func:`harness.timed`), ``--speed`` plain
requests of 48 tokens (tokens/s) and ``--decisions`` constrained decisions (grammar) on the
first graphs of generated house 0's episodes. Prints the medians per thread count and their ratio;
``--json PATH`` writes them and every figure as JSON.
"""

from __future__ import annotations

import argparse
import contextlib
import statistics

from harness import add_output_options, emit, round_order, timed

from sgtool.datasets.episodes import list_episodes
from sgtool.datasets.generator import generate_house
from sgtool.llm.check import decision_check, generation_speed
from sgtool.llm.client import LlmSettings, OpenAIChatClient
from sgtool.llm.server import start_server
from sgtool.recorders.symbolic_environment import SymbolicEnv, SymbolicHouse


def scenes(n: int) -> list[tuple[object, str]]:
    spec = generate_house(0, rooms=(4, 8))
    house = SymbolicHouse(spec)
    out = []
    for ep in list_episodes(spec, n=n, seed=0):
        env = SymbolicEnv(house, ep.query, avoid_rooms=ep.target_rooms)
        out.append((env.observe(), ep.query))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--model", default=None)
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--speed", type=int, default=2)
    ap.add_argument("--decisions", type=int, default=3)
    ap.add_argument("--reason-chars", type=int, default=16)
    add_output_options(ap)
    args = ap.parse_args()
    graphs = scenes(args.decisions)
    tps: dict[int, list[float]] = {1: [], 2: []}
    dec: dict[int, list[float]] = {1: [], 2: []}
    parsed: dict[int, list[bool]] = {1: [], 2: []}
    ups: dict[int, list[float]] = {1: [], 2: []}
    for r in range(args.rounds):
        for threads in (int(t) for t in round_order(["1", "2"], r)):
            with contextlib.ExitStack() as stack:
                server, started = timed(lambda n=threads: stack.enter_context(
                    start_server(args.model, threads=n)))
                up = started.wall_s
                ups[threads].append(up)
                settings = LlmSettings.resolve(base_url=server.base_url, model=server.alias,
                                               timeout_s=600.0, temperature=0.0,
                                               max_tokens=48)
                client = OpenAIChatClient(settings)
                for _ in range(args.speed):
                    s = generation_speed(client, timeout_s=600.0)
                    if s.tokens_per_s is not None:
                        tps[threads].append(s.tokens_per_s)
                        print(f"threads {threads}: {s.tokens_per_s:.1f} tokens/s", flush=True)
                decider = OpenAIChatClient(LlmSettings.resolve(
                    base_url=server.base_url, model=server.alias, timeout_s=600.0,
                    temperature=0.0, max_tokens=2 * args.reason_chars + 60))
                for graph, query in graphs:
                    d = decision_check(decider, graph, query, constraint="grammar",
                                       timeout_s=600.0, reason_chars=args.reason_chars)
                    dec[threads].append(d.decision_s)
                    parsed[threads].append(d.parsed)
                    print(f"threads {threads}: decision {d.decision_s:.1f} s, "
                          f"{'parsed' if d.parsed else 'not parsed'}", flush=True)
            print(f"threads {threads}: server up in {up:.1f} s; tokens/s so far "
                  f"{[round(x, 1) for x in tps[threads]]}; s/decision "
                  f"{[round(x, 1) for x in dec[threads]]}", flush=True)
    for t in (1, 2):
        print(f"threads {t}: median {statistics.median(tps[t]):.1f} tokens/s over "
              f"{len(tps[t])} requests; median {statistics.median(dec[t]):.1f} s/decision over "
              f"{len(dec[t])} decisions; parsed {sum(parsed[t])}/{len(parsed[t])}")
    r_tps = statistics.median(tps[2]) / statistics.median(tps[1])
    r_dec = statistics.median(dec[2]) / statistics.median(dec[1])
    print(f"ratio 2/1 threads: tokens/s x{r_tps:.2f}, s/decision x{r_dec:.2f}")
    emit({"threads": {str(t): {"tokens_per_s": tps[t], "decision_s": dec[t],
                               "parsed": parsed[t], "server_up_s": ups[t],
                               "tokens_per_s_median": statistics.median(tps[t]),
                               "decision_s_median": statistics.median(dec[t])}
                      for t in (1, 2)},
          "ratio_tokens_per_s": r_tps, "ratio_decision_s": r_dec}, args.json_out)


if __name__ == "__main__":
    main()
