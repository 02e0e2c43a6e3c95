"""The facts in ``peer_lcp.PEER_LCPS`` re-derived from the peer data themselves.

The method tests assert CONVERGED only where a method is guaranteed to work; these tests make
sure those guarantees (P-matrix, symmetric PD/PSD, uniqueness, infeasibility) are true of the
data and not just copied from the README.
"""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import linprog
from solvers.lcp.complementarity import assert_complementary
from solvers.lcp.peer_lcp import PEER_DATA, PEER_LCPS, lcp_params, load, names_where


def _all_principal_minors_positive(M: np.ndarray) -> bool:
    n = M.shape[0]
    for size in range(1, n + 1):
        for index in itertools.combinations(range(n), size):
            if np.linalg.det(M[np.ix_(index, index)]) <= 0.0:
                return False
    return True


def _solution_pieces(M: np.ndarray, q: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """Per complementary index set with a nonempty solution polyhedron: (min z, max z) by LP."""
    n = q.shape[0]
    pieces = []
    for mask in range(1 << n):
        active = [i for i in range(n) if mask >> i & 1]
        inactive = [i for i in range(n) if not mask >> i & 1]
        a_eq = [np.eye(n)[i] for i in inactive] + [M[i] for i in active]
        b_eq = [0.0] * len(inactive) + [-q[i] for i in active]
        a_ub = [-M[i] for i in inactive]
        b_ub = [q[i] for i in inactive]
        kwargs = {
            "A_eq": np.array(a_eq),
            "b_eq": np.array(b_eq),
            "A_ub": np.array(a_ub) if a_ub else None,
            "b_ub": np.array(b_ub) if b_ub else None,
            "bounds": [(0, None)] * n,
            "method": "highs",
        }
        if linprog(np.zeros(n), **kwargs).status != 0:
            continue
        low, high = np.empty(n), np.empty(n)
        for j in range(n):
            c = np.eye(n)[j]
            lo, hi = linprog(c, **kwargs), linprog(-c, **kwargs)
            low[j] = lo.fun if lo.status == 0 else -np.inf
            high[j] = -hi.fun if hi.status == 0 else np.inf
        pieces.append((low, high))
    return pieces


def test_peer_folder_holds_exactly_the_tabled_problems() -> None:
    """A new or missing peer LCP file must be reflected in the table (README section 2)."""
    folder = PEER_DATA / "lcp"
    if not folder.is_dir():
        pytest.skip(f"peer data {PEER_DATA} absent")
    assert sorted(p.stem for p in folder.glob("*.dat")) == sorted(PEER_LCPS)


@pytest.mark.parametrize("path", lcp_params())
def test_size_and_symmetry_claims(path: Path) -> None:
    """n, symmetric PD and symmetric PSD (with positive diagonal) hold as tabled."""
    M, q, info = load(path)
    assert M.shape == (info.n, info.n) and q.shape == (info.n,)
    symmetric = np.array_equal(M, M.T)
    eig_min = np.linalg.eigvalsh((M + M.T) / 2).min()
    if info.sym_pd:
        assert symmetric and eig_min > 0.0
    if info.sym_psd:
        assert symmetric and eig_min >= -1e-12 * np.abs(M).max() and np.diag(M).min() > 0.0
    if not info.sym_psd:
        assert not (symmetric and eig_min >= 0.0 and np.diag(M).min() > 0.0)


@pytest.mark.parametrize("path", lcp_params(names_where(lambda i: i.n <= 12)))
def test_p_matrix_claims(path: Path) -> None:
    """The P-matrix property by brute force over all principal minors (n <= 12)."""
    M, _, info = load(path)
    assert _all_principal_minors_positive(M) == info.p_matrix


@pytest.mark.parametrize("path", lcp_params(names_where(lambda i: i.sym_pd and i.n > 12)))
def test_large_p_matrix_claims_via_definiteness(path: Path) -> None:
    """Symmetric PD implies P; checked by the smallest eigenvalue."""
    M, _, info = load(path)
    assert info.p_matrix and np.linalg.eigvalsh(M).min() > 0.0


@pytest.mark.parametrize("path", lcp_params())
def test_feasibility_claims(path: Path) -> None:
    """An LP finds z >= 0 with Mz + q >= 0 exactly when the table says a solution exists."""
    M, q, info = load(path)
    lp = linprog(np.zeros(info.n), A_ub=-M, b_ub=q, bounds=[(0, None)] * info.n, method="highs")
    assert (lp.status == 0) == info.has_solution


@pytest.mark.parametrize("path", lcp_params(names_where(lambda i: i.solution is not None)))
def test_tabled_solutions_solve_the_problem(path: Path) -> None:
    """The closed-form solutions quoted from the README are solutions."""
    M, q, info = load(path)
    assert_complementary(M, q, np.array(info.solution), None, tol=1e-12)


@pytest.mark.parametrize(
    "path", lcp_params(names_where(lambda i: i.unique and not i.p_matrix and i.n <= 9))
)
def test_uniqueness_claims_of_non_p_problems(path: Path) -> None:
    """Every complementary piece of the solution set collapses to the same single point."""
    M, q, _ = load(path)
    pieces = _solution_pieces(M, q)
    assert pieces
    points = [low for low, _ in pieces]
    for low, high in pieces:
        np.testing.assert_allclose(high, low, atol=1e-9)
        np.testing.assert_allclose(low, points[0], atol=1e-9)


@pytest.mark.parametrize(
    "path", lcp_params(["lcp_CPS_1", "lcp_CPS_3", "lcp_CPS_5", "lcp_inf_sol_perturbed"])
)
def test_non_uniqueness_claims(path: Path) -> None:
    """The problems tabled as not unique do have more than one solution."""
    M, q, info = load(path)
    assert not info.unique
    pieces = _solution_pieces(M, q)
    spread = max(np.max(high - low) for low, high in pieces)
    distinct = {tuple(np.round(low, 9)) for low, _ in pieces}
    assert spread > 0 or len(distinct) > 1
