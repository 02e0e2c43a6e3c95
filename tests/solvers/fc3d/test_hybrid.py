"""The Newton/NSGS hybrid (``mdi_envs/solvers/fc3d/hybrid.py``).

Its options, its pure-Newton path (``warm_sweeps=0``), and the peer problem it exists for:
``Capsules-i122-1617`` (n = 888, redundant contacts), where ``newton_ac`` stops at 1.9e-7 and
``nsgs`` needs thousands of sweeps; solved to 1e-8 and checked by the independent cone checker.
"""

from __future__ import annotations

import numpy as np
import pytest
from peer_data import peer_params

from mdi_envs.solvers import FC3D_METHODS, SolverStatus, solve_fc3d
from mdi_envs.solvers.siconos_io import read_friction_contact


def test_registered_with_its_options() -> None:
    spec = FC3D_METHODS.lookup("hybrid")
    assert spec.default_options.warm_sweeps == 50
    for bad in ({"warm_sweeps": -1}, {"shift": -1.0}, {"armijo": 0.6}, {"rho_scale": 0.0}):
        with pytest.raises(ValueError, match="option"):
            solve_fc3d(np.eye(3), np.array([-1.0, 0.0, 0.0]), np.array([0.5]), method="hybrid",
                       **bad)


@pytest.mark.parametrize("seed", range(6))
def test_pure_newton_path_on_random_problems(seed: int, check_coulomb) -> None:
    """Without NSGS sweeps the shifted sparse Newton alone solves well-posed problems."""
    rng = np.random.default_rng(seed)
    nc = 2 + seed
    A = rng.normal(size=(3 * nc, 3 * nc))
    W = A @ A.T + 0.5 * np.eye(3 * nc)
    q = rng.normal(size=3 * nc)
    mu = rng.uniform(0.1, 1.0, nc)
    result = solve_fc3d(W, q, mu, method="hybrid", warm_sweeps=0, tol=1e-10)
    assert result.status is SolverStatus.CONVERGED
    check_coulomb(W, q, mu, result.r, 1e-10)
    newton = solve_fc3d(W, q, mu, method="newton_ac", tol=1e-10)
    assert newton.status is SolverStatus.CONVERGED


@pytest.mark.slow
@pytest.mark.parametrize("path", peer_params("fc3d", names=["Capsules-i122-1617"]))
def test_capsules_i122_converges(path, check_coulomb, recompute_residual) -> None:
    """The peer problem ``newton_ac`` and ``nsgs`` left unsolved, to 1e-8 (about 10 s)."""
    data = read_friction_contact(path)
    result = solve_fc3d(data.W, data.q, data.mu, method="hybrid", tol=1e-8)
    assert result.status is SolverStatus.CONVERGED, result.residual
    assert recompute_residual(data.W, data.q, data.mu, result.r) <= 1e-8
    check_coulomb(data.W, data.q, data.mu, result.r, 1e-8)
