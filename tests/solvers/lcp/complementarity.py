"""Shared checks and problem generators for the LCP tests.

Import as ``from solvers.lcp.complementarity import ...`` (``tests`` is on pytest's ``pythonpath``
and ``solvers`` is a namespace package there).

Every check recomputes ``w = M z + q`` from the data with numpy; nothing trusts a stored answer.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from hypothesis import HealthCheck, settings
from hypothesis import strategies as st

from mdi_envs.solvers import SolverStatus

# Deterministic, small Hypothesis runs (the LCP suite must stay well under a minute).
HYPOTHESIS_SETTINGS = settings(
    max_examples=25,
    deadline=None,
    derandomize=True,
    database=None,
    print_blob=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)

METHODS = ("lemke", "pgs", "newton_fb", "enumerative")


def natural_residual(M: np.ndarray, q: np.ndarray, z: np.ndarray) -> float:
    """``||min(z, M z + q)||_2 / max(||q||_2, 1)`` computed with numpy (not the package)."""
    w = M @ z + q
    return float(np.linalg.norm(np.minimum(z, w)) / max(np.linalg.norm(q), 1.0))


def complementarity_scale(M: np.ndarray, q: np.ndarray, z: np.ndarray) -> float:
    """Magnitude of the terms that make up w = M z + q (at least 1)."""
    z_max = float(np.max(np.abs(z))) if z.size else 0.0
    m_max = float(np.max(np.abs(M))) if M.size else 0.0
    q_max = float(np.max(np.abs(q))) if q.size else 0.0
    return max(1.0, q_max, m_max * z_max)


def assert_complementary(
    M: np.ndarray, q: np.ndarray, z: np.ndarray, w: np.ndarray | None, tol: float
) -> None:
    """Assert directly that z solves LCP(M, q) to ``tol`` relative to the data's scale.

    Checks z >= -tol*scale, w >= -tol*scale, min(|z_i|, |w_i|) <= tol*scale for every i,
    |z . w| <= tol * scale * (||z||_1 + ||w||_1), and, when ``w`` is given, that it equals
    ``M z + q`` recomputed here.
    """
    M = np.asarray(M, dtype=float)
    q = np.asarray(q, dtype=float)
    z = np.asarray(z, dtype=float)
    assert z.shape == q.shape, f"z has shape {z.shape}, expected {q.shape}"
    assert np.all(np.isfinite(z)), "z has non-finite entries"
    w_true = M @ z + q
    scale = complementarity_scale(M, q, z)
    if w is not None:
        w = np.asarray(w, dtype=float)
        assert w.shape == q.shape
        rounding = 16 * np.finfo(float).eps * scale * max(1, q.size)
        np.testing.assert_allclose(w, w_true, rtol=0.0, atol=rounding)
    bound = tol * scale
    assert z.min(initial=0.0) >= -bound, f"z has a negative entry {z.min()} (bound {bound:g})"
    assert w_true.min(initial=0.0) >= -bound, (
        f"w = Mz+q has a negative entry {w_true.min()} (bound {bound:g})"
    )
    pair_min = np.minimum(np.abs(z), np.abs(w_true))
    worst = int(np.argmax(pair_min)) if pair_min.size else 0
    assert pair_min.max(initial=0.0) <= bound, (
        f"pair {worst} is not complementary: z={z[worst]!r}, w={w_true[worst]!r} "
        f"(bound {bound:g})"
    )
    gap = abs(float(z @ w_true))
    gap_bound = bound * (np.abs(z).sum() + np.abs(w_true).sum())
    assert gap <= gap_bound, f"|z.w| = {gap:g} exceeds {gap_bound:g}"


def assert_result_consistent(M: np.ndarray, q: np.ndarray, result: object) -> None:
    """Assert that an ``LCPResult``'s stored w and residual match the data and its z."""
    z = result.z
    assert z.shape == q.shape
    # Rounding of the n-term sums in w: the stored and the recomputed values may differ by that.
    rounding = 16 * np.finfo(float).eps * complementarity_scale(M, q, z) * max(1, q.size)
    np.testing.assert_allclose(result.w, M @ z + q, rtol=0.0, atol=rounding)
    expected = natural_residual(M, q, z)
    slack = 1e-9 * expected + rounding * np.sqrt(max(1, q.size)) / max(np.linalg.norm(q), 1.0)
    assert abs(result.residual - expected) <= slack, (result.residual, expected)
    assert isinstance(result.status, SolverStatus)
    assert isinstance(result.num_iter, int) and result.num_iter >= 0, repr(result.num_iter)


def assert_solved(M: np.ndarray, q: np.ndarray, result: object, tol: float = 1e-10) -> None:
    """Assert CONVERGED, the residual (recomputed) within ``tol`` and complementarity."""
    assert result.status is SolverStatus.CONVERGED, (result.status, result.residual)
    assert_result_consistent(M, q, result)
    assert natural_residual(M, q, result.z) <= tol
    assert_complementary(M, q, result.z, result.w, tol=max(tol, 1e-9))


def assert_honest(M: np.ndarray, q: np.ndarray, result: object, tol: float = 1e-10) -> None:
    """The honesty property: CONVERGED <=> residual <= tol; when CONVERGED, z solves the LCP."""
    assert_result_consistent(M, q, result)
    residual = natural_residual(M, q, result.z)
    converged = result.status is SolverStatus.CONVERGED
    assert converged == (residual <= tol), (
        f"status {result.status.name} but recomputed residual {residual:g} (tol {tol:g})"
    )
    if converged:
        assert_complementary(M, q, result.z, result.w, tol=max(tol, 1e-9))


# --------------------------------------------------------------------------------------------
# Generators: problems with a planted solution (z*, w*): q = w* - M z*.


def diagonally_dominant_p_matrix(rng: np.random.Generator, n: int) -> np.ndarray:
    """Non-symmetric, strictly row diagonally dominant with positive diagonal, hence a P-matrix."""
    M = rng.uniform(-1.0, 1.0, (n, n))
    np.fill_diagonal(M, 0.0)
    M[np.diag_indices(n)] = np.abs(M).sum(axis=1) + rng.uniform(0.2, 1.0, n)
    return M


def gram_pd(rng: np.random.Generator, n: int) -> np.ndarray:
    """Symmetric positive definite ``A A^T / n + delta I`` (delta >= 0.2, well conditioned)."""
    A = rng.standard_normal((n, n))
    return A @ A.T / n + rng.uniform(0.2, 1.0) * np.eye(n)


def nonsymmetric_pd(rng: np.random.Generator, n: int) -> np.ndarray:
    """Non-symmetric positive definite (SPD plus a skew part), hence a P-matrix."""
    K = rng.standard_normal((n, n)) / np.sqrt(n)
    return gram_pd(rng, n) + K - K.T


def psd_singular(rng: np.random.Generator, n: int, rank: int, integer: bool) -> np.ndarray:
    """Symmetric positive semidefinite ``B B^T`` of the given rank (< n: singular)."""
    if integer:
        B = rng.integers(-2, 3, (n, rank)).astype(float)
    else:
        B = rng.standard_normal((n, rank))
    return B @ B.T


def planted_pair(
    rng: np.random.Generator, n: int, degenerate_fraction: float, integer: bool
) -> tuple[np.ndarray, np.ndarray]:
    """Complementary z*, w* >= 0; about ``degenerate_fraction`` of the pairs have z_i = w_i = 0.

    At least one pair has z_i > 0 so that the problem is not trivial (q >= 0) by construction.
    """
    role = rng.choice(3, size=n, p=[(1 - degenerate_fraction) / 2] * 2 + [degenerate_fraction])
    role[rng.integers(n)] = 1
    if integer:
        values = rng.integers(1, 4, n).astype(float)
    else:
        values = rng.uniform(0.1, 2.0, n)
    z = np.where(role == 1, values, 0.0)
    w = np.where(role == 0, values[::-1], 0.0)
    return z, w


@dataclass(frozen=True)
class Planted:
    """An LCP(M, q) with a known solution (z*, w*); ``kind`` names the matrix class."""

    M: np.ndarray
    q: np.ndarray
    z: np.ndarray
    w: np.ndarray
    kind: str

    @property
    def n(self) -> int:
        """Problem size."""
        return int(self.q.shape[0])


KINDS = ("p_diag_dominant", "spd", "pd_nonsymmetric", "psd_singular")


@st.composite
def planted_problems(
    draw: st.DrawFn,
    kind: str,
    max_n: int,
    min_n: int = 2,
    degenerate: bool | None = None,
    integer: bool | None = None,
) -> Planted:
    """Hypothesis strategy: a planted LCP of ``kind`` with n in [min_n, max_n].

    The matrix and the planted pair come from a seeded numpy generator (drawing n^2 floats
    through Hypothesis would exceed its buffer at n = 100); Hypothesis draws the size, the seed,
    the degeneracy, integrality (exact ties in Lemke's ratio test) and the scale of q.
    """
    n = draw(st.integers(min_n, max_n), label="n")
    seed = draw(st.integers(0, 2**32 - 1), label="seed")
    if degenerate is None:
        fraction = draw(st.sampled_from([0.0, 0.3, 0.6]), label="degenerate_fraction")
    else:
        fraction = draw(st.sampled_from([0.3, 0.6])) if degenerate else 0.0
    if integer is None:
        integer = kind == "psd_singular" and draw(st.booleans(), label="integer")
    scale = 1.0 if integer else 10.0 ** draw(st.integers(-4, 4), label="log10_scale")
    rng = np.random.default_rng(seed)
    if kind == "p_diag_dominant":
        M = diagonally_dominant_p_matrix(rng, n)
    elif kind == "spd":
        M = gram_pd(rng, n)
    elif kind == "pd_nonsymmetric":
        M = nonsymmetric_pd(rng, n)
    elif kind == "psd_singular":
        rank = draw(st.integers(1, max(1, n - 1)), label="rank")
        M = psd_singular(rng, n, rank, integer)
    else:  # pragma: no cover - programming error in a test
        raise ValueError(kind)
    z, w = planted_pair(rng, n, fraction, integer)
    z, w = z * scale, w * scale
    return Planted(M, w - M @ z, z, w, kind)


__all__ = [
    "HYPOTHESIS_SETTINGS",
    "KINDS",
    "METHODS",
    "Planted",
    "assert_complementary",
    "assert_honest",
    "assert_result_consistent",
    "assert_solved",
    "complementarity_scale",
    "diagonally_dominant_p_matrix",
    "gram_pd",
    "natural_residual",
    "nonsymmetric_pd",
    "planted_pair",
    "planted_problems",
    "psd_singular",
]
