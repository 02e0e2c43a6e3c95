"""Readers for the Siconos text formats of LCP and friction-contact problems (``.dat`` files).

Siconos reads these files one whitespace-separated token at a time, except inside a CSparse dump,
which is line based. Dense matrices are stored column-major: each printed line of a square
matrix is one *column*. Formats: LCP ``n, <matrix>, q``; friction contact
``d, nc, <matrix>, q, mu``; a matrix block is ``storage, rows, cols`` followed by dense (0),
sparse-block (1) or CSparse (2) data.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from mdi_envs._types import FloatArray

_TOKEN = re.compile(r"\S+")
_CSPARSE_SIZE = re.compile(r"(\d+)-by-(\d+)")
_CSPARSE_COLUMN = re.compile(r"\s*col (\d+) : locations (-?\d+) to (-?\d+)")
_CSPARSE_ENTRY = re.compile(r"\s*(\d+) : (\S+)")


@dataclass(frozen=True)
class FrictionContactData:
    """A local friction-contact problem u = W r + q, r in the Coulomb cones, as read from file.

    Attributes:
        dimension: 2 or 3 (contact-space dimension d).
        W: (d * nc, d * nc) Delassus matrix (dense, or ``scipy.sparse`` CSR when read with
            ``sparse=True``); contact i owns rows d*i .. d*i + d - 1, normal first.
        q: (d * nc,) free velocity.
        mu: (nc,) friction coefficients.
    """

    dimension: int
    W: FloatArray | sp.csr_matrix
    q: FloatArray
    mu: FloatArray


class _Reader:
    """Cursor over a file's text that hands out tokens or, for CSparse dumps, lines."""

    def __init__(self, text: str, source: str, sparse: bool = False) -> None:
        self.text = text
        self.source = source
        self.pos = 0
        self.sparse = sparse

    def token(self) -> str:
        match = _TOKEN.search(self.text, self.pos)
        if match is None:
            raise ValueError(f"{self.source}: unexpected end of file")
        self.pos = match.end()
        return match.group()

    def integer(self) -> int:
        token = self.token()
        try:
            return int(token)
        except ValueError:
            raise ValueError(f"{self.source}: expected an integer, got {token!r}") from None

    def floats(self, count: int) -> FloatArray:
        tokens = [self.token() for _ in range(count)]
        try:
            return np.array([float(token) for token in tokens])
        except ValueError as error:
            raise ValueError(f"{self.source}: expected {count} numbers: {error}") from None

    def line(self) -> str:
        end = self.text.find("\n", self.pos)
        end = len(self.text) if end < 0 else end
        line = self.text[self.pos : end]
        self.pos = end + 1
        return line

    def matrix(self) -> FloatArray | sp.csr_matrix:
        storage, rows, cols = self.integer(), self.integer(), self.integer()
        if storage == 0:
            self.integer(), self.integer()  # the sizes, printed again
            dense = self.floats(rows * cols).reshape(cols, rows).T.copy()
            return sp.csr_matrix(dense) if self.sparse else dense
        if storage == 1:
            return self._sparse_block(rows, cols)
        if storage == 2:
            return self._csparse(rows, cols)
        raise ValueError(f"{self.source}: unknown matrix storage type {storage}")

    def _sparse_block(self, rows: int, cols: int) -> FloatArray:
        num_blocks, block_rows, block_cols = self.integer(), self.integer(), self.integer()
        row_ends = [self.integer() for _ in range(block_rows)]
        col_ends = [self.integer() for _ in range(block_cols)]
        self.integer(), self.integer()  # filled1 = block_rows + 1, filled2 = num_blocks
        row_ptr = [self.integer() for _ in range(block_rows + 1)]
        col_index = [self.integer() for _ in range(num_blocks)]
        matrix = np.zeros((rows, cols))
        for block_row in range(block_rows):
            r0 = row_ends[block_row - 1] if block_row else 0
            r1 = row_ends[block_row]
            for k in range(row_ptr[block_row], row_ptr[block_row + 1]):
                if self.integer() != k:
                    raise ValueError(f"{self.source}: sparse block {k} out of order")
                block_col = col_index[k]
                c0 = col_ends[block_col - 1] if block_col else 0
                c1 = col_ends[block_col]
                block = self.floats((r1 - r0) * (c1 - c0))
                matrix[r0:r1, c0:c1] = block.reshape(c1 - c0, r1 - r0).T
        return sp.csr_matrix(matrix) if self.sparse else matrix

    def _csparse(self, rows: int, cols: int) -> FloatArray:
        if self.integer() != 2:
            raise ValueError(f"{self.source}: only compressed-column CSparse dumps are supported")
        self.line()  # rest of the origin line
        self.line()  # "CSparse Version ..."
        size = _CSPARSE_SIZE.search(self.line())
        if size is None or (int(size.group(1)), int(size.group(2))) != (rows, cols):
            raise ValueError(f"{self.source}: CSparse size line does not match {rows}x{cols}")
        row_index: list[int] = []
        col_index: list[int] = []
        values: list[float] = []
        for _ in range(cols):
            header = _CSPARSE_COLUMN.match(self.line())
            if header is None:
                raise ValueError(f"{self.source}: malformed CSparse column header")
            col, first, last = (int(g) for g in header.groups())
            for _ in range(last - first + 1):
                entry = _CSPARSE_ENTRY.match(self.line())
                if entry is None or not (0 <= int(entry.group(1)) < rows and 0 <= col < cols):
                    raise ValueError(f"{self.source}: malformed CSparse entry in column {col}")
                try:
                    values.append(float(entry.group(2)))
                except ValueError:
                    raise ValueError(
                        f"{self.source}: non-numeric CSparse value in column {col}"
                    ) from None
                row_index.append(int(entry.group(1)))
                col_index.append(col)
        if self.sparse:  # duplicates summed, as a dense read keeps the last: the dumps have none
            return sp.csr_matrix((values, (row_index, col_index)), shape=(rows, cols))
        matrix = np.zeros((rows, cols))
        matrix[row_index, col_index] = values
        return matrix


def read_lcp(path: str | Path) -> tuple[FloatArray, FloatArray]:
    """Read a Siconos LCP file and return ``(M, q)`` with M (n, n), q (n,).

    Raises:
        ValueError: a malformed file (the message names it).
    """
    reader = _Reader(Path(path).read_text(), str(path))
    n = reader.integer()
    M = reader.matrix()
    if M.shape != (n, n):
        raise ValueError(f"{path}: matrix is {M.shape}, expected ({n}, {n})")
    return M, reader.floats(n)


def read_friction_contact(path: str | Path, sparse: bool = False) -> FrictionContactData:
    """Read a Siconos local friction-contact file (2-D or 3-D).

    Args:
        path: the ``.dat`` file.
        sparse: return W as a ``scipy.sparse`` CSR matrix (never densified; the largest FC2D
            peer problem is 14 004 x 14 004, 1.6 GB dense).

    Raises:
        ValueError: a malformed file (the message names it).
    """
    reader = _Reader(Path(path).read_text(), str(path), sparse)
    dimension, num_contacts = reader.integer(), reader.integer()
    n = dimension * num_contacts
    W = reader.matrix()
    if W.shape != (n, n):
        raise ValueError(f"{path}: matrix is {W.shape}, expected ({n}, {n})")
    q = reader.floats(n)
    mu = reader.floats(num_contacts)
    return FrictionContactData(dimension, W, q, mu)


__all__ = ["FrictionContactData", "read_friction_contact", "read_lcp"]
