"""Shared test helpers: where the third-party data lives, small synthetic frames."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]


def shared_data() -> Path:
    """``../shared/data`` beside the repository (override with SGTOOL_SHARED_DATA)."""
    env = os.environ.get("SGTOOL_SHARED_DATA")
    return Path(env) if env else REPO.parent / "shared" / "data"


@pytest.fixture
def shared_data_dir() -> Path:
    d = shared_data()
    if not d.is_dir():
        pytest.skip(f"third-party data folder {d} is absent (a fresh clone has no ../shared)")
    return d


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """``ci_only`` tests (minutes of retraining) run where ``CI`` is set, as ``.ci/run`` is;
    set ``CI=1`` to run them by hand."""
    if os.environ.get("CI"):
        return
    skip = pytest.mark.skip(reason="ci_only: runs in CI (set CI=1 to run here)")
    for item in items:
        if "ci_only" in item.keywords:
            item.add_marker(skip)
