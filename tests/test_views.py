"""``array_view`` gives the same view as numba's slice-and-reshape, sharing the buffer."""

from __future__ import annotations

import gc
import weakref

import numpy as np
from numba import njit, typeof

from mdi_envs._borrowing import borrowing_njit
from mdi_envs._views import array_view


@njit
def _views(buffer: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return (array_view(buffer, 5, (3, 4)), array_view(buffer, 1, (2, 3, 2)),
            array_view(buffer[::2], 1, (2, 3)))


@borrowing_njit
def _write_through(buffer: np.ndarray) -> None:
    array_view(buffer, 4, (2, 2))[1, 1] = -1.0


def test_views_equal_reshaped_slices() -> None:
    buffer = np.arange(40.0)
    matrix, cube, strided = _views(buffer)
    np.testing.assert_array_equal(matrix, buffer[5:17].reshape(3, 4))
    np.testing.assert_array_equal(cube, buffer[1:13].reshape(2, 3, 2))
    np.testing.assert_array_equal(strided, buffer[::2][1:7].reshape(2, 3))
    assert typeof(matrix).layout == "C" and typeof(strided).layout == "A"
    assert matrix.flags.c_contiguous and matrix.base is not None


def test_writes_reach_the_buffer_and_views_keep_it_alive() -> None:
    buffer = np.zeros(16)
    _write_through(buffer)  # compiled without reference counting: a borrowed view
    assert buffer[7] == -1.0 and np.count_nonzero(buffer) == 1
    source = np.arange(40.0)
    alive = weakref.ref(source)
    matrix = _views(source)[0]
    del source
    gc.collect()
    assert alive() is not None  # referenced only through the returned view
    np.testing.assert_array_equal(matrix, np.arange(5.0, 17.0).reshape(3, 4))
    del matrix
    gc.collect()
    assert alive() is None  # and released with it
