"""SCOUT's procedural LLM knowledge generation (sec. IV-C, Eq. 5), optional, cached, resumable.

When an OpenAI-compatible endpoint is configured, the relational sets can come from an LLM
as in SCOUT instead of the offline BEHAVIOR-1K knowledge:

1. Household -> Rooms: one prompt lists room categories R;
2. Rooms -> Categories: per room r, object categories C(r);
3. Categories -> Objects: per (r, c), objects O(r, c); O_household is their union (Eq. 5).
   Every prompt can run ``runs`` times (different wording index) for diversity; outputs are
   lowercased, underscores/hyphens to spaces, singularised, de-duplicated;
4. labelling: per object q, a score in [0, 1] for every room of R (containment, D_contain)
   and a list of objects with 1/0 labels (co-occurrence, D_co-occur).

Every answer is cached in ``cache_dir/exchanges.jsonl`` keyed by the prompt, so an
interrupted run resumes where it stopped and a finished run is reproducible offline (the
cache then answers every prompt). Answers must be JSON (an array or an object, possibly in
a code fence); an unparseable answer is asked again once with a reminder, then skipped and
counted. Transport faults are retried ``max_attempts`` times, then the run stops with a
message saying that rerunning resumes it.
"""

from __future__ import annotations

import json
import logging
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from sgtool.errors import SgtoolError
from sgtool.llm.client import DEFAULT_TIMEOUT_S, ChatClient, LlmTransportError, complete_within
from sgtool.llm.constraints import Constraint
from sgtool.llm.exchange import exchange_record, prompt_key
from sgtool.llm.recorded import TranscriptWriter, read_transcript
from sgtool.semantics.relational_set import RelationalSet, table_to_set
from sgtool.semantics.text import category_text

log = logging.getLogger(__name__)

SYSTEM = ("You are an expert on everyday households. Answer only with JSON, no prose, "
          "no explanations.")


class GenerationError(SgtoolError):
    """The LLM generation cannot continue (endpoint down); rerunning resumes it."""


def singularize(name: str) -> str:
    """Last word to singular ("coffee mugs" -> "coffee mug"), conservative."""
    head, _, last = name.rpartition(" ")
    if len(last) > 4 and last.endswith("ies"):
        last = last[:-3] + "y"
    elif len(last) > 4 and last.endswith(("ches", "shes", "sses", "xes")):
        last = last[:-2]
    elif len(last) > 3 and last.endswith("s") and not last.endswith(("ss", "us", "is")):
        last = last[:-1]
    return f"{head} {last}" if head else last


def normalize_name(name: str) -> str:
    return singularize(category_text(str(name)))


def extract_json(text: str) -> Any:
    """The first JSON array or object in ``text`` (code fences allowed); ValueError if none."""
    fenced = re.search(r"```(?:json)?\s*(.*?)```", text, re.S)
    if fenced:
        text = fenced.group(1)
    for opener, closer in (("[", "]"), ("{", "}")):
        start = text.find(opener)
        end = text.rfind(closer)
        if start != -1 and end > start:
            try:
                return json.loads(text[start : end + 1])
            except json.JSONDecodeError:
                continue
    raise ValueError("no JSON array or object in the answer")


@dataclass
class GenerationStats:
    prompts: int = 0
    cached: int = 0
    requested: int = 0
    skipped: int = 0
    skipped_prompts: list[str] = field(default_factory=list)


class CachedAsker:
    """Ask a prompt once; answers live in a JSONL cache keyed by the prompt hash."""

    def __init__(self, client: ChatClient | None, cache_dir: str | Path,
                 max_attempts: int = 3) -> None:
        self.client = client
        self.cache_dir = Path(cache_dir)
        self.cache_dir.mkdir(parents=True, exist_ok=True)
        self.path = self.cache_dir / "exchanges.jsonl"
        self.answers: dict[str, str] = {}
        if self.path.is_file():
            for rec in read_transcript(self.path):
                if rec.get("response") is not None and not rec.get("error"):
                    self.answers[rec["prompt_sha256"]] = rec["response"]
        self.max_attempts = max_attempts
        settings = getattr(client, "settings", None)
        self.timeout_s = float(getattr(settings, "timeout_s", DEFAULT_TIMEOUT_S))
        self.stats = GenerationStats()
        self._writer: TranscriptWriter | None = None

    def _messages(self, prompt: str) -> list[dict[str, str]]:
        return [{"role": "system", "content": SYSTEM}, {"role": "user", "content": prompt}]

    def _ask(self, messages: list[dict[str, str]], json_object: bool = False) -> str:
        key = prompt_key(messages)
        if key in self.answers:
            self.stats.cached += 1
            return self.answers[key]
        if self.client is None:
            raise GenerationError(
                f"no LLM endpoint configured and {self.path} has no answer for a prompt; "
                "configure an endpoint to continue the generation"
            )
        if self._writer is None:
            self._writer = TranscriptWriter(self.path, append=True)
        last = ""
        # JSON mode forces an object: only for prompts that ask for one (an array answer
        # would be impossible under it; SmolLM2 then invents objects of its own shape)
        json_mode = Constraint("json_object", ()) \
            if json_object and getattr(self.client, "takes_constraint", False) else None
        for attempt in range(self.max_attempts):
            try:
                res = complete_within(self.client, messages, self.timeout_s, json_mode)
            except LlmTransportError as e:
                last = str(e)
                self._writer.write(exchange_record(
                    model=self.client.model, messages=messages, response=None, latency_s=0.0,
                    error=last, attempt=attempt, source="generation"))
                continue
            self.stats.requested += 1
            self._writer.write(exchange_record(
                model=res.model, messages=messages, response=res.text, latency_s=res.latency_s,
                prompt_tokens=res.prompt_tokens, completion_tokens=res.completion_tokens,
                attempt=attempt, source="generation"))
            self.answers[key] = res.text
            return res.text
        raise GenerationError(
            f"LLM generation stopped: {last}; answers so far are cached in {self.path}, "
            "rerun the same command to resume"
        )

    def ask_json(self, prompt: str, check: Callable[[Any], bool], json_object: bool = False
                 ) -> Any | None:
        """Parsed JSON answer satisfying ``check``; one reminder on a bad answer, then None.
        ``json_object``: the answer is a JSON object, so JSON mode may be requested."""
        self.stats.prompts += 1
        messages = self._messages(prompt)
        for reminder in (False, True):
            if reminder:
                messages = self._messages(
                    prompt + "\nYour previous answer was not valid JSON of the requested "
                    "shape. Answer with the JSON only.")
            text = self._ask(messages, json_object)
            try:
                data = extract_json(text)
            except ValueError:
                continue
            if check(data):
                return data
        self.stats.skipped += 1
        self.stats.skipped_prompts.append(prompt[:80])
        log.warning("skipped a prompt with unusable answers: %s", prompt[:80])
        return None

    def close(self) -> None:
        if self._writer is not None:
            self._writer.close()


def _str_list(x: Any) -> bool:
    return isinstance(x, list) and all(isinstance(i, str) for i in x)


def _names(items: list[str], limit: int) -> list[str]:
    out: list[str] = []
    for it in items:
        n = normalize_name(it)
        if n and n not in out and len(n) <= 60:
            out.append(n)
    return out[:limit]


@dataclass(frozen=True)
class GenerationConfig:
    runs: int = 1  # repetitions of each generation prompt (SCOUT: for diversity)
    max_rooms: int = 12
    max_categories: int = 8  # per room
    max_objects: int = 10  # per (room, category)
    max_queries: int | None = None  # label at most this many objects (sorted), None = all
    cooccurrence_per_label: int = 5  # asked-for positives and negatives per query


def generate_sets(asker: CachedAsker, cfg: GenerationConfig = GenerationConfig(),
                  progress: bool = False
                  ) -> tuple[RelationalSet, RelationalSet, tuple[str, ...]]:
    """(containment set, co-occurrence set, room types) from the LLM (module doc)."""
    rooms: list[str] = []
    for k in range(cfg.runs):
        data = asker.ask_json(
            f"List the {cfg.max_rooms} most common room categories of a household, as a JSON "
            f"array of short lowercase names (list {k + 1}).", _str_list)
        for r in _names(data or [], cfg.max_rooms):
            if r not in rooms:
                rooms.append(r)
    rooms = sorted(rooms)[: cfg.max_rooms]
    if not rooms:
        raise GenerationError("the LLM gave no usable room list")
    objects: set[str] = set()
    for room in rooms:
        cats: list[str] = []
        for k in range(cfg.runs):
            data = asker.ask_json(
                f"List {cfg.max_categories} categories of objects found in a {room} (for "
                f"example appliances, furniture, tools), as a JSON array of short lowercase "
                f"names (list {k + 1}).", _str_list)
            cats += [c for c in _names(data or [], cfg.max_categories) if c not in cats]
        for cat in sorted(cats)[: cfg.max_categories]:
            for k in range(cfg.runs):
                data = asker.ask_json(
                    f"List {cfg.max_objects} different {cat} found in a {room}, as a JSON "
                    f"array of object names, lowercase, singular (list {k + 1}).", _str_list)
                objects.update(_names(data or [], cfg.max_objects))
    queries = sorted(objects)
    if cfg.max_queries is not None:
        queries = queries[: cfg.max_queries]
    it = queries
    if progress:
        from tqdm import tqdm

        it = tqdm(queries, desc="label objects", unit="object")
    cont: dict[tuple[str, str], float] = {}
    cooc: dict[tuple[str, str], float] = {}
    room_list = ", ".join(rooms)
    n = cfg.cooccurrence_per_label
    for q in it:
        data = asker.ask_json(
            f"For the object '{q}', give for each of these rooms the probability (0 to 1) "
            f"that it is found there: {room_list}. Answer with a JSON object mapping each "
            "room to its probability.", lambda d: isinstance(d, dict), json_object=True)
        if data:
            for r, v in data.items():
                rn = normalize_name(r)
                try:
                    p = float(v)
                except (TypeError, ValueError):
                    continue
                if rn in rooms and np.isfinite(p):
                    cont[(rn, q)] = float(min(max(p, 0.0), 1.0))
        data = asker.ask_json(
            f"List {n} objects that are usually found at the same place as a '{q}' in a "
            f"household (label 1) and {n} household objects that usually are not (label 0). "
            'Answer with a JSON array of {"object": name, "label": 1 or 0}.',
            lambda d: isinstance(d, list) and all(isinstance(i, dict) for i in d))
        for item in data or []:
            o = normalize_name(item.get("object", ""))
            lab = item.get("label")
            if o and o != q and lab in (0, 1, "0", "1", True, False):
                cooc[(o, q)] = float(int(lab))
    asker.close()
    if not cont or not cooc:
        raise GenerationError("the LLM answers gave no containment or no co-occurrence pairs")
    return table_to_set("containment", cont), table_to_set("cooccurrence", cooc), tuple(rooms)


@dataclass(frozen=True)
class Agreement:
    """How an LLM's relational set agrees with a reference set (BEHAVIOR-1K) on the pairs
    both hold (node and query compared as words)."""

    relation: str
    common: int  # pairs in both sets
    agree: int  # same side of the threshold: LLM >= 0.5 vs reference > 0
    llm_pairs: int

    @property
    def rate(self) -> float:
        return self.agree / self.common if self.common else float("nan")


def agreement(llm: RelationalSet, reference: RelationalSet) -> Agreement:
    """:class:`Agreement` of two :class:`~sgtool.semantics.relational_set.RelationalSet`."""
    ref: dict[tuple[str, str], float] = {}
    for (i, j), t in zip(reference.pairs.tolist(), reference.targets.tolist(), strict=True):
        ref[(normalize_name(reference.nodes[i]), normalize_name(reference.queries[j]))] = t
    common = agree = 0
    for (i, j), t in zip(llm.pairs.tolist(), llm.targets.tolist(), strict=True):
        r = ref.get((normalize_name(llm.nodes[i]), normalize_name(llm.queries[j])))
        if r is None:
            continue
        common += 1
        agree += int((t >= 0.5) == (r > 0))
    return Agreement(llm.relation, common, agree, len(llm.targets))
