"""Pairs of contacts sharing a normal row of W, and the unloading move (``duplicate_contacts``)."""

from __future__ import annotations

import numpy as np

from mdi_envs.solvers.fc3d.duplicate_contacts import duplicate_normal_pairs, unload_duplicates


def _two_points_one_normal() -> tuple[np.ndarray, np.ndarray]:
    """Three contacts; 0 and 2 share the normal row (two points of one face), 1 does not."""
    H = np.array([
        [1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.3], [0.0, 0.0, 1.0, 0.0],
        [0.0, 1.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.5],
        [1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, -0.3], [0.0, 0.0, 1.0, 0.2],
    ])
    return H @ H.T, np.array([-1.0, 0.0, 0.0, -1.0, 0.0, 0.0, -0.9, 0.0, 0.0])


def test_pairs_are_the_contacts_with_parallel_normal_rows() -> None:
    W, _ = _two_points_one_normal()
    np.testing.assert_array_equal(duplicate_normal_pairs(W), [[0, 2]])
    assert duplicate_normal_pairs(np.eye(6)).shape == (0, 2)


def test_unload_moves_the_impulse_to_the_lower_normal_velocity() -> None:
    W, q = _two_points_one_normal()
    r = np.array([0.5, 0.1, 0.0, 1.0, 0.0, 0.0, 0.4, 0.0, 0.1])
    u_n = (W @ r + q)[0::3]
    assert u_n[0] < u_n[2]  # q_N,0 = -1 < q_N,2 = -0.9 and the rows agree: contact 0 is lower
    new_r, moved = unload_duplicates(W, q, r, duplicate_normal_pairs(W))
    assert moved == 1
    np.testing.assert_allclose(new_r, [0.9, 0.1, 0.1, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    np.testing.assert_array_equal(r[6:], [0.4, 0.0, 0.1])  # the input is not modified


def test_a_pair_with_one_unloaded_contact_is_left_alone() -> None:
    W, q = _two_points_one_normal()
    r = np.array([0.5, 0.1, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    new_r, moved = unload_duplicates(W, q, r, duplicate_normal_pairs(W))
    assert moved == 0
    np.testing.assert_array_equal(new_r, r)
