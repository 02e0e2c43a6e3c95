"""Small dense linear-algebra kernels for the solvers' inner loops (numba, no exceptions).

``np.linalg.solve`` raises on a singular matrix, which a compiled hot loop must not do; these
kernels report singularity through their return value instead.
"""

from __future__ import annotations

import math

from numba import njit

from mdi_envs._borrowing import REFERENCE_COUNTED
from mdi_envs._types import FloatArray


@njit(cache=True, inline="always")
def _column_pivot(A: FloatArray, k: int) -> tuple[int, float]:
    """Partial pivoting: the row p >= k with the largest |A[p, k]|, and that value."""
    p = k
    best = abs(A[k, k])
    for i in range(k + 1, A.shape[0]):
        a = abs(A[i, k])
        if a > best:
            best = a
            p = i
    return p, best


@njit(cache=True, inline="always")
def _eliminate_below(A: FloatArray, b: FloatArray, k: int, p: int) -> None:
    """Swap rows k and p of (A, b), then eliminate column k below row k (multipliers kept)."""
    n = A.shape[0]
    if p != k:
        for j in range(n):
            A[k, j], A[p, j] = A[p, j], A[k, j]
        b[k], b[p] = b[p], b[k]
    inv = 1.0 / A[k, k]
    for i in range(k + 1, n):
        f = A[i, k] * inv
        if f != 0.0:
            A[i, k] = f
            for j in range(k + 1, n):
                A[i, j] -= f * A[k, j]
            b[i] -= f * b[k]


@njit(cache=True, inline="always")
def _back_substitute(A: FloatArray, b: FloatArray, rank: int) -> None:
    """b[:rank] = U^-1 b[:rank], U the upper triangle of A's leading rank x rank block."""
    for i in range(rank - 1, -1, -1):
        s = b[i]
        for j in range(i + 1, rank):
            s -= A[i, j] * b[j]
        b[i] = s / A[i, i]


@njit(cache=True, **REFERENCE_COUNTED)
def lu_solve_inplace(A: FloatArray, b: FloatArray, rel_pivot_tol: float) -> bool:
    """Solve ``A x = b`` by Gaussian elimination with partial pivoting, in place.

    Args:
        A: (n, n) matrix; overwritten by its LU factors.
        b: (n,) right-hand side; overwritten by the solution x.
        rel_pivot_tol: a pivot smaller than ``rel_pivot_tol * max|A|`` counts as singular.

    Returns:
        True on success, False if A is singular to that tolerance (A, b then hold garbage).
    """
    n = A.shape[0]
    scale = 0.0
    for i in range(n):
        for j in range(n):
            a = abs(A[i, j])
            if a > scale:
                scale = a
    if n == 0:
        return True
    if scale == 0.0:
        return False
    threshold = rel_pivot_tol * scale
    for k in range(n):
        p, best = _column_pivot(A, k)
        if best <= threshold:
            return False
        _eliminate_below(A, b, k, p)
    _back_substitute(A, b, n)
    return True




@njit(cache=True, **REFERENCE_COUNTED)
def solve_consistent_inplace(A: FloatArray, b: FloatArray, swaps: FloatArray,
                             rel_pivot_tol: float, rel_consistency_tol: float) -> bool:
    """Solve a possibly singular but consistent ``A x = b`` in place, in one elimination.

    Gaussian elimination with partial pivoting in which a column without a pivot above
    ``rel_pivot_tol * max|A|`` (among the rows not yet eliminated) is deferred: swapped with the
    last column not yet deferred, its unknown becoming free. On a regular matrix nothing is
    deferred and this is exactly ``lu_solve_inplace``'s elimination. The numerical rank r is n
    minus the deferred columns. The system counts as consistent when the eliminated
    right-hand side's last n - r entries are at most ``rel_consistency_tol * max|b|``; then x
    solves the r independent equations with the free unknowns at 0 (a basic solution; for
    duplicated rows, an exact solution of all of them). A duplicated row is eliminated to
    exact zeros (its multiplier is 1). One pass costs about one regular solve, where a failed
    LU followed by complete pivoting (the former path for the robot's singular Newton systems)
    cost the LU plus a complete-pivoting search over every remaining entry at every step.

    Args:
        A: (n, n) matrix; overwritten by its factors. b: (n,) right-hand side; overwritten by
            x on success (garbage otherwise).
        swaps: (n,) scratch: the column with which each deferred position was swapped
            (indices held as floats, so that callers can lend a float work vector).
        rel_pivot_tol, rel_consistency_tol: relative tolerances as above.

    Returns:
        True if solved, False if inconsistent (or A = 0 with b != 0).
    """
    n = A.shape[0]
    scale = 0.0
    b_scale = 0.0
    for i in range(n):
        b_scale = max(b_scale, abs(b[i]))
        for j in range(n):
            scale = max(scale, abs(A[i, j]))
    threshold = rel_pivot_tol * scale
    last = n - 1  # the last column not deferred
    k = 0
    while k <= last:
        p, best = _column_pivot(A, k)
        if not best > threshold:  # no pivot among the remaining rows: defer column k
            if k < last:
                for i in range(n):
                    A[i, k], A[i, last] = A[i, last], A[i, k]
            swaps[last] = k
            last -= 1
            continue
        _eliminate_below(A, b, k, p)
        k += 1
    rank = k
    for i in range(rank, n):
        if abs(b[i]) > rel_consistency_tol * b_scale:
            return False
        b[i] = 0.0  # the free unknowns
    _back_substitute(A, b, rank)  # the pivoted unknowns, in the swapped column order
    for j in range(rank, n):  # undo the deferrals, the last one made first
        c = int(swaps[j])
        b[j], b[c] = b[c], b[j]
    return True


@njit(cache=True, **REFERENCE_COUNTED)
def invert_into(A: FloatArray, out: FloatArray, work: FloatArray, column: FloatArray) -> bool:
    """Write A^-1 into ``out`` by one LU solve per column (for the stepper's small matrices).

    Args:
        A: (n, n) matrix (not modified).
        out: (n, n) output, overwritten by A^-1.
        work: (n, n) workspace. column: (n,) workspace.

    Returns:
        False if A is singular (relative pivot below 1e-14); ``out`` then holds garbage.

    A 2 x 2 matrix is inverted in closed form (its adjugate over the determinant), singular
    when |det| <= 1e-14 max|A|^2: the stepper's most common case at a third of the cost.
    """
    n = A.shape[0]
    if n == 2:
        a, b, c, d = A[0, 0], A[0, 1], A[1, 0], A[1, 1]
        det = a * d - b * c
        scale = max(max(abs(a), abs(b)), max(abs(c), abs(d)))
        if not abs(det) > 1e-14 * scale * scale:
            return False
        inv = 1.0 / det
        out[0, 0] = d * inv
        out[0, 1] = -b * inv
        out[1, 0] = -c * inv
        out[1, 1] = a * inv
        return True
    for j in range(n):
        for r in range(n):
            for c in range(n):
                work[r, c] = A[r, c]
            column[r] = 1.0 if r == j else 0.0
        if not lu_solve_inplace(work, column, 1e-14):
            return False
        for r in range(n):
            out[r, j] = column[r]
    return True


@njit(cache=True, **REFERENCE_COUNTED)
def dominates(A: FloatArray, M: FloatArray, fraction: float, work: FloatArray) -> bool:
    """Whether the symmetric part of A - fraction M is positive definite (A, M: (n, n)).

    For an iteration matrix A = M - E that perturbs an SPD mass matrix M this says the
    perturbation E removes less than (1 - fraction) of M's inertia in every direction:
    x^T A x > fraction x^T M x for all x != 0. Cholesky of (A + A^T) / 2 - fraction M in
    ``work`` (n, n), overwritten.
    """
    n = A.shape[0]
    for r in range(n):
        for c in range(n):
            work[r, c] = 0.5 * (A[r, c] + A[c, r]) - fraction * M[r, c]
    for j in range(n):
        pivot = work[j, j]
        for t in range(j):
            pivot -= work[j, t] * work[j, t]
        if not pivot > 0.0:
            return False
        pivot = math.sqrt(pivot)
        work[j, j] = pivot
        for r in range(j + 1, n):
            acc = work[r, j]
            for t in range(j):
                acc -= work[r, t] * work[j, t]
            work[r, j] = acc / pivot
    return True


__all__ = ["dominates", "invert_into", "lu_solve_inplace", "solve_consistent_inplace"]
