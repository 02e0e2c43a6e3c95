"""Independent checks of a model's equations from its Lagrangian (helpers for the model tests).

For L = T - V with T = u^T M(q) u / 2, the Euler-Lagrange equations give
M(q) u' = h(q, u) + B tau with

    h_i = -sum_jk dM_ij/dq_k u_k u_j + 1/2 sum_jk dM_jk/dq_i u_j u_k - dV/dq_i,

so h follows from M and a potential V alone. ``lagrangian_forces`` evaluates this with central
finite differences of ``mass_matrix`` (and of V), never calling the model's ``forces``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
from scipy.integrate import solve_ivp

Potential = Callable[[np.ndarray, Any], float]


def mass(model: type, q: np.ndarray, p: Any) -> np.ndarray:
    return np.array(model.mass_matrix(q, p, math), dtype=float)


def forces(model: type, q: np.ndarray, u: np.ndarray, p: Any) -> np.ndarray:
    return np.array(model.forces(q, u, p, math), dtype=float)


def inputs(model: type, q: np.ndarray, p: Any) -> np.ndarray:
    return np.array(model.input_matrix(q, p, math), dtype=float).reshape(
        model.NUM_DOFS, model.NUM_INPUTS
    )


def lagrangian_forces(model: type, q: np.ndarray, u: np.ndarray, p: Any, potential: Potential,
                      step: float = 1e-6) -> np.ndarray:  # fmt: skip
    """h(q, u) from M(q) and V(q) by central differences (see the module docstring)."""
    n = len(q)
    d_mass = np.empty((n, n, n))  # d_mass[k] = dM/dq_k
    d_potential = np.empty(n)
    for k in range(n):
        e = np.zeros(n)
        e[k] = step
        d_mass[k] = (mass(model, q + e, p) - mass(model, q - e, p)) / (2 * step)
        d_potential[k] = (potential(q + e, p) - potential(q - e, p)) / (2 * step)
    m_dot = np.einsum("kij,k->ij", d_mass, u)
    return -m_dot @ u + 0.5 * np.einsum("kij,i,j->k", d_mass, u, u) - d_potential


def smooth_energy_balance(model: type, p: Any, potential: Potential, q0: np.ndarray,
                          u0: np.ndarray, torque: Callable[[float], np.ndarray],
                          t_end: float) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """Integrate M u' = h + B tau (no contacts) with the input's work W' = tau . B^T u.

    Returns (E(t) - E(0), W(t)) on the solver's output grid, E = T + V: equal for a correct h.
    """
    n = len(q0)

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        q, u = y[:n], y[n : 2 * n]
        generalized = inputs(model, q, p) @ torque(t)
        acceleration = np.linalg.solve(mass(model, q, p), forces(model, q, u, p) + generalized)
        return np.concatenate([u, acceleration, [generalized @ u]])

    solution = solve_ivp(rhs, (0.0, t_end), np.concatenate([q0, u0, [0.0]]), method="DOP853",
                         rtol=1e-11, atol=1e-12, dense_output=False)  # fmt: skip
    assert solution.success
    y = solution.y
    energy = np.array([
        0.5 * y[n : 2 * n, i] @ mass(model, y[:n, i], p) @ y[n : 2 * n, i] + potential(y[:n, i], p)
        for i in range(y.shape[1])
    ])  # fmt: skip
    return energy - energy[0], y[2 * n]
