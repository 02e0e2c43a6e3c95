"""The LCP solver entries under test: each timed on its bare call, its outcome read afterwards."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from quantecon.optimize import lcp_lemke

from mdi_envs._types import FloatArray
from mdi_envs.solvers.lcp import lcp_residual, solve_lcp
from mdi_envs.solvers.lcp.lemke import LemkeOptions, lemke_solve
from mdi_envs.solvers.status import SolverStatus

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


def size_study_entries(n: int) -> list[Entry]:
    """The driver methods applicable at size n, plus QuantEcon's Lemke for reference."""
    methods = [m for m in LCP_METHODS if m != "enumerative" or n <= ENUMERATIVE_MAX_N]
    return [driver_entry(m) for m in methods] + [QUANTECON]
