"""One trivial cached numba kernel: the floor of a process start with numba (``probes.startup``)."""

import numpy as np
from numba import njit


@njit(cache=True)
def first_sum(values: np.ndarray) -> float:
    """Sum of a 1-d float array (trivial on purpose: its load, not its work, is measured)."""
    total = 0.0
    for value in values:
        total += value
    return total
