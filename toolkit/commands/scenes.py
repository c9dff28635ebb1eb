"""``sgtool scenes``: generate houses, check house files, draw them, summarise them, list
search episodes."""

from __future__ import annotations

import math
import sys
from typing import Any

import click

from sgtool.canonical import json_text
from sgtool.commands.options import SEED, FiniteFloatRange, PathParam
from sgtool.errors import SgtoolError


def _parse_rooms(value: str) -> tuple[int, int]:
    from sgtool.commands.options import parse_rooms

    return parse_rooms(value)


def _rooms_option(f):  # type: ignore[no-untyped-def]
    return click.option(
        "--rooms", default="4-12", show_default=True, metavar="MIN-MAX",
        callback=lambda ctx, p, v: _parse_rooms(v),
        help="Range of the number of rooms, corridors included, 4..30 (or one "
        "number).")(f)


def _split_option(f):  # type: ignore[no-untyped-def]
    return click.option(
        "--split", type=click.Choice(["eval", "train"]), default="eval", show_default=True,
        help="Knowledge that furnishes the house: 'eval' for benchmark houses, 'train' for "
             "houses built only from what planners may learn from.")(f)


def _preset_option(f):  # type: ignore[no-untyped-def]
    from sgtool.datasets.presets import PRESET_NAMES

    return click.option(
        "--preset", type=click.Choice(list(PRESET_NAMES)), default="default",
        show_default=True,
        help="Generator preset: 'default', or 'symsearch' for houses as dense as "
             "SymSearch's InteriorGS scenes with long-tail small objects.")(f)


@click.group("scenes")
def command() -> None:
    """Houses furnished from BEHAVIOR-1K knowledge (the `bddl` package, read offline):
    generate them from a seed, check house files of your own, draw their floor plans,
    summarise them in the columns of SCOUT's Table I, list object-search episodes."""


@command.command("generate")
@click.option("--seed", type=SEED, default=0, show_default=True,
              help="Random seed; the same seed gives the same bytes.")
@_rooms_option
@_split_option
@_preset_option
@click.option("-o", "--output", type=PathParam(dir_okay=False), required=True,
              help="House spec JSON to write (atomically).")
@click.option("--force", is_flag=True, help="Overwrite the output file.")
def generate_cmd(seed: int, rooms: tuple[int, int], split: str, preset: str, output: str,
                 force: bool) -> None:
    """Generate a connected multi-room house and write its JSON spec."""
    from sgtool.commands.options import check_output
    from sgtool.datasets.generator import generate_house
    from sgtool.house.io import save_house

    check_output(output, force=force, suffixes=(".json",), what="house spec")
    spec = generate_house(seed, rooms=rooms, split=split, preset=preset)
    save_house(spec, output)
    closed = sum(d.state == "closed" for d in spec.doors)
    inside = sum(o.relation == "inside" for o in spec.objects)
    click.echo(f"{output}: {len(spec.rooms)} rooms ({', '.join(r.category for r in spec.rooms)}), "
               f"{len(spec.doors)} doors ({closed} closed), {len(spec.passages)} passages, "
               f"{len(spec.furniture)} furniture, {len(spec.objects)} objects "
               f"({inside} inside)", err=True)


@command.command("check")
@click.argument("houses", nargs=-1, required=True, type=PathParam())
def check_cmd(houses: tuple[str, ...]) -> None:
    """Check house files (or folders of them) as `sgtool bench --house` does before it runs:
    the house spec (docs/house-format.md), small objects to search for, free floor for the
    robot, ids that can name log folders. One line per file: "ok FILE: id, counts" with
    notes (rooms no door leads into), or "error" and the problem; exit code 2 when any
    file fails."""
    from sgtool.analysis.bench_houses import check_house_files

    lines, ok = check_house_files(houses, emit=click.echo)  # each file's lines at once
    if not ok:
        raise SgtoolError(f"{sum(x.startswith('error') for x in lines)} problem(s) in the "
                          "house files above")


@command.command("show")
@click.argument("house", type=PathParam(dir_okay=False))
@click.option("-o", "--output", type=PathParam(dir_okay=False), default=None,
              help="Image to write (.png, .svg or .pdf) [default: HOUSE with .png].")
@click.option("--dpi", type=click.IntRange(min=30, max=600), default=120, show_default=True,
              help="Resolution of raster images.")
@click.option("--no-objects", is_flag=True, help="Leave small objects out of the picture.")
@click.option("--force", is_flag=True, help="Overwrite the image.")
def show_cmd(house: str, output: str | None, dpi: int, no_objects: bool, force: bool) -> None:
    """Draw the floor plan of HOUSE: rooms coloured and labelled, walls, doors (open green,
    closed red), open-plan passages, furniture (containers hatched), small objects (dots;
    crosses when hidden in a closed container), start poses."""
    from pathlib import Path

    from sgtool.commands.options import check_output
    from sgtool.datasets.draw import draw_house
    from sgtool.house.io import load_house

    spec = load_house(Path(house))  # a path, even one that starts with "{"
    out = check_output(output or Path(house).with_suffix(".png"), force=force,
                       suffixes=(".png", ".svg", ".pdf"), what="image")
    if Path(out).resolve() == Path(house).resolve():
        raise SgtoolError(f"{out}: the image would replace the house file it draws; give "
                          "-o another name")
    draw_house(spec, out, dpi=dpi, show_objects=not no_objects)
    click.echo(f"wrote {out}", err=True)


@command.command("stats")
@click.option("-n", "--houses", type=click.IntRange(min=1, max=1_000_000), default=20,
              show_default=True, help="Number of houses to generate (seeds SEED .. SEED+N-1).")
@click.option("--seed", type=SEED, default=0, show_default=True,
              help="First seed.")
@_rooms_option
@_split_option
@_preset_option
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object.")
def stats_cmd(houses: int, seed: int, rooms: tuple[int, int], split: str, preset: str,
              as_json: bool) -> None:
    """Table I of SCOUT for N generated houses, beside the real OmniGibson scenes of
    `bddl` (all, and homes only) and the rows printed in the paper."""
    from tqdm import tqdm

    from sgtool.datasets.generator import generate_house
    from sgtool.datasets.knowledge import load_knowledge
    from sgtool.datasets.scene_stats import (
        PAPER_TABLE_I,
        format_table,
        house_stats,
        inventory_stats,
    )

    specs = [generate_house(s, rooms=rooms, split=split, preset=preset)
             for s in tqdm(range(seed, seed + houses), desc="houses", unit="house",
                           disable=not sys.stderr.isatty(), file=sys.stderr)]
    ours = house_stats(specs)
    k = load_knowledge()
    rows = {
        f"sgtool {split} houses" + (f" ({preset})" if preset != "default" else ""):
            ours.to_dict(),
        "bddl scenes, all (measured)": inventory_stats(k).to_dict(),
        "bddl scenes, homes (measured)": inventory_stats(k, household_only=True).to_dict(),
        **PAPER_TABLE_I,
    }
    if as_json:
        click.echo(json_text({"rooms": list(rooms), "split": split, "preset": preset,
                               "first_seed": seed, "rows": rows}, indent=2, sort_keys=True))
        return
    click.echo(format_table(rows))
    click.echo(f"\nsgtool houses: {ours.furniture_per_scene:.1f} furniture, "
               f"{ours.contained_per_scene:.1f} small objects per house "
               f"({ours.inside_per_scene:.1f} inside, {ours.hidden_per_scene:.1f} hidden in "
               f"closed containers), {ours.closed_doors_per_scene:.1f} closed doors.")
    click.echo("Obj./Sc. = object instances, Obj. Cat./Sc. = distinct object categories per "
               "scene (the paper's 'Obj. Inst./Sc.' column); rows marked SCOUT are quoted "
               "from the paper, not measured here.")


def _episodes(spec: Any, count: int | None, seed: int, reach: float, preset: str
              ) -> list[Any]:
    """The episodes ``scenes episodes`` lists; a house without start poses gets those the
    bench and the closed loop add (with a note), so the lists agree."""
    from sgtool.datasets.episode_mix import symsearch_episodes
    from sgtool.datasets.episodes import list_episodes
    from sgtool.datasets.start_poses import with_start_poses
    from sgtool.semantics.text import category_text

    if not spec.starts and spec.objects:
        spec = with_start_poses(spec, spec.seed)
        click.echo("sgtool: note: the house has no start poses; those the bench and "
                   "`sgtool run` add are used", err=True)
    if preset == "symsearch":
        n = count or len({category_text(o.category) for o in spec.objects}) or \
            len(spec.furniture)
        return list(symsearch_episodes(spec, n, seed=seed, reach=reach))
    return list_episodes(spec, n=count, seed=seed, reach=reach)


@command.command("episodes")
@click.argument("house", type=PathParam(dir_okay=False))
@click.option("-n", "--count", type=click.IntRange(min=1), default=None,
              help="Number of episodes [default: one per object category].")
@click.option("--seed", type=SEED, default=None,
              help="Seed of the choice of categories and start poses [default: the house "
              "file's seed, the one `sgtool bench` and `run-bench` draw with].")
@click.option("--reach", type=FiniteFloatRange(min=0.3, max=100.0), default=1.0,
              show_default=True,
              help="A target counts as reached within this distance (m) of its parent (at "
              "least 0.3: the robot's centre stays 0.2 m from furniture; at most 100, a "
              "house's largest extent).")
@_preset_option
@click.option("--json", "as_json", is_flag=True, help="Print JSON (one list).")
def episodes_cmd(house: str, count: int | None, seed: int | None, reach: float, preset: str,
                 as_json: bool) -> None:
    """List object-search episodes of HOUSE: query category, target instances, start pose,
    whether every target is hidden in a closed container, and the shortest path (m) from
    the start to the nearest target on the house's occupancy grid (closed doors
    passable). With --preset symsearch, a third of the episodes ask for furniture (SymSearch's
    non-interactive targets); COUNT defaults to the number of small-object categories."""
    from pathlib import Path

    from sgtool.house.io import load_house

    spec = load_house(Path(house))  # a path, even one that starts with "{"
    eps = _episodes(spec, count, spec.seed if seed is None else seed, reach, preset)
    if as_json:
        click.echo(json_text([e.to_dict() for e in eps], indent=1, sort_keys=True))
        return
    if not eps:
        from sgtool.analysis.bench_houses import symbolic_house_problem

        if bad := symbolic_house_problem(spec, house):  # e.g. a room without free floor
            raise SgtoolError(bad)
        click.echo("no episodes: the house has no small objects")
        return
    w = max(len(e.query) for e in eps)
    click.echo(f"{'id':<6} {'query':<{w}}  {'start':>18}  {'hidden':<6} {'path m':>7}  "
               "targets / where")
    for e in eps:
        sp = f"{e.shortest_path:7.2f}" if math.isfinite(e.shortest_path) else "    inf"
        start = f"{e.start.room}({e.start.x:.1f},{e.start.y:.1f})"
        click.echo(f"{e.id:<6} {e.query:<{w}}  {start:>18}  {'yes' if e.hidden else 'no':<6} "
                   f"{sp}  {','.join(e.targets)}: {e.description}")
    hidden = sum(e.hidden for e in eps)
    click.echo(f"{len(eps)} episodes, {hidden} hidden in closed containers", err=True)


@command.command("knowledge")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object.")
def knowledge_cmd(as_json: bool) -> None:
    """Figures of the BEHAVIOR-1K knowledge read from `bddl` and of its train/eval split."""
    from sgtool.datasets.knowledge import load_knowledge, negated_relation_counts
    from sgtool.datasets.split import evaluation_knowledge, training_knowledge, unseen_queries

    def fig(k) -> dict:  # type: ignore[no-untyped-def]
        return {"scenes": len(k.scenes), "rooms": len(k.rooms),
                "room_types": len(k.room_type_counts), "activities": len(k.activities),
                "relations": k.relation_counts(), "triples": len(k.triples)}

    out: dict[str, Any] = {
        "all": fig(load_knowledge()), "train": fig(training_knowledge()),
        "eval": fig(evaluation_knowledge()), "negated_atoms_left_out": negated_relation_counts(),
        "unseen_queries": unseen_queries()}
    if as_json:
        click.echo(json_text(out, indent=2, sort_keys=True))
        return
    for part in ("all", "train", "eval"):
        f = out[part]
        r = f["relations"]
        click.echo(f"{part:>5}: {f['scenes']} scenes, {f['rooms']} rooms "
                   f"({f['room_types']} types), {f['activities']} activities, "
                   f"{r['inside']} inside / {r['ontop']} ontop / {r['inroom']} inroom atoms, "
                   f"{f['triples']} distinct triples")
    click.echo(f"left out (under 'not'): {out['negated_atoms_left_out']}")
    uq = out["unseen_queries"]
    click.echo(f"{len(uq)} unseen query categories (in eval houses, never in training): "
               + ", ".join(uq[:20]) + (", ..." if len(uq) > 20 else ""))
