"""solve_fc3d: analytic cases, input validation, honest reporting, random problems."""

from __future__ import annotations

import doctest

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from peer_data import peer_params

from mdi_envs.solvers._registry import MethodSpec
from mdi_envs.solvers.fc3d import FC3D_METHODS, FrictionContact3D, driver, solve_fc3d
from mdi_envs.solvers.fc3d.nsgs import NSGSOptions
from mdi_envs.solvers.lcp import solve_lcp
from mdi_envs.solvers.siconos_io import read_friction_contact
from mdi_envs.solvers.status import SolverStatus

METHODS = FC3D_METHODS.names()


def test_all_methods_are_registered() -> None:
    assert METHODS == ["fixed_point_socp", "hybrid", "newton_ac", "nsgs"]
    assert set(FC3D_METHODS.summaries()) == set(METHODS)


def test_docstring_example_runs() -> None:
    failures, tried = doctest.testmod(driver, verbose=False)
    assert tried > 0 and failures == 0


# --- analytic single-contact cases: W diagonal, the solution in closed form -------------------


def _closed_form(w_n: float, w_t: float, q: np.ndarray, mu: float) -> np.ndarray:
    """The solution of one contact with W = diag(w_n, w_t, w_t)."""
    if q[0] >= 0.0:
        return np.zeros(3)
    r_n = -q[0] / w_n
    q_t = q[1:]
    if np.linalg.norm(q_t) <= w_t * mu * r_n:  # stick: u_T = 0
        return np.array([r_n, *(-q_t / w_t)])
    return np.array([r_n, *(-mu * r_n * q_t / np.linalg.norm(q_t))])  # slide, against q_T


@pytest.mark.parametrize("method", METHODS)
def test_take_off_gives_zero_impulse(method: str, check_coulomb) -> None:
    W, q, mu = np.diag([2.0, 3.0, 3.0]), np.array([0.5, 4.0, -1.0]), np.array([0.6])
    result = solve_fc3d(W, q, mu, method=method)
    assert result.status is SolverStatus.CONVERGED
    np.testing.assert_array_equal(result.r, 0.0)
    regimes = check_coulomb(W, q, mu, result.r, 1e-12)
    assert regimes.take_off.all()
    # the method itself (not only the driver's trivial case) finds the take-off
    problem = FrictionContact3D(W, q, mu)
    spec = FC3D_METHODS.lookup(method)
    r, status, _ = spec.solve(problem, np.array([1.0, 0.2, 0.0]), spec.default_options)
    assert status is SolverStatus.CONVERGED
    np.testing.assert_allclose(r, 0.0, atol=1e-10)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("q_t", [(0.0, 0.0), (0.3, -0.2), (0.5, 0.0)])
def test_stick_inside_the_cone(method: str, q_t, check_coulomb) -> None:
    W, mu = np.diag([2.0, 3.0, 3.0]), np.array([0.5])
    q = np.array([-1.0, *q_t])  # r_N = 0.5, stick iff |q_T| / 3 <= 0.25
    result = solve_fc3d(W, q, mu, method=method)
    assert result.status is SolverStatus.CONVERGED
    np.testing.assert_allclose(result.r, -np.linalg.solve(W, q), atol=1e-10)
    np.testing.assert_allclose(result.u, 0.0, atol=1e-10)
    regimes = check_coulomb(W, q, mu, result.r, 1e-10)
    assert regimes.stick.all() or not np.any(q_t)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("q_t", [(1.0, 0.0), (-2.0, 2.0), (0.0, 30.0)])
def test_slide_on_the_cone_boundary(method: str, q_t, check_coulomb) -> None:
    w_n, w_t, mu = 2.0, 3.0, 0.5
    W, q = np.diag([w_n, w_t, w_t]), np.array([-1.0, *q_t])
    result = solve_fc3d(W, q, np.array([mu]), method=method)
    assert result.status is SolverStatus.CONVERGED
    expected = _closed_form(w_n, w_t, q, mu)
    np.testing.assert_allclose(result.r, expected, atol=1e-10)
    assert np.hypot(*result.r[1:]) == pytest.approx(mu * result.r[0], rel=1e-10)
    regimes = check_coulomb(W, q, np.array([mu]), result.r, 1e-10)
    assert regimes.slide.all()


@pytest.mark.parametrize("method", METHODS)
def test_decoupled_contacts_in_every_regime(method: str, check_coulomb) -> None:
    # block-diagonal W: each contact is its own closed-form problem
    blocks = [(1.0, 1.0), (2.0, 0.5), (4.0, 3.0), (1.0, 2.0)]
    qs = [(-1.0, 0.1, 0.0), (-2.0, 3.0, -4.0), (1.0, 5.0, 5.0), (-1.0, 0.0, 0.0)]
    mus = [0.5, 0.3, 0.8, 0.0]
    W = np.diag([w for w_n, w_t in blocks for w in (w_n, w_t, w_t)])
    q = np.concatenate(qs)
    result = solve_fc3d(W, q, np.array(mus), method=method)
    assert result.status is SolverStatus.CONVERGED
    expected = np.concatenate(
        [
            _closed_form(w_n, w_t, np.array(qi), m)
            for (w_n, w_t), qi, m in zip(blocks, qs, mus, strict=True)
        ]
    )
    np.testing.assert_allclose(result.r, expected, atol=1e-9)
    regimes = check_coulomb(W, q, np.array(mus), result.r, 1e-10)
    assert regimes.stick.tolist() == [True, False, False, False]
    assert regimes.slide.tolist() == [False, True, False, False]
    assert regimes.take_off.tolist() == [False, False, True, False]


# --- input validation --------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"W": np.full((3, 3), np.nan)}, r"\bW\b"),
        ({"q": np.array([-1.0, np.nan, 0.0])}, r"\bq\b"),
        ({"mu": np.array([np.nan])}, r"\bmu\b"),
        ({"mu": np.array([-0.1])}, r"\bmu\b"),
        ({"W": np.eye(4)}, r"\bW\b"),
        ({"W": np.eye(3)[:2]}, r"\bW\b"),
        ({"q": np.ones(4)}, r"\bq\b"),
        ({"mu": np.ones(2)}, r"\bmu\b"),
        ({"r0": np.ones(2)}, r"\br0\b"),
        ({"r0": np.array([np.inf, 0.0, 0.0])}, r"\br0\b"),
        ({"method": "lemke"}, r"unknown FC3D method 'lemke'.*newton_ac.*nsgs"),
        ({"method": None}, r"unknown FC3D method"),
        ({"tolerance": 1e-8}, r"unknown option.*tolerance"),
        ({"method": "newton_ac", "damping": 0.1}, r"unknown option.*damping"),
        ({"tol": 0.0}, r"\btol\b"),
        ({"max_iter": 0}, r"\bmax_iter\b"),
        ({"method": "newton_ac", "armijo": 0.7}, r"\barmijo\b"),
        ({"method": "newton_ac", "prox_sigma": -1.0}, r"\bprox_sigma\b"),
        ({"method": "newton_ac", "rho_scale": 0.0}, r"\brho_scale\b"),
        ({"method": "nsgs", "relaxation": 2.0}, r"\brelaxation\b"),
        ({"method": "nsgs", "damping": -1.0}, r"\bdamping\b"),
        ({"method": "nsgs", "local_tol": 0.0}, r"\blocal_tol\b"),
        ({"method": "nsgs", "local_max_iter": 0}, r"\blocal_max_iter\b"),
    ],
)
def test_bad_input_raises_value_error(kwargs: dict, message: str) -> None:
    args = {"W": np.eye(3), "q": np.array([-1.0, 0.5, 0.0]), "mu": np.array([0.3])}
    args.update(kwargs)
    with pytest.raises(ValueError, match=message):
        solve_fc3d(**args)


def test_empty_and_trivial_problems() -> None:
    result = solve_fc3d(np.zeros((0, 0)), np.zeros(0), np.zeros(0))
    assert result.status is SolverStatus.CONVERGED and result.r.shape == (0,)
    result = solve_fc3d(-np.eye(6), np.array([0.0, 1, 1, 2, -3, 0]), np.array([0.1, 0.2]))
    assert result.status is SolverStatus.CONVERGED and result.num_iter == 0
    np.testing.assert_array_equal(result.r, 0.0)
    np.testing.assert_array_equal(result.u, [0.0, 1, 1, 2, -3, 0])


@pytest.mark.parametrize("method", METHODS)
def test_warm_start_at_the_solution_takes_no_iteration(method: str) -> None:
    W = np.array([[2.0, 0.5, 0.0], [0.5, 3.0, 0.2], [0.0, 0.2, 3.0]])
    q, mu = np.array([-1.0, 2.0, 0.5]), np.array([0.4])
    first = solve_fc3d(W, q, mu, method=method)
    again = solve_fc3d(W, q, mu, method=method, r0=first.r)
    assert again.status is SolverStatus.CONVERGED and again.num_iter == 0
    np.testing.assert_array_equal(again.r, first.r)


@pytest.mark.parametrize("method", METHODS)
def test_iteration_limit_is_reported_not_raised(method: str) -> None:
    data = read_friction_contact_or_skip("OneObject-i100000-499.hdf5")
    # fixed_point_socp's Newton polish has its own budget (polish_iter): switched off here
    options = {"polish_below": 0.0} if method == "fixed_point_socp" else {}
    result = solve_fc3d(data.W, data.q, data.mu, method=method, max_iter=2, **options)
    assert result.status is SolverStatus.MAX_ITER
    assert result.num_iter == 2 and result.residual > 1e-10


def read_friction_contact_or_skip(stem: str):
    """Read one peer file, or skip when the peer data folder is absent."""
    (param,) = peer_params("fc3d", names=[stem])
    if param.values[0] is None:
        pytest.skip("peer data absent")
    return read_friction_contact(param.values[0])


# --- honest reporting on larger peer problems --------------------------------------------------

LARGER = [
    "NESpheres_10_1",
    "NESpheres_30_1",
    "Confeti-ex13-4contact-Fc3D-SBM",
    "Confeti-ex03-Fc3D-SBM",
    "GFC3D_TwoRods1-condensed",
    "Capsules-i101-404",
]


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("path", peer_params("fc3d", names=LARGER))
def test_larger_peer_problems_are_reported_honestly(method, path, recompute_residual) -> None:
    data = read_friction_contact(path)
    # a few hundred sweeps/steps: enough to converge on most, and to test MAX_ITER on the others
    max_iter = 300 if method == "nsgs" else 100
    tol = 1e-8
    result = solve_fc3d(data.W, data.q, data.mu, method=method, tol=tol, max_iter=max_iter)
    # abs: the two sums W r + q round differently (4e-14 apart at a 5e-13 residual, seen)
    assert result.residual == pytest.approx(
        recompute_residual(data.W, data.q, data.mu, result.r), rel=1e-6, abs=1e-12
    )
    np.testing.assert_allclose(result.u, data.W @ result.r + data.q, rtol=1e-10, atol=1e-10)
    assert (result.status is SolverStatus.CONVERGED) == (result.residual <= tol)
    assert result.status in (SolverStatus.CONVERGED, SolverStatus.MAX_ITER, SolverStatus.BREAKDOWN)
    assert result.method == method


def test_a_method_claiming_convergence_above_tol_is_downgraded(monkeypatch) -> None:
    def liar(problem, r0, options):
        return np.zeros(problem.q.shape[0]), SolverStatus.CONVERGED, 1

    spec = MethodSpec("liar", liar, NSGSOptions, "claims convergence at r = 0")
    monkeypatch.setitem(FC3D_METHODS._methods, "liar", spec)
    result = solve_fc3d(np.eye(3), np.array([-1.0, 0.0, 0.0]), np.array([0.5]), method="liar")
    assert result.status is SolverStatus.INACCURATE and result.residual == pytest.approx(1.0)
    unchecked = solve_fc3d(
        np.eye(3), np.array([-1.0, 0.0, 0.0]), np.array([0.5]), method="liar",
        check_solution=False,
    )
    assert unchecked.status is SolverStatus.CONVERGED


# --- random well-conditioned problems ------------------------------------------------------------


def _random_problem(seed: int, nc: int, frictionless: bool = False):
    """W = A A^T + delta I (symmetric positive definite), q of random scale, mu in [0, 1]."""
    rng = np.random.default_rng(seed)
    n = 3 * nc
    A = rng.normal(size=(n, n))
    W = A @ A.T + rng.uniform(0.1, 1.0) * np.eye(n)
    q = rng.normal(size=n) * 10.0 ** rng.uniform(-2, 2)
    mu = np.zeros(nc) if frictionless else rng.uniform(0.0, 1.0, size=nc)
    return W, q, mu


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**32 - 1), nc=st.integers(1, 10))
def test_random_problems_both_methods_converge(seed, nc, check_coulomb) -> None:
    W, q, mu = _random_problem(seed, nc)
    for method in METHODS:
        result = solve_fc3d(W, q, mu, method=method)
        assert result.status is SolverStatus.CONVERGED, (method, result)
        check_coulomb(W, q, mu, result.r, 1e-9)


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**32 - 1), nc=st.integers(1, 10))
def test_frictionless_random_problems_agree_with_the_lcp(seed, nc, check_coulomb) -> None:
    # mu = 0 forces r_T = 0 and leaves the LCP(W_NN, q_N); W_NN is positive definite, so r
    # is unique and both methods must find Lemke's solution.
    W, q, mu = _random_problem(seed, nc, frictionless=True)
    lcp = solve_lcp(W[::3, ::3], q[::3])
    assert lcp.status is SolverStatus.CONVERGED
    expected = np.zeros(3 * nc)
    expected[::3] = lcp.z
    scale = max(1.0, np.abs(expected).max())
    for method in METHODS:
        result = solve_fc3d(W, q, mu, method=method)
        assert result.status is SolverStatus.CONVERGED
        check_coulomb(W, q, mu, result.r, 1e-9)
        np.testing.assert_allclose(result.r, expected, atol=1e-7 * scale)
