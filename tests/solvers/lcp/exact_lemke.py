"""Reference: Lemke's method in exact rational arithmetic, for checking the float kernel.

Same algorithm as ``mdi_envs.solvers.lcp.lemke`` -- covering vector d = 1, the most negative q_i
leaves first, the artificial variable leaves whenever it ties in the ratio test, otherwise the
lexicographic rule on the rows of B^-1 -- but with ``fractions.Fraction`` entries, so ties are
exact and there is no tolerance. Floats convert to fractions exactly, so the reference solves
exactly the problem the float kernel sees. Slow (pure Python): meant for n <= ~40 and a few
hundred pivots.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np


@dataclass(frozen=True)
class ExactLemkeResult:
    """Outcome of the exact run: ``status`` is "solved", "ray" or "max_iter"."""

    status: str
    z: tuple[Fraction, ...]
    pivots: int

    def z_float(self) -> np.ndarray:
        """The solution as floats."""
        return np.array([float(v) for v in self.z])


def exact_lemke(M: np.ndarray, q: np.ndarray, max_pivots: int = 10_000) -> ExactLemkeResult:
    """Run lexicographic Lemke on LCP(M, q) exactly; M (n, n), q (n,) floats."""
    M = np.asarray(M, dtype=float)
    q = np.asarray(q, dtype=float)
    n = q.shape[0]
    art = 2 * n
    if n == 0 or q.min() >= 0.0:
        return ExactLemkeResult("solved", tuple(Fraction(0) for _ in range(n)), 0)
    # Full tableau rows: [w_0..w_{n-1} | z_0..z_{n-1} | z_art | rhs] for w - M z - d z_art = q.
    rows = [
        [Fraction(int(i == j)) for j in range(n)]
        + [-Fraction(float(M[i, j])) for j in range(n)]
        + [Fraction(-1), Fraction(float(q[i]))]
        for i in range(n)
    ]
    basis = list(range(n))

    def lex_key(i: int, col: int) -> list[Fraction]:
        a = rows[i][col]
        return [rows[i][-1] / a] + [rows[i][k] / a for k in range(n)]

    # First pivot: the artificial enters; the row whose (q_i, e_i) is lexicographically smallest
    # leaves (the most negative q_i, ties to the largest index).
    r = min(range(n), key=lambda i: [rows[i][-1]] + [rows[i][k] for k in range(n)])
    entering = art
    pivots = 0
    while pivots < max_pivots:
        if pivots > 0:
            candidates = [i for i in range(n) if rows[i][entering] > 0]
            if not candidates:
                return ExactLemkeResult("ray", _basic_z(rows, basis, n), pivots)
            theta = min(rows[i][-1] / rows[i][entering] for i in candidates)
            ties = [i for i in candidates if rows[i][-1] / rows[i][entering] == theta]
            art_rows = [i for i in ties if basis[i] == art]
            r = art_rows[0] if art_rows else min(ties, key=lambda i: lex_key(i, entering))
        pivot = rows[r][entering]
        rows[r] = [v / pivot for v in rows[r]]
        for i in range(n):
            factor = rows[i][entering]
            if i != r and factor != 0:
                rows[i] = [a - factor * b for a, b in zip(rows[i], rows[r], strict=True)]
        leaving = basis[r]
        basis[r] = entering
        pivots += 1
        if leaving == art:
            return ExactLemkeResult("solved", _basic_z(rows, basis, n), pivots)
        entering = leaving + n if leaving < n else leaving - n
    return ExactLemkeResult("max_iter", _basic_z(rows, basis, n), pivots)


def _basic_z(rows: list[list[Fraction]], basis: list[int], n: int) -> tuple[Fraction, ...]:
    z = [Fraction(0)] * n
    for i, var in enumerate(basis):
        if n <= var < 2 * n:
            z[var - n] = rows[i][-1]
    return tuple(z)


__all__ = ["ExactLemkeResult", "exact_lemke"]
