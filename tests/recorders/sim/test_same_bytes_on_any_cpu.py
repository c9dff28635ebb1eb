"""A recording's bytes do not depend on which CPU kernels OpenBLAS picks: pose products
are summed in a fixed order in plain floats (``sgtool.log.codec.compose``), not by a
BLAS product whose last bits differ by kernel (``OPENBLAS_CORETYPE`` picks another
machine's; the logs of a CI runner, a Ray node and a laptop differed in /tf)."""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from sgtool.log.codec import compose, relative


def test_compose_and_relative_are_the_products() -> None:
    rng = np.random.default_rng(0)
    for _ in range(20):
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        a = np.eye(4)
        a[:3, :3], a[:3, 3] = q, rng.normal(size=3)
        b = rng.normal(size=(4, 4))
        assert np.allclose(compose(a, b), a @ b, rtol=0, atol=1e-12)
        assert np.allclose(relative(a, b), np.linalg.inv(a) @ b, rtol=0, atol=1e-12)


def _record(out: Path, coretype: str | None) -> str:
    env = {**os.environ, "HF_HUB_OFFLINE": "1", "TRANSFORMERS_OFFLINE": "1"}
    env.pop("OPENBLAS_CORETYPE", None)
    if coretype:
        env["OPENBLAS_CORETYPE"] = coretype
    r = subprocess.run([sys.executable, "-m", "sgtool.cli", "record", "--seed", "3",
                        "--rooms", "4-4", "--resolution", "32x24", "--frames", "60",
                        "--noise", "mild", "--quiet", "-o", str(out)],
                       env=env, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    return hashlib.sha256(out.read_bytes()).hexdigest()


@pytest.mark.skipif(sys.platform != "linux", reason="OPENBLAS_CORETYPE is OpenBLAS on Linux")
def test_a_recording_is_the_same_bytes_with_another_cpus_kernels(tmp_path: Path) -> None:
    mine = _record(tmp_path / "a.mcap", None)
    assert _record(tmp_path / "b.mcap", "Sandybridge") == mine
