"""An independent checker of planar Coulomb solutions, in plain numpy (no package kernels).

The conditions are checked one by one (Signorini, the friction interval, stick and slide), not
through the package's residual, so that the tests judge the solvers independently of it.
"""

from __future__ import annotations

import numpy as np


def natural_residual_2d(W: object, q: np.ndarray, mu: np.ndarray, r: np.ndarray) -> float:
    """``||r - P_K(r - u_hat)|| / max(||q||, 1)`` recomputed from scratch (W dense or sparse)."""
    u = (W @ r + q).reshape(-1, 2)
    R = r.reshape(-1, 2)
    x_n = R[:, 0] - (u[:, 0] + mu * np.abs(u[:, 1]))
    x_t = R[:, 1] - u[:, 1]
    t = np.abs(x_t)
    inside = (t <= mu * x_n) & (x_n >= 0.0)
    polar = mu * t <= -x_n
    beta = (x_n + mu * t) / (1.0 + mu * mu)
    p_n = np.where(inside, x_n, np.where(polar, 0.0, beta))
    p_t = np.where(inside, x_t, np.where(polar, 0.0, mu * beta * np.sign(x_t)))
    error = np.hypot(R[:, 0] - p_n, R[:, 1] - p_t)
    return float(np.linalg.norm(error) / max(np.linalg.norm(q), 1.0))


def assert_coulomb_2d(
    W: object, q: np.ndarray, mu: np.ndarray, r: np.ndarray, tol: float
) -> dict[str, int]:
    """Assert that r solves FC2D(W, q, mu) to ``tol`` by the Coulomb conditions themselves.

    With delta = tol * max(||q||, 1): r_N >= -delta, |r_T| <= mu r_N + 2 delta,
    u_N >= -10 (1 + mu) delta, |r_N u_N| small, a contact clearly inside the friction interval
    does not slip, and a slipping contact pushes back at mu r_N against the slip.

    Returns:
        How many contacts take off, stick and slide.
    """
    q, mu, r = (np.asarray(a, dtype=float) for a in (q, mu, r))
    assert np.all(np.isfinite(r))
    residual = natural_residual_2d(W, q, mu, r)
    assert residual <= tol, f"natural-map residual {residual:.3e} > {tol:.1e}"
    delta = tol * max(np.linalg.norm(q), 1.0)
    R = r.reshape(-1, 2)
    U = np.asarray(W @ r + q).reshape(-1, 2)
    r_n, r_t, u_n, u_t = R[:, 0], R[:, 1], U[:, 0], U[:, 1]
    scale = np.hypot(r_n, r_t) + np.hypot(u_n, u_t) + delta
    assert np.all(r_n >= -delta), "negative normal impulse"
    assert np.all(np.abs(r_t) <= mu * r_n + 2.0 * delta), "friction outside mu r_N"
    assert np.all(u_n >= -10.0 * (1.0 + mu) * delta), "penetrating normal velocity"
    assert np.all(np.abs(r_n * u_n) <= 10.0 * delta * scale), "Signorini violated"
    active = r_n > 10.0 * delta
    margin = mu * r_n - np.abs(r_t)
    stick = active & (margin > 1e-3 * r_n)
    assert np.all(
        np.abs(u_t[stick]) * margin[stick] <= 10.0 * delta * scale[stick]
    ), "a sticking contact slips"
    slide = active & ~stick & (np.abs(u_t) > 10.0 * delta * (1.0 + mu))
    assert np.all(
        np.abs(r_t[slide] + mu[slide] * r_n[slide] * np.sign(u_t[slide]))
        <= 10.0 * delta * scale[slide] / np.abs(u_t[slide]) + 2.0 * delta
    ), "a sliding contact's friction is not -mu r_N sign(u_T)"
    return {
        "take_off": int(np.sum(~active)),
        "stick": int(np.sum(stick)),
        "slide": int(np.sum(slide)),
    }
