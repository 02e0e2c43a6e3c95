"""De Saxce's fixed point on cone QPs (``mdi_envs/solvers/fc3d/fixed_point_socp.py``).

Its options, the clear error without clarabel, one-contact problems with known solutions
(slide, stick, mu = 0), random non-symmetric W = H A H^T, and ``Capsules-i122-1617``,
cone-checked. ``RockPile_tob1``, the peer problem only this method solves, is in
``test_peer_table.py``. The tests that solve skip when clarabel (the ``conic`` extra) is absent.
"""

from __future__ import annotations

import importlib.util
import sys

import numpy as np
import pytest
from peer_data import peer_params

from mdi_envs.solvers import FC3D_METHODS, SolverStatus, solve_fc3d
from mdi_envs.solvers.siconos_io import read_friction_contact

needs_clarabel = pytest.mark.skipif(
    importlib.util.find_spec("clarabel") is None,
    reason='clarabel absent (pip install "mdi-envs[conic]")',
)
METHOD = "fixed_point_socp"


def test_registered_with_its_options() -> None:
    spec = FC3D_METHODS.lookup(METHOD)
    assert spec.default_options.relaxation == 0.5
    bad_options = ({"relaxation": 0.0}, {"relaxation": 1.5}, {"socp_tol": 0.0},
                   {"stall_iter": 0}, {"polish_below": -1.0}, {"polish_iter": 0},
                   {"polish_cycles": 0})
    for bad in bad_options:
        with pytest.raises(ValueError, match="option"):
            solve_fc3d(np.eye(3), np.array([-1.0, 0.0, 0.0]), np.array([0.5]), method=METHOD,
                       **bad)


def test_without_clarabel_the_error_names_the_extra(monkeypatch) -> None:
    monkeypatch.setitem(sys.modules, "clarabel", None)  # makes `import clarabel` fail
    with pytest.raises(ImportError, match=r"mdi-envs\[conic\]"):
        solve_fc3d(np.eye(3), np.array([-1.0, 2.0, 0.0]), np.array([0.5]), method=METHOD)


@needs_clarabel
@pytest.mark.parametrize(
    ("q", "mu", "r_expected"),
    [
        ([-1.0, 2.0, 0.0], 0.5, [1.0, -0.5, 0.0]),  # slides: r_T on the cone, against u_T
        ([-1.0, 0.0, 0.2], 0.5, [1.0, 0.0, -0.2]),  # sticks: u = 0
        ([-1.0, 2.0, 0.0], 0.0, [1.0, 0.0, 0.0]),  # frictionless: r_T = 0, u_T free
    ],
)
def test_one_contact_known_solution(q, mu, r_expected, check_coulomb) -> None:
    W, q, mu = np.eye(3), np.array(q), np.array([mu])
    result = solve_fc3d(W, q, mu, method=METHOD, tol=1e-10)
    assert result.status is SolverStatus.CONVERGED, result.residual
    np.testing.assert_allclose(result.r, r_expected, atol=1e-8)
    check_coulomb(W, q, mu, result.r, 1e-10)


@needs_clarabel
@pytest.mark.parametrize("seed", range(4))
def test_random_non_symmetric_rank_deficient(seed: int, check_coulomb) -> None:
    """W = H A H^T with A positive definite plus skew, H with fewer columns than rows."""
    rng = np.random.default_rng(seed)
    nc = 3 + seed
    H = rng.normal(size=(3 * nc, 2 * nc))
    B = rng.normal(size=(2 * nc, 2 * nc))
    S = rng.normal(size=(2 * nc, 2 * nc))
    W = H @ (B @ B.T + np.eye(2 * nc) + 0.1 * (S - S.T)) @ H.T
    q = rng.normal(size=3 * nc)
    mu = rng.uniform(0.1, 0.5, nc)
    result = solve_fc3d(W, q, mu, method=METHOD, tol=1e-8)
    assert result.status is SolverStatus.CONVERGED, result.residual
    check_coulomb(W, q, mu, result.r, 1e-8)


@needs_clarabel
@pytest.mark.parametrize("path", peer_params("fc3d", names=["Capsules-i122-1617"]))
def test_capsules_i122_converges(path, check_coulomb, recompute_residual) -> None:
    """The capsules at n = 888 (redundant contacts, non-symmetric W); about 2.5 s."""
    data = read_friction_contact(path)
    result = solve_fc3d(data.W, data.q, data.mu, method=METHOD, tol=1e-8)
    assert result.status is SolverStatus.CONVERGED, result.residual
    assert recompute_residual(data.W, data.q, data.mu, result.r) <= 1e-8
    check_coulomb(data.W, data.q, data.mu, result.r, 1e-8)
