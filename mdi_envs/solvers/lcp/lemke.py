"""Lemke's complementary pivoting method with a lexicographic, scale-relative ratio test.

The kernel works on the compact (Tucker) tableau: only the n + 1 non-basic columns and the
right-hand side are stored, as an (n, n + 2) array, so each pivot costs n(n + 2) multiply-adds
instead of the n(2n + 2) of the full tableau ``[I, -M, -d | q]``.

Variables are numbered ``w_j = j``, ``z_j = n + j`` and the artificial ``z_0 = 2n``; the covering
vector is d = 1. Degeneracy is handled by the lexicographic rule on the rows of B^-1, with ties
judged relative to scale: row i ties with the minimum ratio theta when
``b_i - theta * a_i <= tie_tol * max|b|`` (an absolute tie tolerance either cycles on degenerate
problems whose rounding noise exceeds it or mistakes a uniformly tiny q for zero). If the
artificial variable can leave, it does, and the method stops.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from mdi_envs._types import FloatArray, IntArray
from mdi_envs.solvers._linalg import lu_solve_inplace
from mdi_envs.solvers._registry import SolverOptions, require_real_option
from mdi_envs.solvers.lcp.problem import LCP, natural_map, screen
from mdi_envs.solvers.lcp.registry import DIRECT_M_NOT_FINITE, DIRECT_Q_NOT_FINITE, LCP_METHODS
from mdi_envs.solvers.status import (
    CODE_CONVERGED,
    CODE_INACCURATE,
    CODE_MAX_ITER,
    CODE_NO_SOLUTION,
    CODE_RAY_TERMINATION,
    SolverStatus,
)


@dataclass(frozen=True)
class LemkeOptions(SolverOptions):
    """Options of Lemke's method.

    Attributes:
        max_iter: pivot limit (Lemke's method is exponential in the worst case: Murty's n = 6
            example needs 2^6 pivots).
        pivot_tol: an entering-column entry counts as positive only above
            ``pivot_tol * max|column|``.
        tie_tol: relative tie tolerance of the ratio test (see the module docstring).
    """

    max_iter: int = 10_000
    pivot_tol: float = 1e-12
    tie_tol: float = 1e-11

    def __post_init__(self) -> None:
        super().__post_init__()
        for name in ("pivot_tol", "tie_tol"):
            require_real_option(self, name, low=0.0, high=1.0, high_inclusive=False)


@njit(cache=True)
def lemke_kernel(
    M: FloatArray,
    q: FloatArray,
    max_iter: int,
    pivot_tol: float,
    tie_tol: float,
    T: FloatArray,
    basis: IntArray,
    row_of: IntArray,
    slot_of: IntArray,
    slot_var: IntArray,
    pivot_row: FloatArray,
    z: FloatArray,
) -> tuple[int, int]:
    """Run Lemke's method on LCP(M, q) with preallocated workspaces.

    Args:
        M: (n, n) matrix. q: (n,) vector.
        max_iter: pivot limit. pivot_tol, tie_tol: see ``LemkeOptions``.
        T: (n, n + 2) tableau workspace, overwritten.
        basis: (n,) int workspace, overwritten: the basic variable of each row on return.
        row_of, slot_of: (2n + 1,) int workspaces, overwritten.
        slot_var: (n + 1,) int workspace, overwritten.
        pivot_row: (n + 2,) workspace, overwritten.
        z: (n,) output, overwritten with the solution (or the last basic point).

    Returns:
        (code, pivots): code 0 converged, 1 pivot limit, 2 secondary ray.
    """
    n = q.shape[0]
    rhs = n + 1
    art = 2 * n
    for j in range(n):
        z[j] = 0.0
    qmin = 0.0
    for i in range(n):
        if q[i] < qmin:
            qmin = q[i]
    if qmin >= 0.0:
        return CODE_CONVERGED, 0

    # Tucker tableau: basic w, non-basic z_0..z_{n-1} and the artificial in slot n. M and q are
    # divided by powers of two near their largest entries: exact, leaves the pivot path of
    # exact arithmetic unchanged, and makes the tolerances independent of the data's units.
    m_largest = 0.0
    q_largest = 0.0
    for i in range(n):
        q_largest = max(q_largest, abs(q[i]))
        for j in range(n):
            m_largest = max(m_largest, abs(M[i, j]))
    m_scale = _power_of_two_near(m_largest)
    q_scale = _power_of_two_near(q_largest)
    for i in range(n):
        for j in range(n):
            T[i, j] = -M[i, j] / m_scale
        T[i, n] = -1.0
        T[i, rhs] = q[i] / q_scale
        basis[i] = i
        row_of[i] = i
        slot_of[i] = -1
    for j in range(n):
        row_of[n + j] = -1
        slot_of[n + j] = j
        slot_var[j] = n + j
    row_of[art] = -1
    slot_of[art] = n
    slot_var[n] = art

    # First pivot: the artificial enters and the most negative q_i leaves (ties: largest i,
    # which is the lexicographic choice for B^-1 = I).
    r = 0
    for i in range(1, n):
        if q[i] <= q[r] + tie_tol * (-qmin):
            r = i
    entering = art
    num_pivots = 0
    code = CODE_MAX_ITER
    while num_pivots < max_iter:
        s = slot_of[entering]
        if num_pivots > 0:
            r = _ratio_test(T, s, n, pivot_tol, tie_tol, row_of, slot_of, art)
            if r < 0:
                code = CODE_RAY_TERMINATION
                break
        leaving = basis[r]
        _pivot(T, r, s, pivot_row)
        num_pivots += 1
        basis[r] = entering
        row_of[entering] = r
        slot_of[entering] = -1
        row_of[leaving] = -1
        slot_of[leaving] = s
        slot_var[s] = leaving
        if leaving == art:
            code = CODE_CONVERGED
            break
        entering = leaving + n if leaving < n else leaving - n

    for i in range(n):
        v = basis[i]
        if n <= v < art:
            z[v - n] = T[i, rhs] * (q_scale / m_scale)
    return code, num_pivots


@njit(cache=True)
def _power_of_two_near(largest: float) -> float:
    """The power of two nearest ``largest`` > 0 (1 for 0); dividing by it is exact."""
    if largest == 0.0:
        return 1.0
    return 2.0 ** np.round(np.log2(largest))


@njit(cache=True)
def _pivot(T: FloatArray, r: int, s: int, pivot_row: FloatArray) -> None:
    """Exchange the basic variable of row r with the non-basic one in slot s (T modified).

    ``pivot_row`` (n + 2,) is a workspace: updating from a copy of the pivot row instead of
    ``T[r]`` itself removes the aliasing that keeps the row update from vectorizing. Rows are
    updated through ``T[i, c]``, not a row view ``T[i]``: making the view (reference counting
    included) cost a third of each pivot at n = 50.
    """
    n, width = T.shape
    inv = 1.0 / T[r, s]
    T[r, s] = 1.0
    for c in range(width):
        v = T[r, c] * inv
        T[r, c] = v
        pivot_row[c] = v
    for i in range(n):
        if i == r:
            continue
        f = T[i, s]
        if f != 0.0:
            T[i, s] = 0.0
            for c in range(width):
                T[i, c] -= f * pivot_row[c]


@njit(cache=True)
def _ratio_test(
    T: FloatArray,
    s: int,
    n: int,
    pivot_tol: float,
    tie_tol: float,
    row_of: IntArray,
    slot_of: IntArray,
    art: int,
) -> int:
    """Leaving row for the column in slot s, or -1 on a ray (lexicographic tie-breaking)."""
    rhs = n + 1
    col_max = 0.0
    b_max = 0.0
    for i in range(n):
        a = abs(T[i, s])
        if a > col_max:
            col_max = a
        b = abs(T[i, rhs])
        if b > b_max:
            b_max = b
    if col_max == 0.0:
        return -1
    threshold = pivot_tol * col_max
    tie_scale = tie_tol * b_max
    # Fast path (no degeneracy): a unique minimum ratio on an entry that is not noise.
    best = -1
    theta = np.inf
    for i in range(n):
        a = T[i, s]
        if a > threshold:
            ratio = T[i, rhs] / a
            if ratio < theta:
                theta = ratio
                best = i
    if best < 0:
        return -1
    num_ties = 0
    for i in range(n):
        a = T[i, s]
        if a > threshold and T[i, rhs] - theta * a <= tie_scale:
            num_ties += 1
    if num_ties <= 1 and T[best, s] > pivot_tol * _row_scale(T, best, n):
        return best
    excluded = np.zeros(n, dtype=np.bool_)
    while True:
        best = -1
        theta = np.inf
        for i in range(n):
            a = T[i, s]
            if a > threshold and not excluded[i]:
                ratio = T[i, rhs] / a
                if ratio < theta:
                    theta = ratio
                    best = i
        if best < 0:
            return -1
        num_ties = 0
        for i in range(n):
            if _is_tie(T, i, s, theta, threshold, tie_scale, excluded):
                num_ties += 1
        ties = np.empty(max(num_ties, 1), dtype=np.int64)
        ties[0] = best
        num_ties = 0
        for i in range(n):
            if _is_tie(T, i, s, theta, threshold, tie_scale, excluded):
                ties[num_ties] = i
                num_ties += 1
        num_ties = max(num_ties, 1)
        # A pivot entry that is rounding noise relative to its own row (a zero in exact
        # arithmetic) must not be pivoted on, nor inflate the lexicographic comparison.
        kept = 0
        for t in range(num_ties):
            i = ties[t]
            if T[i, s] > pivot_tol * _row_scale(T, i, n):
                ties[kept] = i
                kept += 1
        if kept > 0:
            num_ties = kept
            break
        for t in range(num_ties):
            excluded[ties[t]] = True
    if num_ties == 1:
        return ties[0]
    art_row = -1 if slot_of[art] >= 0 else row_of[art]
    for t in range(num_ties):
        if ties[t] == art_row:
            return art_row
    # Lexicographic rule on the rows of B^-1 (its column k is the column of w_k), with ties
    # judged relative to the largest entry of the rows compared (entries that are zero in exact
    # arithmetic carry rounding noise).
    v_scale = 0.0
    for k in range(n):
        for t in range(num_ties):
            v = abs(_inverse_basis_entry(T, ties[t], k, row_of, slot_of)) / T[ties[t], s]
            if v > v_scale:
                v_scale = v
    values = np.empty(num_ties)
    for k in range(n):
        v_min = np.inf
        for t in range(num_ties):
            i = ties[t]
            v = _inverse_basis_entry(T, i, k, row_of, slot_of) / T[i, s]
            values[t] = v
            if v < v_min:
                v_min = v
        kept = 0
        for t in range(num_ties):
            if values[t] <= v_min + tie_tol * v_scale:
                ties[kept] = ties[t]
                kept += 1
        num_ties = kept
        if num_ties == 1:
            break
    return ties[0]


@njit(cache=True)
def _is_tie(
    T: FloatArray,
    i: int,
    s: int,
    theta: float,
    threshold: float,
    tie_scale: float,
    excluded: np.ndarray,
) -> bool:
    """Whether row i attains the minimum ratio theta, to the scale-relative tie tolerance."""
    a = T[i, s]
    if a <= threshold or excluded[i]:
        return False
    return T[i, T.shape[1] - 1] - theta * a <= tie_scale


@njit(cache=True)
def _row_scale(T: FloatArray, i: int, n: int) -> float:
    """max_c |T[i, c]| over the n + 1 non-basic slots of row i."""
    scale = 0.0
    for c in range(n + 1):
        v = abs(T[i, c])
        if v > scale:
            scale = v
    return scale


@njit(cache=True)
def _inverse_basis_entry(
    T: FloatArray, i: int, k: int, row_of: IntArray, slot_of: IntArray
) -> float:
    """Entry (i, k) of B^-1: the tableau column of w_k, a unit vector while w_k is basic."""
    if slot_of[k] >= 0:
        return T[i, slot_of[k]]
    return 1.0 if row_of[k] == i else 0.0


@njit(cache=True)
def refine_basic_solution(
    M: FloatArray, q: FloatArray, basis: IntArray, z: FloatArray, A: FloatArray, x: FloatArray
) -> bool:
    """Recompute the basic solution of the final basis by one fresh LU solve (in place).

    Removes the rounding accumulated over many pivots: solves ``B x_B = q`` where the columns
    of B are ``e_j`` for a basic ``w_j`` and ``-M[:, j]`` for a basic ``z_j``.

    Args:
        M: (n, n). q: (n,). basis: (n,) final basic variables (numbering of the module).
        z: (n,) overwritten with the refined solution on success.
        A: (n, n) workspace. x: (n,) workspace.

    Returns:
        False if the final basis matrix is numerically singular (z is then left unchanged).
    """
    n = q.shape[0]
    for i in range(n):
        x[i] = q[i]
    for c in range(n):
        v = basis[c]
        for i in range(n):
            if v < n:
                A[i, c] = 1.0 if i == v else 0.0
            else:
                A[i, c] = -M[i, v - n]
    if not lu_solve_inplace(A, x, 1e-14):
        return False
    for j in range(n):
        z[j] = 0.0
    for c in range(n):
        v = basis[c]
        if n <= v < 2 * n:
            z[v - n] = max(x[c], 0.0)
    return True


@njit(cache=True)
def lemke_solve(
    M: FloatArray, q: FloatArray, max_iter: int, pivot_tol: float, tie_tol: float, tol: float
) -> tuple[FloatArray, int, int]:
    """Allocate the workspaces, run ``lemke_kernel`` and refactorize the final basis if needed.

    Args:
        M: (n, n). q: (n,). max_iter, pivot_tol, tie_tol: see ``LemkeOptions``.
        tol: residual tolerance; a pivoted solution above it is recomputed from its basis.

    Returns:
        (z, code, pivots) with z (n,); code as for ``lemke_kernel``.
    """
    n = q.shape[0]
    z = np.empty(n)
    code, pivots, _ = lemke_solve_into(M, q, max_iter, pivot_tol, tie_tol, tol, z, np.empty(n))
    return z, code, pivots


@njit(cache=True)
def lemke_solve_into(
    M: FloatArray,
    q: FloatArray,
    max_iter: int,
    pivot_tol: float,
    tie_tol: float,
    tol: float,
    z: FloatArray,
    w: FloatArray,
) -> tuple[int, int, float]:
    """``lemke_solve`` writing into z (n,) and w = M z + q (n,) (both overwritten).

    Returns:
        (code, pivots, residual): the shared residual of the returned z, computed once (twice
        if the final basis is refactorized).
    """
    n = q.shape[0]
    basis = np.empty(n, dtype=np.int64)
    code, pivots = lemke_kernel(
        M, q, max_iter, pivot_tol, tie_tol, np.empty((n, n + 2)), basis,
        np.empty(2 * n + 1, dtype=np.int64), np.empty(2 * n + 1, dtype=np.int64),
        np.empty(n + 1, dtype=np.int64), np.empty(n + 2), z,
    )
    residual = natural_map(M, q, z, w)
    if code == CODE_CONVERGED and pivots > 0 and residual > tol:
        if refine_basic_solution(M, q, basis, z, np.empty((n, n)), np.empty(n)):
            residual = natural_map(M, q, z, w)
    return code, pivots, residual


@njit(cache=True)
def lemke_checked(
    M: FloatArray,
    q: FloatArray,
    max_iter: int,
    pivot_tol: float,
    tie_tol: float,
    tol: float,
    check_solution: bool,
    z: FloatArray,
    w: FloatArray,
) -> tuple[int, int, float]:
    """The whole of ``solve_lcp(M, q, method="lemke")`` after the shape checks, in one call.

    Screens the data for NaN/inf, solves the trivial cases exactly (q >= 0: z = 0; n = 1: the
    closed form), runs Lemke's method otherwise, computes w = M z + q and the shared residual
    with ``natural_map`` and downgrades CONVERGED above ``tol`` to INACCURATE (if
    ``check_solution``), exactly as the generic driver path does.

    Args:
        M: (n, n), q: (n,): C-contiguous float64, shapes already checked.
        max_iter, pivot_tol, tie_tol, tol: see ``LemkeOptions``.
        check_solution: apply the residual check to the status.
        z: (n,) output: the solution. w: (n,) output: M z + q. Both overwritten.

    Returns:
        (code, pivots, residual): code a ``SolverStatus`` value, or ``DIRECT_Q_NOT_FINITE`` /
        ``DIRECT_M_NOT_FINITE`` (then nothing was solved; q is screened first).
    """
    n = q.shape[0]
    is_M_finite, is_q_finite, is_trivial = screen(M, q)
    if not is_q_finite:
        return DIRECT_Q_NOT_FINITE, 0, np.nan
    if not is_M_finite:
        return DIRECT_M_NOT_FINITE, 0, np.nan
    code, pivots = CODE_CONVERGED, 0
    if n > 1 and not is_trivial:
        code, pivots, residual = lemke_solve_into(M, q, max_iter, pivot_tol, tie_tol, tol, z, w)
    else:
        for j in range(n):
            z[j] = 0.0
        if not is_trivial:  # n = 1, q < 0: z = -q/m if m > 0, otherwise no solution
            if M[0, 0] > 0.0:
                z[0] = -q[0] / M[0, 0]
            else:
                code = CODE_NO_SOLUTION
        residual = natural_map(M, q, z, w)
    if check_solution and code == CODE_CONVERGED and not residual <= tol:
        code = CODE_INACCURATE
    return code, pivots, residual


def lemke_direct(
    M: FloatArray, q: FloatArray, options: LemkeOptions, z: FloatArray, w: FloatArray
) -> tuple[int, int, float]:
    """``lemke_checked`` with its options read from ``options`` (the registry's direct path)."""
    return lemke_checked(
        M, q, options.max_iter, options.pivot_tol, options.tie_tol, options.tol,
        options.check_solution, z, w,
    )


@LCP_METHODS.register(
    "lemke", LemkeOptions, "Lemke's complementary pivoting (lexicographic)", direct=lemke_direct
)
def solve_lemke(
    problem: LCP, z0: FloatArray | None, options: LemkeOptions
) -> tuple[FloatArray, SolverStatus, int]:
    """Solve ``problem`` by Lemke's method (``z0`` is ignored: pivoting starts from z = 0).

    Returns:
        (z, status, pivots). A secondary ray is ``RAY_TERMINATION``; if the pivoted solution
        misses ``options.tol``, the final basis is refactorized once before reporting.
    """
    z, code, pivots = lemke_solve(
        problem.M, problem.q, options.max_iter, options.pivot_tol, options.tie_tol, options.tol
    )
    return z, SolverStatus(code), pivots


__all__ = [
    "LemkeOptions",
    "lemke_checked",
    "lemke_direct",
    "lemke_kernel",
    "lemke_solve",
    "lemke_solve_into",
    "refine_basic_solution",
    "solve_lemke",
]
