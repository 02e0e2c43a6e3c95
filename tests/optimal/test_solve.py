"""``optimal.solve``: a multi-start's start solved in a worker process equals one solved here."""

from __future__ import annotations

from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context

import numpy as np
import pytest

pytest.importorskip("casadi")

from optimal.solve import _solve_start  # noqa: E402


def test_a_start_solved_in_a_worker_process_equals_one_solved_here() -> None:
    job = ("double_integrator", None, None, 1.0, False)
    here = _solve_start(*job)
    with ProcessPoolExecutor(1, mp_context=get_context("fork")) as pool:
        there = pool.submit(_solve_start, *job).result()
    assert here["converged"] and there["converged"]
    assert abs(here["final_time"] - 2.0) <= 1e-4  # bang-bang, T = 2 sqrt(d / a)
    assert there["cost"] == pytest.approx(here["cost"], rel=1e-9)
    np.testing.assert_allclose(there["arrays"]["tau"], here["arrays"]["tau"], atol=1e-7)
    assert len(there["history"]) == len(here["history"]) >= 1
