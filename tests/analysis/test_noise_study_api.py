"""The noise study's Python calls: the configuration from plain values and the one-line
errors of a caller's mistakes (the recording itself is covered by the API guide's test)."""

from __future__ import annotations

from pathlib import Path

import pytest

import sgtool


def test_the_config_lists_conditions_as_the_command_does() -> None:
    cfg = sgtool.noise_study_config(2, house_seed=5, rooms=(4, 6),
                                    factors={"holes": [0.08, 0.01, 0.08]}, profiles="strong",
                                    camera=(96, 72), fps=2.0, frames=30)
    assert [h.id for h in cfg.houses] == ["house-5", "house-6"]
    assert [c.noise for c in cfg.conditions] == ["none", "none,holes=0.01",
                                                 "none,holes=0.08", "strong"]
    assert cfg.rooms == (4, 6)
    s = cfg.settings
    assert (s.width, s.height, s.fps, s.frames) == (96, 72, 2.0, 30)
    # no factors given: the command's default levels and both profiles
    default = sgtool.noise_study_config(1)
    assert [c.noise for c in default.conditions][-2:] == ["mild", "strong"]
    assert len(default.conditions) == 1 + 13 + 2


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"factors": {"blur": [0.1]}}, "'blur' is not a noise factor"),
    ({"factors": {"holes": "0.1"}}, "factors['holes']: a list of levels"),
    ({"factors": {"holes": [-0.1]}}, "factors['holes']: a list of levels"),
    ({"profiles": ["loud"]}, "'loud': unknown profile"),
    ({"camera": (8, 8)}, "at least 16x16"),
    ({"frames": 0}, "must be >= 1"),
])
def test_a_bad_config_value_is_one_line(kwargs: dict, message: str) -> None:
    with pytest.raises(sgtool.SgtoolError) as e:
        sgtool.noise_study_config(1, **kwargs)
    assert message in str(e.value) and "\n" not in str(e.value)


@pytest.mark.parametrize("houses", [-1, True, 2.0])
def test_houses_is_a_count(houses: object) -> None:
    with pytest.raises(sgtool.SgtoolError, match="houses="):
        sgtool.noise_study_config(houses)  # type: ignore[arg-type]


def test_run_refuses_bad_workers_and_a_file_as_cache(tmp_path: Path) -> None:
    cfg = sgtool.noise_study_config(1, factors={"holes": [0.01]})
    with pytest.raises(sgtool.SgtoolError, match="workers=0"):
        sgtool.run_noise_study(cfg, tmp_path, workers=0)
    file = tmp_path / "cache.txt"
    file.write_text("x")
    with pytest.raises(sgtool.SgtoolError, match="is a file, not a folder"):
        sgtool.run_noise_study(cfg, file)
    assert file.read_text() == "x"
