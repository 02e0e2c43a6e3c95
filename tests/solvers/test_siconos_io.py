"""Readers of the Siconos text formats (``mdi_envs/solvers/siconos_io.py``).

Self-made files (written to ``tmp_path``) test every storage type, the column-major orientation
and the error messages without ../shared; the peer files test the real data
(../shared/peer-data/siconos/README.md sections 1 and 3).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from peer_data import PEER_DATA, peer_params

from mdi_envs.solvers.siconos_io import FrictionContactData, read_friction_contact, read_lcp


def _write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


# ------------------------------------------------------------------------------------------
# Self-made files

DENSE_LCP = """2
0
2
2
2\t2
1 2
3 4
-1 -2
this trailing comment is ignored
"""

SBM_LCP = """3
1
3
3
3
2
2
2 3
2 3
3
3
0 2 3
0 1 1
0
1.0
2.0
3.0
4.0
1
5.0
6.0
2
7.0
-1 -2 -3
"""

SBM_EMPTY_ROW_LCP = """3
1
3
3
2
3
3
1 2 3
1 2 3
4
2
0 1 1 2
2 0
0
5.0
1
7.0
-1 0 1
"""

CSPARSE_FC2D = """2
2
2
4
4
2
CSparse Version 3.1.9, May 4, 2016.  Copyright (c) Timothy A. Davis, 2006-2016
4-by-4, nzmax: 5 nnz: 5, 1-norm: 3.5
    col 0 : locations 0 to 1
      0 : 2
      3 : -0.5
    col 1 : locations 2 to 2
      1 : 1.5
    col 2 : locations 3 to 2
    col 3 : locations 3 to 4
      0 : 0.25
      3 : 3
-1 0.5 2 -3
0.3 0.7
1
"""

DENSE_FC3D = "3\n1\n0\n3\n3\n3 3\n" + "\n".join(
    str(v) for v in [15, -1, -2, -1, 14, 1, -2, 1, 16, -1, 2, 3, 0.1]
)


def test_dense_lcp_is_column_major(tmp_path: Path) -> None:
    """Each printed line of a dense square matrix is a column; text after q is ignored."""
    M, q = read_lcp(_write(tmp_path, "dense.dat", DENSE_LCP))
    np.testing.assert_array_equal(M, [[1.0, 3.0], [2.0, 4.0]])
    np.testing.assert_array_equal(q, [-1.0, -2.0])
    assert M.dtype == np.float64 and M.flags.c_contiguous


def test_dense_lcp_ignores_line_breaks(tmp_path: Path) -> None:
    """Whitespace, line breaks included, carries no meaning outside CSparse dumps."""
    flat = " ".join(DENSE_LCP.split("\n")[:8])
    M, q = read_lcp(_write(tmp_path, "flat.dat", flat))
    np.testing.assert_array_equal(M, [[1.0, 3.0], [2.0, 4.0]])
    np.testing.assert_array_equal(q, [-1.0, -2.0])


def test_sparse_block_lcp(tmp_path: Path) -> None:
    """SBM: cumulative block ends, block-CSR pointers, column-major blocks, a 2x1 block."""
    M, q = read_lcp(_write(tmp_path, "sbm.dat", SBM_LCP))
    np.testing.assert_array_equal(M, [[1.0, 3.0, 5.0], [2.0, 4.0, 6.0], [0.0, 0.0, 7.0]])
    np.testing.assert_array_equal(q, [-1.0, -2.0, -3.0])


def test_sparse_block_lcp_with_an_empty_block_row(tmp_path: Path) -> None:
    """A block row without stored blocks (and no diagonal blocks at all) stays zero."""
    M, q = read_lcp(_write(tmp_path, "sbm_empty.dat", SBM_EMPTY_ROW_LCP))
    np.testing.assert_array_equal(M, [[0.0, 0.0, 5.0], [0.0, 0.0, 0.0], [7.0, 0.0, 0.0]])
    np.testing.assert_array_equal(q, [-1.0, 0.0, 1.0])


def test_csparse_friction_contact(tmp_path: Path) -> None:
    """CSparse CSC dump: line-based columns, an empty column, then q, mu and a trailing flag."""
    data = read_friction_contact(_write(tmp_path, "fc2d.dat", CSPARSE_FC2D))
    assert isinstance(data, FrictionContactData)
    assert data.dimension == 2
    expected = np.zeros((4, 4))
    expected[0, 0], expected[3, 0], expected[1, 1] = 2.0, -0.5, 1.5
    expected[0, 3], expected[3, 3] = 0.25, 3.0
    np.testing.assert_array_equal(data.W, expected)
    np.testing.assert_array_equal(data.q, [-1.0, 0.5, 2.0, -3.0])
    np.testing.assert_array_equal(data.mu, [0.3, 0.7])


def test_dense_friction_contact_one_value_per_line(tmp_path: Path) -> None:
    """The FrictionContact3D_1c layout (one value per line), self-made."""
    data = read_friction_contact(_write(tmp_path, "fc3d.dat", DENSE_FC3D))
    assert data.dimension == 3
    np.testing.assert_array_equal(data.W, [[15, -1, -2], [-1, 14, 1], [-2, 1, 16]])
    np.testing.assert_array_equal(data.q, [-1.0, 2.0, 3.0])
    np.testing.assert_array_equal(data.mu, [0.1])


def test_reader_accepts_str_paths(tmp_path: Path) -> None:
    """Both str and Path are accepted."""
    path = _write(tmp_path, "dense.dat", DENSE_LCP)
    np.testing.assert_array_equal(read_lcp(str(path))[0], read_lcp(path)[0])


MALFORMED_LCP = {
    "empty": "",
    "truncated_matrix": "2\n0\n2\n2\n2 2\n1 0\n0\n",
    "truncated_q": "2\n0\n2\n2\n2 2\n1 0\n0 1\n-1\n",
    "unknown_storage": "2\n7\n2\n2\n",
    "size_mismatch": "3\n0\n2\n2\n2 2\n1 0 0 1\n-1 -1 -1\n",
    "not_square": "2\n0\n2\n3\n2 3\n1 0 0 1 0 0\n-1 -1\n",
    "sbm_block_out_of_order": "2\n1\n2\n2\n1\n1\n1\n2\n2\n2\n1\n0 1\n0\n5\n1 2 3 4\n-1 -1\n",
    "csparse_unsupported_origin": "2\n2\n2\n2\n1\nCSparse\n2-by-2, nzmax: 0 nnz: 0\n",
    "csparse_size_line": "2\n2\n2\n2\n2\nCSparse\n3-by-3, nzmax: 0 nnz: 0\n",
    "csparse_column_header": "2\n2\n2\n2\n2\nCSparse\n2-by-2, nzmax: 1\n  row 0 : 1\n",
    "csparse_entry": "2\n2\n2\n2\n2\nCSparse\n2-by-2\n    col 0 : locations 0 to 0\n  x\n",
    # Non-numeric tokens and out-of-range indices are malformed input too:
    "non_numeric_size": "two\n0\n2\n2\n2 2\n1 0 0 1\n-1 -1\n",
    "non_numeric_value": "2\n0\n2\n2\n2 2\n1 zero 0 1\n-1 -1\n",
    "non_numeric_q": "2\n0\n2\n2\n2 2\n1 0 0 1\n-1 q\n",
    "csparse_row_out_of_range": (
        "2\n2\n2\n2\n2\nCSparse\n2-by-2, nzmax: 1\n    col 0 : locations 0 to 0\n      5 : 1\n"
        "    col 1 : locations 1 to 0\n-1 -1\n"
    ),
}


@pytest.mark.parametrize("name", sorted(MALFORMED_LCP))
def test_malformed_lcp_raises_value_error_naming_the_file(tmp_path: Path, name: str) -> None:
    """Every malformed file raises ValueError whose message names the file."""
    path = _write(tmp_path, f"{name}.dat", MALFORMED_LCP[name])
    with pytest.raises(ValueError, match=re.escape(str(path))):
        read_lcp(path)


@pytest.mark.parametrize(
    ("name", "text"),
    [
        ("wrong_size", "3\n2\n0\n3\n3\n3 3\n" + " ".join(["1"] * 9) + "\n1 2 3\n0.1 0.1\n"),
        ("truncated_mu", "3\n1\n0\n3\n3\n3 3\n" + " ".join(["1"] * 9) + "\n1 2 3\n"),
    ],
)
def test_malformed_friction_contact_names_the_file(tmp_path: Path, name: str, text: str) -> None:
    """A matrix that is not (d nc) x (d nc), or missing mu, raises ValueError naming the file."""
    path = _write(tmp_path, f"{name}.dat", text)
    with pytest.raises(ValueError, match=re.escape(str(path))):
        read_friction_contact(path)


def test_missing_file_is_an_os_error(tmp_path: Path) -> None:
    """A path that does not exist is not a format problem."""
    with pytest.raises(FileNotFoundError):
        read_lcp(tmp_path / "absent.dat")


# ------------------------------------------------------------------------------------------
# Peer files


def _peer(kind: str, name: str) -> Path:
    path = PEER_DATA / kind / f"{name}.dat"
    if not path.is_file():
        pytest.skip(f"peer data {PEER_DATA} absent")
    return path


@pytest.mark.parametrize("path", peer_params("lcp"))
def test_every_peer_lcp_parses(path: Path) -> None:
    """All 20 LCP files: square M, matching q, finite values."""
    M, q = read_lcp(path)
    assert M.ndim == 2 and M.shape == (q.shape[0], q.shape[0])
    assert np.isfinite(M).all() and np.isfinite(q).all()


# The two largest granular-flow dumps (4040^2 and 14004^2 dense doubles: 130 MB and 1.6 GB)
# are left out to keep the suite fast and small; 00667 below covers the CSparse path.
_LARGE = ["fc2d_granularflowonwall_02020_00213", "fc2d_granularflowonwall_07002_00801"]


@pytest.mark.parametrize(
    "path",
    [p for p in peer_params("fc2d") if not (p.values[0] and p.values[0].stem in _LARGE)]
    + peer_params("fc3d"),
)
def test_every_peer_friction_problem_parses(path: Path) -> None:
    """Dimension d in {2, 3}, W is (d nc) x (d nc), q and mu match, everything finite, mu > 0."""
    data = read_friction_contact(path)
    assert data.dimension == (2 if path.parent.name == "fc2d" else 3)
    nc = data.mu.shape[0]
    n = data.dimension * nc
    assert data.W.shape == (n, n) and data.q.shape == (n,)
    assert np.isfinite(data.W).all() and np.isfinite(data.q).all()
    assert (data.mu > 0).all() and (data.mu <= 1).all()


@pytest.mark.parametrize(
    ("dense", "block"),
    [
        ("lcp_deudeu", "lcp_deudeu_block"),
        ("lcp_ortiz", "lcp_ortiz_block"),
        ("lcp_trivial", "lcp_trivial_block"),
    ],
)
def test_lcp_twins_parse_identically(dense: str, block: str) -> None:
    """Dense and sparse-block copies of the same problem are bit-identical after parsing."""
    M1, q1 = read_lcp(_peer("lcp", dense))
    M2, q2 = read_lcp(_peer("lcp", block))
    np.testing.assert_array_equal(M1, M2)
    np.testing.assert_array_equal(q1, q2)
    assert np.count_nonzero(M1) > 0


def test_fc3d_twins_parse_identically() -> None:
    """FC3D_Example1 (dense) and FC3D_Example1_SBM: W = I, q = (-1, 1, 3) x 3, mu = 0.1."""
    dense = read_friction_contact(_peer("fc3d", "FC3D_Example1"))
    block = read_friction_contact(_peer("fc3d", "FC3D_Example1_SBM"))
    for a, b in ((dense.W, block.W), (dense.q, block.q), (dense.mu, block.mu)):
        np.testing.assert_array_equal(a, b)
    assert dense.dimension == block.dimension == 3
    np.testing.assert_array_equal(dense.W, np.eye(9))
    np.testing.assert_array_equal(dense.q, np.tile([-1.0, 1.0, 3.0], 3))
    np.testing.assert_array_equal(dense.mu, [0.1] * 3)


@pytest.mark.parametrize("name", ["lcp_exp_murty", "lcp_exp_murty2"])
def test_exp_murty_is_read_column_major(name: str) -> None:
    """Murty's matrix is upper triangular, 1 on the diagonal and 2 above (file shows M^T)."""
    M, _ = read_lcp(_peer("lcp", name))
    np.testing.assert_array_equal(M, np.eye(6) + 2 * np.triu(np.ones((6, 6)), 1))


def test_ortiz_orientation() -> None:
    """lcp_ortiz's first printed line (3 -1 0 0) is column 0 of M."""
    M, q = read_lcp(_peer("lcp", "lcp_ortiz"))
    np.testing.assert_array_equal(M[:, 0], [3.0, -1.0, 0.0, 0.0])
    np.testing.assert_array_equal(M[0], [3.0, 1.0, 0.0, -1.0])
    np.testing.assert_array_equal(q, [-2.0, 1.0, -1.0, 1.0])


def test_one_value_per_line_fc3d() -> None:
    """FrictionContact3D_1c: README section 3.2 quotes W, q and mu."""
    data = read_friction_contact(_peer("fc3d", "FrictionContact3D_1c"))
    np.testing.assert_array_equal(data.W, [[15, -1, -2], [-1, 14, 1], [-2, 1, 16]])
    np.testing.assert_array_equal(data.q, [-1.0, 2.0, 3.0])
    np.testing.assert_array_equal(data.mu, [0.1])


def test_granular_flow_csparse_dump() -> None:
    """fc2d_granularflowonwall_00667_00000: 1334 x 1334 CSC dump with nnz 3822."""
    data = read_friction_contact(_peer("fc2d", "fc2d_granularflowonwall_00667_00000"))
    assert data.dimension == 2
    assert data.W.shape == (1334, 1334) and data.q.shape == (1334,) and data.mu.shape == (667,)
    assert np.count_nonzero(data.W) == 3822
    assert data.W[0, 0] == 856.713 and data.W[649, 0] == -454.43  # the dump's first column
    np.testing.assert_array_equal(data.W, data.W.T)
    np.testing.assert_array_equal(data.mu, 0.5)
    assert 0 < np.abs(data.q).max() < 1e-18  # README: |q|_inf = 5.4e-19


@pytest.mark.parametrize(
    ("name", "nnz"),
    [
        ("FC2D_SliderCrankLagrangian00000", 16),
        ("FrictionContactProblem00031", 60),
        ("FrictionContactProblem00071", 1140),
        ("FrictionContactProblem00237", 6588),
        ("FrictionContactProblem00374", 76),
        ("FrictionContactProblem00394", 24),
        ("FrictionContactProblem00727", 6306),
    ],
)
def test_fc2d_nonzero_counts_match_the_readme(name: str, nnz: int) -> None:
    """Non-zero counts of README section 3.1 (dense, SBM 2x2)."""
    data = read_friction_contact(_peer("fc2d", name))
    assert np.count_nonzero(data.W) == nnz
