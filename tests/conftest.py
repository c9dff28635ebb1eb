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
