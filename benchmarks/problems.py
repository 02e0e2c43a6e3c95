"""The LCP benchmark's problems and the solver entries under test.

Problems: two seeded random LCP families and the Siconos peer LCP files. ``spd``:
``M = A A^T / n + 0.1 I``; ``contact``: a redundant-contact Delassus matrix regularized as
constraint-force mixing does. Every instance follows from ``(SEED, family, n, instance)``.
Entries: each timed on its bare call, its outcome read afterwards.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from quantecon.optimize import lcp_lemke

from mdi_envs._types import FloatArray
from mdi_envs.solvers.lcp import lcp_residual, solve_lcp
from mdi_envs.solvers.lcp.lemke import LemkeOptions, lemke_solve
from mdi_envs.solvers.siconos_io import read_lcp
from mdi_envs.solvers.status import SolverStatus

SEED = 20_240_601  # Root seed of every random benchmark problem.
CONTACTS_PER_BODY = 6
CFM_SHIFT = 0.01
"""Diagonal shift of the contact family, relative to the mean diagonal of ``J J^T``."""

Generator = Callable[[np.random.Generator, int], tuple[FloatArray, FloatArray]]


@dataclass(frozen=True)
class Problem:
    """One LCP instance of the benchmark."""

    name: str
    family: str
    n: int
    M: FloatArray
    q: FloatArray


def spd_lcp(rng: np.random.Generator, n: int) -> tuple[FloatArray, FloatArray]:
    """Symmetric positive definite ``M = A A^T / n + 0.1 I`` and ``q ~ N(0, I)``."""
    A = rng.standard_normal((n, n))
    return A @ A.T / n + 0.1 * np.eye(n), rng.standard_normal(n)


def contact_lcp(rng: np.random.Generator, n: int) -> tuple[FloatArray, FloatArray]:
    """Regularized redundant-contact Delassus matrix and free-velocity ``q = J v``."""
    num_bodies = math.ceil(n / CONTACTS_PER_BODY)
    J = np.zeros((n, 3 * num_bodies))
    for i in range(n):
        angle = rng.uniform(0.0, 2.0 * np.pi)
        normal = np.array([np.cos(angle), np.sin(angle)])
        body = i % num_bodies
        _add_contact_row(J[i], body, normal, rng.normal(0.0, 0.5, 2))
        if i % 2 == 1 and num_bodies > 1:
            _add_contact_row(J[i], (body + 1) % num_bodies, -normal, rng.normal(0.0, 0.5, 2))
    W = J @ J.T
    M = W + CFM_SHIFT * float(np.mean(np.diag(W))) * np.eye(n)
    return M, J @ rng.standard_normal(J.shape[1])


def _add_contact_row(row: FloatArray, body: int, normal: FloatArray, arm: FloatArray) -> None:
    """Add a body's normal-velocity Jacobian ``(n_x, n_y, arm x n)`` to ``row`` (in place)."""
    row[3 * body : 3 * body + 2] += normal
    row[3 * body + 2] += arm[0] * normal[1] - arm[1] * normal[0]


FAMILIES: dict[str, Generator] = {"spd": spd_lcp, "contact": contact_lcp}


def random_problem(family: str, n: int, instance: int) -> Problem:
    """Instance ``instance`` of size n of a random family (deterministic)."""
    family_id = list(FAMILIES).index(family)
    rng = np.random.default_rng([SEED, family_id, n, instance])
    M, q = FAMILIES[family](rng, n)
    return Problem(f"{family}-n{n}-i{instance}", family, n, np.ascontiguousarray(M), q)


def peer_data_dir() -> Path:
    """Root of the Siconos peer data: ``$MDI_ENVS_PEER_DATA`` or ``<repo>/../shared/...``."""
    default = Path(__file__).resolve().parents[1].parent / "shared" / "peer-data" / "siconos"
    return Path(os.environ.get("MDI_ENVS_PEER_DATA", default))


def peer_lcp_problems(root: Path | None = None) -> list[Problem]:
    """Every ``lcp/*.dat`` file under the peer data root, sorted by name; [] if absent."""
    folder = (root or peer_data_dir()) / "lcp"
    problems = []
    for path in sorted(folder.glob("*.dat")) if folder.is_dir() else []:
        M, q = read_lcp(path)
        problems.append(Problem(path.stem, "siconos", q.shape[0], np.ascontiguousarray(M), q))
    return problems

LCP_METHODS = ("lemke", "pgs", "newton_fb", "enumerative")  # of solve_lcp, in the size study
ENUMERATIVE_MAX_N = 10  # largest n of the exhaustive method (2^n index sets)
QUANTECON_MAX_ITER = 10_000  # QuantEcon's pivot cap (its default 10^6 cycles on lcp_tobenna)
QUANTECON_STATUS = {0: "0 (solved)", 1: "1 (iteration limit)", 2: "2 (secondary ray)"}
_LEMKE = LemkeOptions()


@dataclass(frozen=True)
class Outcome:
    """A solve's own success flag and status, its iterations and the shared residual measure."""

    success: bool
    status: str
    iterations: int
    residual: float


@dataclass(frozen=True)
class Entry:
    """A timed ``solve(M, q)`` and ``read(raw, M, q) -> Outcome`` of its raw result."""

    name: str
    label: str
    solve: Callable[[FloatArray, FloatArray], Any]
    read: Callable[[Any, FloatArray, FloatArray], Outcome]


def driver_entry(method: str) -> Entry:
    """The public driver ``solve_lcp(M, q, method=method)`` (validation + residual included)."""
    return Entry(method, f"solve_lcp(method={method!r})",
                 lambda M, q: solve_lcp(M, q, method=method),
                 lambda r, M, q: Outcome(r.status is SolverStatus.CONVERGED, r.status.name,
                                         int(r.num_iter), float(r.residual)))


def _kernel_read(raw: Any, M: FloatArray, q: FloatArray) -> Outcome:
    z, code, pivots = raw
    status = SolverStatus(code)
    return Outcome(status is SolverStatus.CONVERGED, status.name, int(pivots),
                   lcp_residual(M, q, z))


KERNEL = Entry("lemke_solve", "lemke_solve (compiled entry)",
               lambda M, q: lemke_solve(M, q, _LEMKE.max_iter, _LEMKE.pivot_tol, _LEMKE.tie_tol,
                                        _LEMKE.tol), _kernel_read)
QUANTECON = Entry("quantecon", "quantecon.optimize.lcp_lemke (compiled)",
                  lambda M, q: lcp_lemke(M, q, max_iter=QUANTECON_MAX_ITER),
                  lambda r, M, q: Outcome(bool(r.success),
                                          QUANTECON_STATUS.get(int(r.status), str(r.status)),
                                          int(r.num_iter), lcp_residual(M, q, r.z)))
DRIVER_LEMKE = driver_entry("lemke")

