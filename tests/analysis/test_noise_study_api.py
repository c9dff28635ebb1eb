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
    assert len(default.conditions) == 1 + 15 + 2  # 15 levels of 7 factors


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"factors": {"blur": [0.1]}}, "'blur' is not a noise factor"),
    ({"factors": {"holes": "0.1"}}, "factors['holes']: a list of numbers"),
    ({"factors": {"holes": None}}, "factors['holes']: a list of numbers"),
    ({"factors": {"holes": [-0.1]}}, "factors['holes']: level -0.1"),
    ({"factors": {"label_swap": [2.0]}}, "a probability, at most 1"),
    ({"factors": "holes"}, "factors='holes': a mapping"),
    ({"profiles": ["loud"]}, "profiles: 'loud': unknown profile"),
    ({"profiles": 5}, "profiles=5: a profile name"),
    ({"camera": (8, 8)}, "camera=8: a whole number >= 16"),
    ({"camera": "160x120"}, "camera='160x120': give two whole numbers"),
    ({"camera": (96.7, 72)}, "camera=96.7"),
    ({"rooms": (5, 3)}, "rooms=(5, 3): need 4 <= MIN <= MAX"),
    ({"rooms": "4-5"}, "rooms='4-5': give two whole numbers"),
    ({"frames": 0}, "frames=0: a whole number >= 1"),
    ({"frames": 2.5}, "frames=2.5"),
    ({"fps": "4"}, "fps='4': a number"),
    ({"noise_seed": -1}, "noise_seed=-1"),
    ({"house_files": 5}, "house_files=5: a path or a list of paths"),
])
def test_a_bad_config_value_is_one_line(kwargs: dict, message: str) -> None:
    with pytest.raises(sgtool.SgtoolError) as e:
        sgtool.noise_study_config(1, **kwargs)
    assert message in str(e.value) and "\n" not in str(e.value)


@pytest.mark.parametrize("houses", [-1, True, 2.0])
def test_houses_is_a_count(houses: object) -> None:
    with pytest.raises(sgtool.SgtoolError, match="houses="):
        sgtool.noise_study_config(houses)  # type: ignore[arg-type]


def test_one_house_file_is_a_path_not_a_list_of_characters(tmp_path: Path) -> None:
    missing = tmp_path / "mine.json"
    with pytest.raises(sgtool.SgtoolError) as e:
        sgtool.noise_study_config(0, house_files=str(missing))
    assert str(missing) in str(e.value) and "\n" not in str(e.value)


def test_run_refuses_bad_workers_and_a_file_as_cache(tmp_path: Path) -> None:
    cfg = sgtool.noise_study_config(1, factors={"holes": [0.01]})
    with pytest.raises(sgtool.SgtoolError, match="workers=0"):
        sgtool.run_noise_study(cfg, tmp_path, workers=0)
    file = tmp_path / "cache.txt"
    file.write_text("x")
    with pytest.raises(sgtool.SgtoolError, match="is a file, not a folder"):
        sgtool.run_noise_study(cfg, file)
    assert file.read_text() == "x"
