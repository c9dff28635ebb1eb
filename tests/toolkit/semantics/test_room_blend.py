"""The room blend: neighbour knowledge, novelty weight, fitting on held-out names, loading."""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pytest

from sgtool.errors import SgtoolError
from sgtool.semantics.room_blend import (
    BLEND_FILE,
    VECTORS_FILE,
    HeldOutName,
    RoomBlend,
    RoomBlendParams,
    blend_scores,
    fit_room_blend,
    load_room_blend,
    save_room_blend,
)


class AxisEncoder:
    """Texts to unit vectors on three axes: bathroom things, kitchen things, a third
    direction; the room names lie between their things and the third axis."""

    AXES = {
        "soap": [1.0, 0.0, 0.0], "towel": [0.8, 0.0, 0.6], "sponge": [0.6, 0.8, 0.0],
        "pan": [0.0, 1.0, 0.0], "pot": [0.0, 0.8, 0.6], "tractor": [0.0, 0.0, 1.0],
        "bathroom": [0.6, 0.0, 0.8], "kitchen": [0.0, 0.6, 0.8],
    }

    def encode(self, texts: Sequence[str]) -> np.ndarray:
        return np.array([self.AXES[t] for t in texts], dtype=np.float32)


TABLE = {"bathroom": ["soap"], "kitchen": ["pan"]}
ROOMS = ["bathroom", "kitchen"]


def test_blend_scores_by_hand() -> None:
    p = RoomBlendParams(neighbours=1, cos_weight=0.5, low=0.0, high=1.0, novelty_lo=0.5,
                        novelty_hi=1.0, lambda_max=1.0)
    nb, cos = np.array([0.9, 0.3]), np.array([0.6, 0.0])
    learned = np.array([0.2, 0.8])
    # knowledge x = (nb + 0.5 cos) / 1.5 = (0.8, 0.2); sim 0.75 -> lambda 0.5
    out = blend_scores(p, nb, cos, 0.75, learned)
    assert out == pytest.approx([0.5 * 0.2 + 0.5 * 0.8, 0.5 * 0.8 + 0.5 * 0.2])
    assert blend_scores(p, nb, cos, 1.0, learned) == pytest.approx(learned)  # a known name
    assert blend_scores(p, nb, cos, 0.2, learned) == pytest.approx([0.8, 0.2])  # a new one
    capped = RoomBlendParams(**{**p.__dict__, "lambda_max": 0.5})
    assert blend_scores(capped, nb, cos, 1.0, learned) == pytest.approx(
        0.5 * learned + 0.5 * np.array([0.8, 0.2]))


def test_room_blend_leans_on_neighbours_for_a_new_name() -> None:
    p = RoomBlendParams(neighbours=1, cos_weight=0.0, low=0.0, high=1.0, novelty_lo=0.9,
                        novelty_hi=1.0, lambda_max=1.0)
    b = RoomBlend(TABLE, ["soap", "pan"], p, AxisEncoder())
    nb, cos, sim = b.parts(ROOMS, "sponge")
    assert nb == pytest.approx([0.6, 0.8]) and sim == pytest.approx(0.8)
    assert cos == pytest.approx([0.36, 0.48])
    # sim 0.8 < 0.9: the learned model (which says bathroom) has no say
    assert b.blend(ROOMS, "sponge", np.array([1.0, 0.0])) == pytest.approx([0.6, 0.8])
    # a training name keeps its learned scores
    assert b.blend(ROOMS, "soap", np.array([0.3, 0.1])) == pytest.approx([0.3, 0.1])
    # a room type without table names has neighbour score 0
    assert b.parts(["bathroom", "tractor"], "towel")[0] == pytest.approx([0.8, 0.0])


def test_fit_picks_the_grid_point_that_gets_held_out_names_right(monkeypatch) -> None:
    import sgtool.semantics.room_blend as rb

    monkeypatch.setattr(rb, "PARAM_GRID", {
        "neighbours": (1,), "cos_weight": (0.0,), "low": (0.0,), "high": (1.0,),
        "novelty_lo": (0.5,), "novelty_hi": (1.0,), "lambda_max": (1.0, 0.0)})

    def learned(rooms: Sequence[str], query: str) -> np.ndarray:
        return np.array([1.0, 0.0])  # always the bathroom: wrong for the kitchen things

    held = [HeldOutName("pot", frozenset({"kitchen"})), HeldOutName("towel",
                                                                    frozenset({"bathroom"}))]
    params, acc = fit_room_blend(TABLE, ["soap", "pan"], held, ROOMS, learned, AxisEncoder())
    # pot: sim 0.8 -> lambda 0.6 (lambda_max 1): 0.6 * (1, 0) + 0.4 * (0, 0.8) = bathroom;
    # lambda_max 0: neighbours only -> kitchen; towel is right either way
    assert params.lambda_max == 0.0 and acc == 1.0
    with pytest.raises(ValueError):
        fit_room_blend(TABLE, ["soap"], [], ROOMS, learned, AxisEncoder())


def test_save_and_load_room_blend(tmp_path) -> None:
    enc = AxisEncoder()
    assert load_room_blend(tmp_path, enc) is None  # a folder without a blend
    b = RoomBlend(TABLE, ["soap", "pan"], RoomBlendParams(neighbours=3), enc)
    save_room_blend(tmp_path, b, {"fit": {"blend_top1": 0.5}})
    first = (tmp_path / BLEND_FILE).read_bytes(), (tmp_path / VECTORS_FILE).read_bytes()
    save_room_blend(tmp_path, b, {"fit": {"blend_top1": 0.5}})
    assert ((tmp_path / BLEND_FILE).read_bytes(), (tmp_path / VECTORS_FILE).read_bytes()) \
        == first  # byte-stable
    back = load_room_blend(tmp_path, enc)
    assert back is not None and back.params == b.params and back.table == b.table
    # the known names' vectors come from the file: an encoder that knows only the query
    # and room names is enough

    class QueryOnly(AxisEncoder):
        def encode(self, texts: Sequence[str]) -> np.ndarray:
            assert not {"soap", "pan"} & set(texts)
            return super().encode(texts)

    saved = load_room_blend(tmp_path, QueryOnly())
    assert saved is not None
    assert saved.parts(ROOMS, "towel")[0] == pytest.approx([0.8, 0.0])
    with pytest.raises(ValueError, match="outside the training names"):
        RoomBlend({"kitchen": ["pot"]}, ["pan"], RoomBlendParams(), enc)
    with pytest.raises(ValueError, match="vectors for"):
        RoomBlend(TABLE, ["soap", "pan"], RoomBlendParams(), enc, np.zeros((1, 3)))
    (tmp_path / VECTORS_FILE).write_bytes(b"not an array")  # the file at fault is named
    with pytest.raises(SgtoolError, match=f"{VECTORS_FILE}: not the room blend's name vectors"):
        load_room_blend(tmp_path, enc)
    (tmp_path / VECTORS_FILE).unlink()
    (tmp_path / BLEND_FILE).write_text('{"params": {"neighbours": 0}}')
    with pytest.raises(SgtoolError, match="not a room blend"):
        load_room_blend(tmp_path, enc)


def test_params_are_checked() -> None:
    with pytest.raises(ValueError):
        RoomBlendParams(high=0.1, low=0.2)
    with pytest.raises(ValueError):
        RoomBlendParams(lambda_max=1.5)


def test_the_shipped_blend_weights_load_and_the_default_ones_stay_unblended() -> None:
    from support.semantics_fixtures import encoder

    from sgtool.semantics.priors import BLEND_WEIGHTS_DIR, LearnedPriors

    enc = encoder()
    assert LearnedPriors(enc).room_blend is None  # the baselines' priors are unchanged
    blended = LearnedPriors(enc, "blend")  # the name `--priors blend` gives
    assert blended.weights_dir == BLEND_WEIGHTS_DIR and blended.room_blend is not None
    doc = json.loads((BLEND_WEIGHTS_DIR / BLEND_FILE).read_text())
    fit = doc["fit"]  # fitted on names held out of a second training
    assert fit["heldout_names"] > 100 and fit["blend_top1"] >= fit["learned_top1"]
    rooms = ["bathroom", "kitchen", "living_room", "bedroom"]
    # the ProcTHOR annotations put a soap bar in the bathroom and an alarm clock in a bedroom
    for query, room in (("soap bar", "bathroom"), ("alarm clock", "bedroom"),
                        ("frying pan", "kitchen")):
        s = blended.rooms(rooms, query)
        assert rooms[int(np.argmax(s))] == room, (query, s)
        assert 0.0 <= s.min() and s.max() <= 1.0


def test_named_weights_resolve_unless_a_folder_of_that_name_exists(tmp_path,
                                                                  monkeypatch) -> None:
    from sgtool.semantics.priors import BLEND_WEIGHTS_DIR, WEIGHTS_DIR, weights_folder

    assert weights_folder(None) == WEIGHTS_DIR == weights_folder("shipped")
    assert weights_folder("blend") == BLEND_WEIGHTS_DIR
    assert weights_folder(tmp_path) == tmp_path
    monkeypatch.chdir(tmp_path)
    (tmp_path / "blend").mkdir()  # a user's own folder called blend wins over the name
    assert weights_folder("blend") == Path("blend")


def test_a_tie_at_the_top_is_a_shared_hit() -> None:
    from sgtool.semantics.room_blend import tied_hit

    best = np.array([False, True, False])
    assert tied_hit(np.array([0.2, 0.9, 0.1]), best) == 1.0
    assert tied_hit(np.array([1.0, 1.0, 0.1]), best) == 0.5  # not a hit by list order
    assert tied_hit(np.array([1.0, 0.5, 0.1]), best) == 0.0


@pytest.mark.ci_only
def test_blend_weights_are_what_distill_writes(tmp_path) -> None:
    """`sgtool distill --room-blend` (two trainings and the fit, a few minutes) rebuilds
    the shipped blend weights: the same room table and training names (data, exact), the
    same held-out names, and the fit's accuracies within 0.03 (torch's last bits differ
    between processors, see test_distill's retrain check, so the grid's choice may too)."""
    from click.testing import CliRunner

    from sgtool.commands.distill import command
    from sgtool.semantics.priors import BLEND_WEIGHTS_DIR

    r = CliRunner().invoke(command, ["--room-blend", "--out", str(tmp_path)])
    assert r.exit_code == 0, r.output
    new = json.loads((tmp_path / BLEND_FILE).read_text())
    shipped = json.loads((BLEND_WEIGHTS_DIR / BLEND_FILE).read_text())
    assert new["table"] == shipped["table"]
    assert new["training_names"] == shipped["training_names"]
    assert new["fit"]["heldout_names"] == shipped["fit"]["heldout_names"]
    for key in ("learned_top1", "blend_top1", "cosine_top1"):
        assert abs(new["fit"][key] - shipped["fit"][key]) < 0.03, key
    assert np.load(tmp_path / VECTORS_FILE).shape == (len(shipped["training_names"]), 384)
