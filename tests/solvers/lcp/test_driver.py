"""``solve_lcp`` (``mdi_envs/solvers/lcp/driver.py``).

Validation, the exact trivial cases, dispatch, the residual check, and agreement of all methods
where the solution is unique.
"""

from __future__ import annotations

import doctest
import warnings

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from solvers.lcp.complementarity import (
    HYPOTHESIS_SETTINGS,
    METHODS,
    Planted,
    assert_complementary,
    assert_result_consistent,
    assert_solved,
    planted_problems,
)

from mdi_envs.solvers import LCP_METHODS, LCPResult, SolverStatus, solve_lcp
from mdi_envs.solvers.lcp import driver

M2 = np.array([[2.0, 1.0], [1.0, 2.0]])
Q2 = np.array([-5.0, -6.0])


def test_methods_constant_matches_the_registry() -> None:
    """The tests cover every registered method."""
    assert sorted(METHODS) == LCP_METHODS.names()


def test_docstring_example() -> None:
    """The example in solve_lcp's docstring runs and prints what it claims."""
    finder = doctest.DocTestFinder()
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS)
    for test in finder.find(driver.solve_lcp, "solve_lcp", globs={"solve_lcp": solve_lcp}):
        runner.run(test)
    assert runner.tries >= 2 and runner.failures == 0


def test_default_method_is_lemke() -> None:
    """Without ``method`` the result comes from Lemke."""
    result = solve_lcp(M2, Q2)
    assert result.method == "lemke" and result.num_iter == 3
    assert_solved(M2, Q2, result)


def test_result_fields() -> None:
    """LCPResult carries z, w = Mz + q, status, num_iter, residual and the method name."""
    result = solve_lcp(M2, Q2, method="newton_fb")
    assert isinstance(result, LCPResult)
    assert result._fields == ("z", "w", "status", "num_iter", "residual", "method")
    assert result.method == "newton_fb"
    assert_result_consistent(M2, Q2, result)


# ------------------------------------------------------------------------------------------
# Exact trivial cases


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize(
    "q", [np.zeros(3), np.array([1.0, 0.0, 2.0]), np.array([0.0, -0.0, 5.0])], ids=str
)
def test_nonnegative_q_gives_zero_without_iterating(method: str, q: np.ndarray) -> None:
    """For q >= 0: z = 0 exactly, num_iter 0, whatever M (here indefinite with a zero diagonal)."""
    M = np.array([[0.0, -1.0, 3.0], [2.0, 0.0, -4.0], [-1.0, 5.0, -2.0]])
    result = solve_lcp(M, q, method=method)
    assert result.status is SolverStatus.CONVERGED
    assert result.num_iter == 0 and result.residual == 0.0
    np.testing.assert_array_equal(result.z, np.zeros(3))
    np.testing.assert_array_equal(result.w, q)


def test_nonnegative_q_skips_the_enumerative_size_limit() -> None:
    """The trivial case is settled before dispatch: no 2^n enumeration, no size error."""
    result = solve_lcp(np.eye(30), np.ones(30), method="enumerative")
    assert result.status is SolverStatus.CONVERGED and result.num_iter == 0


@pytest.mark.parametrize("method", METHODS)
def test_empty_problem(method: str) -> None:
    """The empty problem (n = 0) is trivially solved."""
    result = solve_lcp(np.zeros((0, 0)), np.zeros(0), method=method)
    assert result.status is SolverStatus.CONVERGED
    assert result.z.shape == (0,) and result.num_iter == 0 and result.residual == 0.0


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize(("m", "q"), [(2.0, -3.0), (1e-300, -1.0), (5.0, -1e-300), (1e6, -1e6)])
def test_scalar_closed_form(method: str, m: float, q: float) -> None:
    """For n = 1, m > 0, q < 0: z = -q/m exactly, num_iter 0, for every method."""
    result = solve_lcp(np.array([[m]]), np.array([q]), method=method)
    assert result.status is SolverStatus.CONVERGED and result.num_iter == 0
    assert result.z[0] == -q / m
    assert_complementary(np.array([[m]]), np.array([q]), result.z, result.w, tol=1e-15)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("m", [0.0, -0.0, -1.0, -1e-300])
def test_scalar_without_solution(method: str, m: float) -> None:
    """For n = 1, m <= 0, q < 0: w = m z + q < 0 for every z >= 0, so NO_SOLUTION (z = 0)."""
    result = solve_lcp(np.array([[m]]), np.array([-1.0]), method=method)
    assert result.status is SolverStatus.NO_SOLUTION and result.num_iter == 0
    np.testing.assert_array_equal(result.z, [0.0])
    assert result.residual == 1.0


@pytest.mark.parametrize("m", [-1.0, 0.0, 3.0])
def test_scalar_with_nonnegative_q(m: float) -> None:
    """For n = 1, q >= 0: z = 0 whatever the sign of m."""
    result = solve_lcp(np.array([[m]]), np.array([2.0]))
    assert result.status is SolverStatus.CONVERGED and result.z[0] == 0.0


# ------------------------------------------------------------------------------------------
# Bad input


@pytest.mark.parametrize(
    ("M", "q", "match"),
    [
        (np.array([[1.0, np.nan], [0.0, 1.0]]), Q2, "M contains NaN or inf"),
        (np.array([[1.0, np.inf], [0.0, 1.0]]), Q2, "M contains NaN or inf"),
        (np.array([[1.0, 0.0], [-np.inf, 1.0]]), Q2, "M contains NaN or inf"),
        # Values that only become inf (or lose information) on conversion to float64:
        ([[10**400, 0], [0, 1]], Q2, "M "),
        (np.array([[1.0 + 1.0j, 0.0], [0.0, 1.0]]), Q2, "M "),
        (M2, np.array([-1.0, np.nan]), "q contains NaN or inf"),
        (M2, np.array([np.inf, -1.0]), "q contains NaN or inf"),
        (np.ones((2, 3)), Q2, "M must be square, got shape \\(2, 3\\)"),
        (np.ones((3, 2)), Q2, "M must be square"),
        (M2, np.ones(3), "q has length 3 but M is 2x2"),
        (M2, np.ones(1), "q has length 1 but M is 2x2"),
        (np.ones((2, 2, 2)), Q2, "M must have 2 dimension\\(s\\), got shape \\(2, 2, 2\\)"),
        (np.ones(4), Q2, "M must have 2 dimension"),
        (2.0, Q2, "M must have 2 dimension"),
        (M2, Q2.reshape(2, 1), "q must have 1 dimension\\(s\\), got shape \\(2, 1\\)"),
        ("M", Q2, "M must be a numeric array"),
        ([["a", "b"], ["c", "d"]], Q2, "M must be a numeric array"),
        (M2, ["x", "y"], "q must be a numeric array"),
        ([[1.0, 2.0], [3.0]], Q2, "M must be a numeric array"),
        (None, Q2, "M must have 2 dimension"),
    ],
    ids=[
        "M_nan", "M_inf", "M_minus_inf", "M_int_beyond_float", "M_complex", "q_nan", "q_inf",
        "M_2x3", "M_3x2", "q_too_long", "q_too_short", "M_3d", "M_1d", "M_scalar", "q_2d",
        "M_string", "M_strings", "q_strings", "M_ragged", "M_none",
    ],
)
def test_bad_data(M: object, q: object, match: str) -> None:
    """NaN/inf, wrong shapes and non-numeric data raise ValueError naming the argument.

    A complex M must not be silently cast to its real part, and a Python int beyond the float
    range is as unusable as inf.
    """
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(ValueError, match=match):
            solve_lcp(M, q)


@pytest.mark.parametrize("method", METHODS)
def test_bad_data_is_rejected_whatever_the_method(method: str) -> None:
    """Validation happens in the driver, before any method sees the data."""
    with pytest.raises(ValueError, match="M contains NaN or inf"):
        solve_lcp(np.array([[1.0, np.nan], [0.0, 1.0]]), Q2, method=method)
    with pytest.raises(ValueError, match="q has length 3 but M is 2x2"):
        solve_lcp(M2, np.ones(3), method=method)


@pytest.mark.parametrize(
    ("z0", "match"),
    [
        (np.ones(3), "z0 has length 3, expected 2"),
        (np.array([1.0, np.nan]), "z0 contains NaN or inf"),
        (np.ones((2, 1)), "z0 must have 1 dimension"),
        (["a", "b"], "z0 must be a numeric array"),
    ],
)
@pytest.mark.parametrize("method", ["pgs", "newton_fb"])
def test_bad_start(method: str, z0: object, match: str) -> None:
    """A malformed starting point is rejected."""
    with pytest.raises(ValueError, match=match):
        solve_lcp(M2, Q2, method=method, z0=z0)


@pytest.mark.parametrize("method", ["Lemke_", "simplex", "", "pgs ", None, 3, ["lemke"]])
def test_unknown_method_lists_the_valid_ones(method: object) -> None:
    """An unknown method name raises ValueError listing every registered method."""
    with pytest.raises(ValueError, match="unknown LCP method") as info:
        solve_lcp(M2, Q2, method=method)
    assert "valid methods: ['enumerative', 'lemke', 'newton_fb', 'pgs']" in str(info.value)


@pytest.mark.parametrize(
    ("method", "option"),
    [("lemke", "relaxation"), ("pgs", "pivot_tol"), ("newton_fb", "max_size"), ("lemke", "tole")],
)
def test_unknown_option_lists_the_valid_ones(method: str, option: str) -> None:
    """An option the method does not have raises ValueError listing that method's options."""
    spec = LCP_METHODS.lookup(method)
    with pytest.raises(ValueError, match=f"unknown option\\(s\\) \\['{option}'\\]") as info:
        solve_lcp(M2, Q2, method=method, **{option: 1.0})
    message = str(info.value)
    assert f"for method '{method}'" in message
    for field in ("tol", "max_iter", "check_solution"):
        assert repr(field) in message
    assert str(sorted(spec.default_options.__dataclass_fields__)) in message


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize(
    ("option", "value", "match"),
    [
        ("tol", 0.0, "option 'tol' must be a finite number in \\(0, inf\\]"),
        ("tol", -1e-8, "option 'tol' must be a finite number in \\(0, inf\\]"),
        ("tol", float("nan"), "option 'tol' must be a finite number in \\(0, inf\\]"),
        ("max_iter", 0, "option 'max_iter' must be an integer >= 1"),
        ("max_iter", -5, "option 'max_iter' must be an integer >= 1"),
        ("max_iter", 1.5, "option 'max_iter' must be an integer >= 1"),
    ],
)
def test_invalid_common_option_values(method: str, option: str, value: float, match: str) -> None:
    """A tol > 0 and a positive integer max_iter are enforced for every method.

    (Non-finite max_iter is tested on ``SolverOptions`` itself, in tests/solvers/test_registry.py.)
    """
    with pytest.raises(ValueError, match=match):
        solve_lcp(M2, Q2, method=method, **{option: value})


@pytest.mark.parametrize("method", METHODS)
def test_integral_float_max_iter_behaves_like_the_int(method: str) -> None:
    """max_iter = 20.0 passes validation ("a positive integer"), so it must act as 20.

    Rejecting it with ValueError would be acceptable too; returning a float num_iter (or, with
    NUMBA_DISABLE_JIT=1, raising TypeError from ``range``) is not.
    """
    M = np.array([[4.0, 1.0, 0.0], [1.0, 3.0, 1.0], [0.0, 1.0, 2.0]])
    q = np.array([-1.0, -2.0, -3.0])
    try:
        result = solve_lcp(M, q, method=method, max_iter=20.0)
    except ValueError:
        return
    reference = solve_lcp(M, q, method=method, max_iter=20)
    assert type(result.num_iter) is int, repr(result.num_iter)
    assert (result.status, result.num_iter) == (reference.status, reference.num_iter)
    np.testing.assert_array_equal(result.z, reference.z)


def test_validation_happens_even_for_trivial_problems() -> None:
    """Options and data are checked before the trivial-case shortcut."""
    with pytest.raises(ValueError, match="option 'tol'"):
        solve_lcp(M2, np.ones(2), tol=-1.0)
    with pytest.raises(ValueError, match="q contains NaN"):
        solve_lcp(M2, np.array([1.0, np.nan]))


# ------------------------------------------------------------------------------------------
# Inputs are not modified; layouts and dtypes do not matter


@pytest.mark.parametrize("method", METHODS)
def test_inputs_are_not_modified(method: str) -> None:
    """M, q and z0 are read-only for the solver (PGS and Newton update a copy of z0)."""
    rng = np.random.default_rng(0)
    M = rng.uniform(-1, 1, (5, 5)) + 6 * np.eye(5)
    M = (M + M.T) / 2
    q = rng.uniform(-2, 1, 5)
    z0 = np.full(5, 0.5)
    copies = (M.copy(), q.copy(), z0.copy())
    solve_lcp(M, q, method=method, z0=z0)
    for array, copy in zip((M, q, z0), copies, strict=True):
        np.testing.assert_array_equal(array, copy)


@pytest.mark.parametrize("method", METHODS)
def test_layouts_and_dtypes_give_the_same_answer(method: str) -> None:
    """Fortran order, strided views, integer arrays and nested lists are all accepted."""
    M = np.array([[4, 1, 0], [1, 3, -1], [0, -1, 2]])
    q = np.array([-1, -2, 1])
    reference = solve_lcp(M.astype(float), q.astype(float), method=method)
    assert_solved(M.astype(float), q.astype(float), reference)
    big = np.zeros((6, 6))
    big[::2, ::2] = M
    variants = [
        (np.asfortranarray(M.astype(float)), q.astype(float)),
        (big[::2, ::2], np.repeat(q, 2)[::2].astype(float)),
        (M, q),
        (M.tolist(), q.tolist()),
        (M.astype(np.float32), q.astype(np.float32)),
    ]
    for M_variant, q_variant in variants:
        result = solve_lcp(M_variant, q_variant, method=method)
        assert result.status is reference.status
        np.testing.assert_allclose(result.z, reference.z, rtol=1e-12, atol=1e-14)


# ------------------------------------------------------------------------------------------
# The residual check


def test_check_solution_never_lets_converged_exceed_tol() -> None:
    """Whatever a method claims, CONVERGED implies residual <= tol after the driver's check."""
    rng = np.random.default_rng(5)
    for _ in range(20):
        M = rng.uniform(-1, 1, (4, 4))
        q = rng.uniform(-1, 1, 4)
        for method in METHODS:
            for tol in (1e-4, 1e-10, 1e-16):
                result = solve_lcp(M, q, method=method, tol=tol, max_iter=50)
                if result.status is SolverStatus.CONVERGED:
                    assert result.residual <= tol


def test_status_is_success_only_for_converged() -> None:
    """``SolverStatus.is_success`` is True for CONVERGED only."""
    assert [s.name for s in SolverStatus if s.is_success] == ["CONVERGED"]
    assert [int(s) for s in SolverStatus] == [0, 1, 2, 3, 4, 5]


# ------------------------------------------------------------------------------------------
# All methods agree where the solution is unique (P-matrices)


@HYPOTHESIS_SETTINGS
@given(st.sampled_from(["spd", "pd_nonsymmetric", "p_diag_dominant"]).flatmap(
    lambda kind: planted_problems(kind, max_n=24)
))
def test_methods_agree_on_p_matrices(problem: Planted) -> None:
    """Every applicable method returns the same z (the unique, planted one)."""
    methods = ["lemke", "newton_fb"]
    if problem.kind == "spd":
        methods.append("pgs")
    if problem.n <= 10:
        methods.append("enumerative")
    scale = max(1.0, np.abs(problem.z).max())
    solutions = {}
    for method in methods:
        result = solve_lcp(problem.M, problem.q, method=method)
        assert_solved(problem.M, problem.q, result)
        solutions[method] = result.z
    for method, z in solutions.items():
        np.testing.assert_allclose(z, solutions["lemke"], rtol=0, atol=1e-7 * scale, err_msg=method)
        np.testing.assert_allclose(z, problem.z, rtol=0, atol=1e-7 * scale, err_msg=method)
