"""The matrix-file readers of structure.fe (issue 26), each on files another writer made:
scipy.io.mmwrite, scipy.io.savemat, h5py in MATLAB's v7.3 layout, Abaqus text written here
line by line from the layout the Abaqus manuals document, pyyeti's OP4 writer."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import scipy.io
import scipy.sparse

from clearjoint.structure.fe import FEModelError
from clearjoint.structure.fe.readers import read_matrix, sniff_format

K = (
    np.array(
        [
            [4.0, -1.0, 0.0, 0.5],
            [-1.0, 5.0, -2.0, 0.0],
            [0.0, -2.0, 6.0, -1.5],
            [0.5, 0.0, -1.5, 7.0],
        ]
    )
    * 1e5
)
M = np.diag([1.0, 2.0, 3.0, 4.0]) + 0.1 * (np.eye(4, k=1) + np.eye(4, k=-1))


def test_matrix_market_written_by_scipy(tmp_path: Path) -> None:
    path = tmp_path / "k.mtx"
    scipy.io.mmwrite(str(path), scipy.sparse.coo_matrix(K), symmetry="symmetric")
    assert sniff_format(path) == "matrix-market"
    matrix, names = read_matrix(path, "stiffness")
    np.testing.assert_array_equal(matrix.toarray(), K)
    assert names is None


def test_matlab_v5_written_by_scipy_with_default_and_named_keys(tmp_path: Path) -> None:
    path = tmp_path / "model.mat"
    scipy.io.savemat(str(path), {"M": M, "K": scipy.sparse.csc_matrix(K), "Kjoint": 2 * K})
    np.testing.assert_array_equal(read_matrix(path, "mass")[0].toarray(), M)
    np.testing.assert_array_equal(read_matrix(path, "stiffness")[0].toarray(), K)
    np.testing.assert_array_equal(read_matrix(path, "stiffness", key="Kjoint")[0].toarray(), 2 * K)
    with pytest.raises(FEModelError, match=r"no variable 'C'.*holds K, Kjoint, M"):
        read_matrix(path, "damping")


def test_matlab_v73_written_by_h5py_in_matlabs_layout(tmp_path: Path) -> None:
    """v7.3 is HDF5 after a 512-byte header; arrays column-major, sparse as data/ir/jc."""
    h5py = pytest.importorskip("h5py")
    path = tmp_path / "model73.mat"
    with h5py.File(path, "w", userblock_size=512) as f:
        f.create_dataset("M", data=M.T)  # MATLAB writes columns first
        csc = scipy.sparse.csc_matrix(K)
        g = f.create_group("K")
        g.attrs["MATLAB_sparse"] = np.uint64(4)
        g.create_dataset("data", data=csc.data)
        g.create_dataset("ir", data=csc.indices.astype(np.uint64))
        g.create_dataset("jc", data=csc.indptr.astype(np.uint64))
    with path.open("r+b") as handle:
        handle.write(b"MATLAB 7.3 MAT-file, written by a test".ljust(128))
    assert sniff_format(path) == "mat"
    np.testing.assert_array_equal(read_matrix(path, "mass")[0].toarray(), M)
    np.testing.assert_array_equal(read_matrix(path, "stiffness")[0].toarray(), K)


def _user_element_file(path: Path) -> None:
    """*SUBSTRUCTURE MATRIX OUTPUT, OUTPUT FILE=USER DEFINED: two nodes, DOFs 1 and 2."""
    lines = [
        "** SUBSTRUCTURE MATRIX OUTPUT, written by hand",
        "*USER ELEMENT, NODES=2, TYPE=Z1, LINEAR",
        "1, 2",
    ]
    for kind, a in (("MASS", M), ("STIFFNESS", K)):
        lines.append(f"*MATRIX, TYPE={kind}")
        upper = [a[i, j] for j in range(4) for i in range(j + 1)]  # by columns, to the diagonal
        for start in range(0, len(upper), 4):
            lines.append(", ".join(f"{v:.16E}" for v in upper[start : start + 4]))
    path.write_text("\n".join(lines) + "\n")


def test_abaqus_substructure_layout_written_by_hand(tmp_path: Path) -> None:
    path = tmp_path / "sub.mtx"
    _user_element_file(path)
    assert sniff_format(path) == "abaqus"
    k, names = read_matrix(path, "stiffness")
    m, _ = read_matrix(path, "mass")
    np.testing.assert_array_equal(k.toarray(), K)
    np.testing.assert_array_equal(m.toarray(), M)
    assert names == ("1.1", "1.2", "2.1", "2.2")
    with pytest.raises(FEModelError, match="no \\*MATRIX, TYPE=VISCOUS DAMPING"):
        read_matrix(path, "damping")


def test_abaqus_matrix_input_layout_written_by_hand(tmp_path: Path) -> None:
    """*MATRIX OUTPUT, FORMAT=MATRIX INPUT: node, DOF, node, DOF, value; lower triangle."""
    dofs = [(7, 1), (7, 2), (9, 1), (9, 3)]
    lines = ["** MATRIX INPUT FORMAT"]
    for i in range(4):
        for j in range(i + 1):
            if K[i, j] != 0.0:
                (a, da), (b, db) = dofs[i], dofs[j]
                lines.append(f"{a},{da}, {b},{db}, {K[i, j]:.16e}")
    path = tmp_path / "job_STIF2.mtx"
    path.write_text("\n".join(lines) + "\n")
    assert sniff_format(path) == "abaqus"
    k, names = read_matrix(path, "stiffness")
    np.testing.assert_array_equal(k.toarray(), K)
    assert names == ("7.1", "7.2", "9.1", "9.3")


def test_a_file_of_no_known_format_is_refused_in_one_line(tmp_path: Path) -> None:
    path = tmp_path / "k.mtx"
    path.write_text("1;2;3\n4;5;6\n")
    with pytest.raises(FEModelError, match="not a matrix file") as info:
        read_matrix(path, "stiffness")
    assert "\n" not in str(info.value)
    with pytest.raises(FEModelError, match="no such matrix file"):
        read_matrix(tmp_path / "none.mtx", "stiffness")
    bad = tmp_path / "bad.mtx"
    bad.write_text("1,1, 1,1, 2.0\n1,1, 2,1\n")
    with pytest.raises(FEModelError, match=r"bad\.mtx:2: a MATRIX INPUT line has 5 fields"):
        read_matrix(bad, "stiffness")
    short = tmp_path / "short.mtx"
    _user_element_file(short)
    short.write_text(short.read_text().rsplit("\n", 2)[0] + "\n")  # drop the last line
    with pytest.raises(FEModelError, match="needs 10"):
        read_matrix(short, "stiffness")


def test_nastran_op4_written_by_pyyeti(tmp_path: Path) -> None:
    op4 = pytest.importorskip("pyyeti.nastran.op4", reason="pyyeti (the fe extra) not installed")
    path = tmp_path / "model.op4"
    op4.write(str(path), {"KAA": K, "MAA": M})
    assert sniff_format(path) == "op4"
    np.testing.assert_allclose(
        read_matrix(path, "stiffness", key="kaa")[0].toarray(), K, rtol=1e-15
    )
    np.testing.assert_allclose(read_matrix(path, "mass", key="MAA")[0].toarray(), M, rtol=1e-15)
    with pytest.raises(FEModelError, match="no matrix 'K'"):
        read_matrix(path, "stiffness")
