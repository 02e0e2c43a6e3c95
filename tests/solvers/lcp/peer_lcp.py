"""What we know about each peer (Siconos) LCP: ../shared/peer-data/siconos/README.md, section 2.

Structural claims used to decide what a method is *guaranteed* to do (P-matrix, symmetric PD,
uniqueness) are re-derived from the data in ``test_peer_table.py`` instead of being trusted.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from peer_data import PEER_DATA, peer_params

from mdi_envs.solvers.siconos_io import read_lcp


@dataclass(frozen=True)
class PeerLCP:
    """Facts about one peer LCP.

    Attributes:
        n: size.
        lemke_pivots: pivot count of a correct lexicographic Lemke (README table, checked against
            an exact-rational run).
        ray_reason: why RAY_TERMINATION is the correct Lemke outcome, or None if Lemke solves it.
        has_solution: whether a solution exists.
        unique: whether the solution is unique (so every method must find the same z).
        solution: the closed-form solution when the README states one.
        p_matrix: every principal minor positive.
        sym_pd: symmetric positive definite.
        sym_psd: symmetric positive semidefinite with a positive diagonal (PGS's class).
    """

    n: int
    lemke_pivots: int
    ray_reason: str | None = None
    has_solution: bool = True
    unique: bool = False
    solution: tuple[float, ...] | None = None
    p_matrix: bool = False
    sym_pd: bool = False
    sym_psd: bool = False


_SPD = {"unique": True, "p_matrix": True, "sym_pd": True, "sym_psd": True}

PEER_LCPS: dict[str, PeerLCP] = {
    "lcp_CPS_1": PeerLCP(2, 2, sym_psd=True),  # z1 + z2 = 1: a segment of solutions
    "lcp_CPS_2": PeerLCP(3, 5, unique=True, solution=(0.0, 1.0, 3.0)),
    "lcp_CPS_3": PeerLCP(
        4,
        1,
        ray_reason=(
            "bimatrix game M = [[0, A], [B^T, 0]]: M_rr = 0 on the first pivot's row, so Lemke "
            "ray-terminates for any covering vector although solutions exist"
        ),
    ),
    "lcp_CPS_4": PeerLCP(4, 5, unique=True, solution=(2.0, 2.0, 2.0, 92.0)),
    "lcp_CPS_4bis": PeerLCP(4, 5, unique=True, solution=(3.0, 3.0, 0.0, 83.0)),
    "lcp_CPS_5": PeerLCP(2, 2, sym_psd=True),  # z = (t, t + 1), t >= 0
    "lcp_Pang_isolated_sol": PeerLCP(3, 3, unique=True, solution=(1.0, 0.0, 0.0)),
    "lcp_Pang_isolated_sol_perturbed": PeerLCP(
        3,
        4,
        ray_reason="infeasible (no z >= 0 has Mz + q >= 0): the secondary ray is the answer",
        has_solution=False,
    ),
    "lcp_deudeu": PeerLCP(2, 3, solution=(4 / 3, 7 / 3), **_SPD),
    "lcp_deudeu_block": PeerLCP(2, 3, solution=(4 / 3, 7 / 3), **_SPD),
    "lcp_enum_fails": PeerLCP(9, 8, unique=True),
    "lcp_exp_murty": PeerLCP(6, 2, unique=True, p_matrix=True, solution=(0.0,) * 5 + (1.0,)),
    "lcp_exp_murty2": PeerLCP(6, 64, unique=True, p_matrix=True, solution=(0.0,) * 5 + (64.0,)),
    "lcp_inf_sol_perturbed": PeerLCP(3, 5),  # z = (1, t, t + 1e-4)
    "lcp_mmc": PeerLCP(26, 23, **_SPD),
    "lcp_ortiz": PeerLCP(4, 3, unique=True, p_matrix=True, solution=(2 / 3, 0.0, 1 / 3, 0.0)),
    "lcp_ortiz_block": PeerLCP(
        4, 3, unique=True, p_matrix=True, solution=(2 / 3, 0.0, 1 / 3, 0.0)
    ),
    "lcp_tobenna": PeerLCP(40, 127),
    "lcp_trivial": PeerLCP(9, 10, solution=tuple(1 / i for i in range(1, 10)), **_SPD),
    "lcp_trivial_block": PeerLCP(9, 10, solution=tuple(1 / i for i in range(1, 10)), **_SPD),
}


def lcp_params(names: list[str] | None = None) -> list[object]:
    """``pytest.param`` per peer LCP file (a single skipped param when ../shared is absent)."""
    return peer_params("lcp", names)


def names_where(predicate: object) -> list[str]:
    """Names of the peer LCPs whose ``PeerLCP`` satisfies ``predicate``."""
    return [name for name, info in PEER_LCPS.items() if predicate(info)]


@functools.cache
def _load(path: str) -> tuple[np.ndarray, np.ndarray]:
    return read_lcp(path)


def load(path: Path) -> tuple[np.ndarray, np.ndarray, PeerLCP]:
    """Read a peer LCP (cached; fresh copies returned) and its facts."""
    M, q = _load(str(path))
    return M.copy(), q.copy(), PEER_LCPS[path.stem]


__all__ = ["PEER_DATA", "PEER_LCPS", "PeerLCP", "lcp_params", "load", "names_where"]
