"""All 11 Siconos FC2D peer problems solved to 1e-8, checked by the independent checker.

Dense methods (``lemke``, ``nsgs`` on a dense W) on the eight problems of at most 752 rows; the
sparse Newton (``newton_ac``, W read in CSR form) on every problem, the three granular ones
(1334, 4040 and 14 004 rows) included. Skips cleanly when ../shared is absent. The largest
problem (14 004 rows, about 15 s) is marked slow.
"""

from __future__ import annotations

import numpy as np
import pytest
from peer_data import peer_params
from solvers.fc2d.coulomb_2d import assert_coulomb_2d, natural_residual_2d

from mdi_envs.solvers import SolverStatus
from mdi_envs.solvers.fc2d import solve_fc2d
from mdi_envs.solvers.siconos_io import read_friction_contact

TOL = 1e-8
LARGEST = "fc2d_granularflowonwall_07002_00801"
GRANULAR = ["fc2d_granularflowonwall_00667_00000", "fc2d_granularflowonwall_02020_00213"]
SMALL = [
    "FC2D_SliderCrankLagrangian00000",
    "FC2D_SliderCrankLagrangian00001",
    "FrictionContactProblem00031",
    "FrictionContactProblem00071",
    "FrictionContactProblem00237",
    "FrictionContactProblem00374",
    "FrictionContactProblem00394",
    "FrictionContactProblem00727",
]


def _check(path, method: str, sparse: bool) -> None:
    data = read_friction_contact(path, sparse=sparse)
    assert data.dimension == 2
    options = {"max_iter": 5000} if method == "nsgs" else {}
    result = solve_fc2d(data.W, data.q, data.mu, method=method, tol=TOL, **options)
    assert result.status is SolverStatus.CONVERGED, (result.status, result.residual)
    assert result.residual <= TOL
    assert result.residual == pytest.approx(
        natural_residual_2d(data.W, data.q, data.mu, result.r), rel=1e-6, abs=1e-15
    )
    np.testing.assert_allclose(result.u, data.W @ result.r + data.q, rtol=1e-10, atol=1e-10)
    assert_coulomb_2d(data.W, data.q, data.mu, result.r, TOL)


@pytest.mark.parametrize("method", ["lemke", "nsgs", "newton_ac"])
@pytest.mark.parametrize("path", peer_params("fc2d", names=SMALL))
def test_small_peer_problems(path, method: str) -> None:
    """Every method on the eight small problems (dense W)."""
    _check(path, method, sparse=False)


@pytest.mark.parametrize("path", peer_params("fc2d", names=GRANULAR))
def test_granular_peer_problems(path) -> None:
    """The sparse Newton on the granular problems of 1334 and 4040 rows (W never dense)."""
    _check(path, "newton_ac", sparse=True)


@pytest.mark.slow
@pytest.mark.parametrize("path", peer_params("fc2d", names=[LARGEST]))
def test_largest_peer_problem(path) -> None:
    """The sparse Newton on the granular problem of 14 004 rows (about 15 s)."""
    _check(path, "newton_ac", sparse=True)


def test_the_lists_cover_every_peer_file() -> None:
    """SMALL, GRANULAR and LARGEST name all 11 files (when the peer data is present)."""
    from peer_data import peer_files

    stems = {p.stem for p in peer_files("fc2d")}
    if not stems:
        pytest.skip("peer data absent")
    assert stems == {*SMALL, *GRANULAR, LARGEST}
