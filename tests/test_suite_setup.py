"""The test session's own set-up (tests/conftest.py): one BLAS thread in effect, every test
that starts Ray in the one pytest-xdist unit of work, file units otherwise."""

from __future__ import annotations

import os
import re
from pathlib import Path

from conftest import RAY_STARTERS, xdist_scope

TESTS = Path(__file__).resolve().parent
REPO = TESTS.parent


def test_numpy_runs_with_the_blas_threads_the_session_sets() -> None:
    import numpy as np
    from threadpoolctl import threadpool_info

    np.ones((4, 4)) @ np.ones((4, 4))
    want = int(os.environ["OPENBLAS_NUM_THREADS"])
    openblas = [p for p in threadpool_info() if p["internal_api"] == "openblas"]
    assert openblas, threadpool_info()
    # conftest set it before numpy loaded its BLAS; a plug-in importing numpy first would not
    assert {p["num_threads"] for p in openblas} == {want}


def test_scope_is_the_file_or_ray() -> None:
    assert xdist_scope("tests/a/test_x.py::test_one[p1]") == "tests/a/test_x.py"
    assert xdist_scope("tests/a/test_x.py::Cls::test_two") == "tests/a/test_x.py"
    assert xdist_scope("tests/analysis/test_ray_executor.py::test_bench") == "ray"
    assert xdist_scope("tests/analysis/test_ray_cluster.py::test_resume") == "ray"
    assert xdist_scope("tests/test_benchmarks.py::test_script[benchmarks/ray_scale.py]") == "ray"
    assert xdist_scope("tests/test_benchmarks.py::test_script[benchmarks/replay.py]") == \
        "tests/test_benchmarks.py"


def test_every_test_that_starts_ray_is_a_ray_starter() -> None:
    """A renamed or new test module, or benchmark script, that starts Ray must join the
    ``ray`` unit (a test module calling ``ray.init``; a script run by test_benchmarks that
    starts Ray itself or through ``--executor ray``)."""
    starts = re.compile(r"ray\.init\(|executor=\"ray\"|\"--executor\", \"ray\"")
    modules = {p.relative_to(REPO).as_posix() + "::" for p in TESTS.rglob("test_*.py")
               if p.name != Path(__file__).name and "ray.init(" in p.read_text()}
    scripts = {f"[benchmarks/{p.name}]" for p in (REPO / "benchmarks").glob("*.py")
               if starts.search(p.read_text())}
    assert modules and scripts, "nothing starts Ray: the patterns above are stale"
    assert modules | scripts == set(RAY_STARTERS)
