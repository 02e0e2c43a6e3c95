"""Contacts that share a normal row of W, and the move that unloads one contact of each pair.

Two contact points between the same two bodies with the same normal (a box face on a box face,
a rock resting on two points of another) give contacts i, j whose normal rows of the Delassus
matrix coincide: ``W[3i] ~ W[3j]``. Then ``u_N,i - u_N,j = q_N,i - q_N,j`` (up to the rows'
tiny difference) whatever r is, so both cannot have u_N = 0 unless their q_N agree: in an exact
solution only the contact with the lower normal velocity of such a pair can carry load.
Newton-type methods and fixed points spread the load over both and then stall (both normal
velocities stay a little positive while both impulses are inside the cone's interior or on its
boundary). ``unload_duplicates`` moves the whole impulse of the contact with the higher u_N
onto the other one, a change of regime that the following Newton steps cannot make themselves.
"""

from __future__ import annotations

import numpy as np

from mdi_envs._types import FloatArray, IntArray

DUPLICATE_COSINE = 0.999
"""Cosine between two normal rows of W above which the contacts count as one normal pair."""
LOADED_FRACTION = 1e-8
"""A contact counts as loaded when its normal impulse exceeds this fraction of the largest."""


def duplicate_normal_pairs(W: FloatArray, cosine: float = DUPLICATE_COSINE) -> IntArray:
    """Pairs (i, j), i < j, of contacts whose normal rows of W (3 nc, 3 nc) are parallel.

    Returns:
        (m, 2) integer array of contact indices, rows sorted.
    """
    normals = W[0::3]
    norms = np.linalg.norm(normals, axis=1)
    unit = normals / np.where(norms > 0.0, norms, 1.0)[:, None]
    cosines = np.triu(unit @ unit.T, k=1)
    return np.argwhere(cosines > cosine).astype(np.int64)


def unload_duplicates(
    W: FloatArray, q: FloatArray, r: FloatArray, pairs: IntArray
) -> tuple[FloatArray, int]:
    """Move each loaded pair's impulse onto the contact with the lower normal velocity.

    Args:
        W: (3 nc, 3 nc). q: (3 nc,). r: (3 nc,) impulses (not modified).
        pairs: (m, 2) contact pairs from ``duplicate_normal_pairs``.

    Returns:
        (the new impulses (3 nc,), the number of pairs whose load was moved). A pair is moved
        when both of its contacts are loaded (normal impulse above ``LOADED_FRACTION`` of the
        largest); pairs are visited in order, all judged by the normal velocities of r.
    """
    R = r.reshape(-1, 3).copy()
    u_n = (W @ r + q)[0::3]
    loaded = LOADED_FRACTION * max(float(R[:, 0].max(initial=0.0)), 0.0)
    moved = 0
    for i, j in pairs:
        if R[i, 0] > loaded and R[j, 0] > loaded:
            high, low = (i, j) if u_n[i] > u_n[j] else (j, i)
            R[low] += R[high]
            R[high] = 0.0
            moved += 1
    return R.reshape(-1), moved


__all__ = ["DUPLICATE_COSINE", "LOADED_FRACTION", "duplicate_normal_pairs", "unload_duplicates"]
