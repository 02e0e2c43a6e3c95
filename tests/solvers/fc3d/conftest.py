"""Shared checks of FC3D solutions: the cone conditions themselves, in plain numpy.

Nothing here imports the package's kernels: the natural-map residual and the cone projection
are re-implemented so that the tests judge the solvers independently of their own residual.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pytest


def project_cone(mu: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Row-wise projection of x (nc, 3) onto the Coulomb cones {||x_T|| <= mu x_N}."""
    out = np.zeros_like(x)
    for i, (m, (xn, xt1, xt2)) in enumerate(zip(mu, x, strict=True)):
        t = np.hypot(xt1, xt2)
        if t <= m * xn and xn >= 0.0:
            out[i] = (xn, xt1, xt2)
        elif m * t <= -xn:
            out[i] = 0.0
        else:
            beta = (xn + m * t) / (1.0 + m * m)
            out[i] = (beta, m * beta * xt1 / t, m * beta * xt2 / t)
    return out


def natural_residual(W: np.ndarray, q: np.ndarray, mu: np.ndarray, r: np.ndarray) -> float:
    """``||r - P_K(r - u_hat)|| / max(||q||, 1)``, recomputed from scratch."""
    u = (W @ r + q).reshape(-1, 3)
    R = r.reshape(-1, 3)
    u_hat = u.copy()
    u_hat[:, 0] += mu * np.hypot(u[:, 1], u[:, 2])
    return float(np.linalg.norm(R - project_cone(mu, R - u_hat)) / max(np.linalg.norm(q), 1.0))


@dataclass(frozen=True)
class Regimes:
    """Which contacts the checker classified as taking off, sticking or sliding."""

    take_off: np.ndarray
    stick: np.ndarray
    slide: np.ndarray


def assert_coulomb(
    W: np.ndarray, q: np.ndarray, mu: np.ndarray, r: np.ndarray, tol: float
) -> Regimes:
    """Assert that r solves FC3D(W, q, mu) to ``tol`` by the cone conditions themselves.

    With delta = tol * max(||q||, 1) the absolute size of the natural-map error e, the
    conditions checked per contact follow from r - e in K, u_hat - e in K*, (r - e).(e - u_hat) = 0:
    r in K (to delta), u_N >= -(1 + mu) delta, |r_N u_N| small, ||u_T|| ~ 0 where r is clearly
    inside the cone (stick), and r_T ~ -mu r_N u_T / ||u_T|| where u_T != 0 (slide). The bounds
    carry a safety factor of 10 over what the algebra gives.
    """
    W, q, mu, r = (np.asarray(a, dtype=float) for a in (W, q, mu, r))
    assert np.all(np.isfinite(r))
    residual = natural_residual(W, q, mu, r)
    assert residual <= tol, f"natural-map residual {residual:.3e} > {tol:.1e}"
    delta = tol * max(np.linalg.norm(q), 1.0)
    R = r.reshape(-1, 3)
    U = (W @ r + q).reshape(-1, 3)
    r_n, r_t = R[:, 0], np.hypot(R[:, 1], R[:, 2])
    u_n, u_t = U[:, 0], np.hypot(U[:, 1], U[:, 2])
    r_norm = np.linalg.norm(R, axis=1)
    u_hat_norm = np.hypot(u_n + mu * u_t, u_t)
    slack = delta * (2.0 * r_norm + u_hat_norm + delta)

    assert np.all(r_n >= -delta), "negative normal impulse"
    assert np.all(r_t <= mu * r_n + 2.0 * delta), "impulse outside the friction cone"
    assert np.all(u_n >= -10.0 * (1.0 + mu) * delta), "penetrating normal velocity"
    assert np.all(np.abs(r_n * u_n) <= 10.0 * slack), "Signorini complementarity violated"

    margin = (mu * r_n - r_t) / np.sqrt(1.0 + mu * mu)
    stick = (r_n > 10.0 * delta) & (margin > 1e-3 * r_norm)
    assert np.all(
        u_t[stick] <= 10.0 * (slack[stick] + delta * r_norm[stick]) / margin[stick]
    ), "sticking contact slips"

    slide = (r_n > 10.0 * delta) & (u_t > 0.0) & ~stick
    safe_u_t = np.where(slide, u_t, 1.0)
    direction = U[:, 1:] / safe_u_t[:, None]
    error = np.linalg.norm(R[:, 1:] + (mu * r_n)[:, None] * direction, axis=1)
    bound = 10.0 * (slack / safe_u_t + np.sqrt(2.0 * r_t * slack / safe_u_t)) + 2.0 * delta
    assert np.all(error[slide] <= bound[slide]), "sliding impulse not opposite to the slip"
    return Regimes(take_off=r_n <= 10.0 * delta, stick=stick, slide=slide)


@pytest.fixture(scope="session")
def check_coulomb() -> Callable[..., Regimes]:
    """The cone-condition checker ``assert_coulomb(W, q, mu, r, tol)``."""
    return assert_coulomb


@pytest.fixture(scope="session")
def recompute_residual() -> Callable[..., float]:
    """The independent residual ``natural_residual(W, q, mu, r)``."""
    return natural_residual
