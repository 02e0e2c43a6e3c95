"""The solver entry points under test, each timed on its bare call and read afterwards."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from quantecon.optimize import lcp_lemke

from mdi_envs._types import FloatArray
from mdi_envs.solvers.lcp import lcp_residual, solve_lcp
from mdi_envs.solvers.lcp.lemke import LemkeOptions, lemke_solve
from mdi_envs.solvers.status import SolverStatus

LCP_METHODS = ("lemke", "pgs", "newton_fb", "enumerative")
"""Methods of ``solve_lcp`` in the work-size study."""

ENUMERATIVE_MAX_N = 10
"""Largest size the exhaustive method is run at (it examines 2^n index sets)."""

QUANTECON_MAX_ITER = 10_000
"""Pivot cap for QuantEcon (its default of 10^6 cycles for minutes on lcp_tobenna)."""

QUANTECON_STATUS = {0: "0 (solved)", 1: "1 (iteration limit)", 2: "2 (secondary ray)"}
"""QuantEcon's own status codes, reported in its own words."""

_LEMKE = LemkeOptions()


@dataclass(frozen=True)
class Outcome:
    """What one solve produced, in a form shared by every entry.

    Attributes:
        success: the entry's own success flag (ours: status CONVERGED, which includes our
            residual check; QuantEcon: its ``success``, which checks no residual).
        status: the entry's status in its own vocabulary.
        iterations: pivots, sweeps or Newton steps, as the entry counts them.
        residual: ``||min(z, M z + q)|| / max(||q||, 1)``, recomputed with ``lcp_residual``.
    """

    success: bool
    status: str
    iterations: int
    residual: float


@dataclass(frozen=True)
class Entry:
    """A timed callable and the reader of its raw result.

    Attributes:
        name: short key used in the JSON and tables.
        label: human-readable description for plots.
        solve: ``solve(M, q) -> raw result``; the only thing that is timed.
        read: ``read(raw, M, q) -> Outcome``.
    """

    name: str
    label: str
    solve: Callable[[FloatArray, FloatArray], Any]
    read: Callable[[Any, FloatArray, FloatArray], Outcome]


def driver_entry(method: str) -> Entry:
    """The public driver ``solve_lcp(M, q, method=method)`` (validation + residual included)."""

    def solve(M: FloatArray, q: FloatArray) -> Any:
        return solve_lcp(M, q, method=method)

    def read(result: Any, M: FloatArray, q: FloatArray) -> Outcome:
        return Outcome(
            result.status is SolverStatus.CONVERGED,
            result.status.name,
            int(result.num_iter),
            float(result.residual),
        )

    return Entry(method, f"solve_lcp(method={method!r})", solve, read)


def _kernel_solve(M: FloatArray, q: FloatArray) -> Any:
    """Our compiled Lemke entry with the driver's default options."""
    return lemke_solve(M, q, _LEMKE.max_iter, _LEMKE.pivot_tol, _LEMKE.tie_tol, _LEMKE.tol)


def _kernel_read(raw: Any, M: FloatArray, q: FloatArray) -> Outcome:
    """Outcome of ``lemke_solve``: (z, code, pivots); the residual is recomputed here."""
    z, code, pivots = raw
    status = SolverStatus(code)
    return Outcome(
        status is SolverStatus.CONVERGED, status.name, int(pivots), lcp_residual(M, q, z)
    )


def _quantecon_solve(M: FloatArray, q: FloatArray) -> Any:
    """QuantEcon's compiled Lemke with the pivot cap (all other options at its defaults)."""
    return lcp_lemke(M, q, max_iter=QUANTECON_MAX_ITER)


def _quantecon_read(raw: Any, M: FloatArray, q: FloatArray) -> Outcome:
    """Outcome of ``lcp_lemke``; its residual is recomputed with our measure."""
    return Outcome(
        bool(raw.success),
        QUANTECON_STATUS.get(int(raw.status), str(raw.status)),
        int(raw.num_iter),
        lcp_residual(M, q, raw.z),
    )


KERNEL = Entry("lemke_solve", "lemke_solve (compiled entry)", _kernel_solve, _kernel_read)
QUANTECON = Entry(
    "quantecon", "quantecon.optimize.lcp_lemke (compiled)", _quantecon_solve, _quantecon_read
)
DRIVER_LEMKE = driver_entry("lemke")


def size_study_entries(n: int) -> list[Entry]:
    """The driver methods applicable at size n, plus QuantEcon's Lemke for reference."""
    methods = [m for m in LCP_METHODS if m != "enumerative" or n <= ENUMERATIVE_MAX_N]
    return [driver_entry(m) for m in methods] + [QUANTECON]


__all__ = ["DRIVER_LEMKE", "ENUMERATIVE_MAX_N", "KERNEL", "LCP_METHODS", "QUANTECON",
           "QUANTECON_MAX_ITER", "QUANTECON_STATUS", "Entry", "Outcome", "driver_entry",
           "size_study_entries"]
