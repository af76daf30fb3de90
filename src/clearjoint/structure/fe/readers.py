"""Matrix files of finite-element programs: Matrix Market, MATLAB, Abaqus, Nastran OP4.

One function, :func:`read_matrix`, reads the mass, stiffness or damping matrix of a
model from a file, with the DOF names the file carries (or None). The format is
sniffed from the content, the suffix only breaking ties; a file that is none of them,
or that lacks the matrix asked for, is one clear error, never a silent misread.

* Matrix Market (``%%MatrixMarket`` first line; ``scipy.io.mmread``): one matrix a file.
* MATLAB ``.mat`` (v5 through ``scipy.io.loadmat``; v7.3, an HDF5 file, through
  ``h5py``): the variables ``M``, ``K``, ``C`` by default (as tmdsimpy's files), or
  the names given.
* Abaqus text ``.mtx``, in either of its two layouts:

  - the substructure or user-element layout (``*SUBSTRUCTURE MATRIX OUTPUT, OUTPUT
    FILE=USER DEFINED``): a ``*USER ELEMENT, NODES=n, ... LINEAR`` line, a data line of
    the active DOFs per node (e.g. ``1, 2, 3``), then ``*MATRIX, TYPE=MASS`` and
    ``*MATRIX, TYPE=STIFFNESS`` blocks, each the upper triangle stored column by column
    (row 1 to the diagonal of each column), up to four entries a line. The DOFs are
    ordered node by node; they are named ``"<k>.<dof>"`` (k the node's position, 1-based);
  - the matrix-input layout (``*MATRIX OUTPUT, FORMAT=MATRIX INPUT``): one entry a line,
    ``row node, row DOF, column node, column DOF, value``, lower, upper or both
    triangles; the DOFs are named ``"<node>.<dof>"``, sorted by node then DOF.

  Lines starting with ``**`` are comments.
* Nastran OP4 (``pyyeti.nastran.op4``, the optional extra ``fe``): the variables named,
  by default ``M``, ``K``, ``C`` as in a MATLAB file (names are matched case-blind).
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np
import scipy.io
import scipy.sparse

from clearjoint.structure.fe.matrices import FEModelError

#: The matrices a model file can hold, and their default variable names (.mat, OP4).
KINDS = {"mass": "M", "stiffness": "K", "damping": "C"}

#: The formats :func:`read_matrix` knows.
FORMATS = ("matrix-market", "mat", "abaqus", "op4")

#: Abaqus's *MATRIX TYPE= words for each kind.
_ABAQUS_TYPES = {"mass": ("MASS",), "stiffness": ("STIFFNESS",), "damping": ("VISCOUS DAMPING",)}

_HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"


def sniff_format(path: Path) -> str:
    """The format of a matrix file from its first bytes (the suffix breaks no tie).

    Raises
    ------
    FEModelError
        None of :data:`FORMATS`.
    """
    with path.open("rb") as handle:
        head = handle.read(4096)
    if head.startswith(b"%%MatrixMarket"):
        return "matrix-market"
    if head.startswith(b"MATLAB 5.0 MAT-file") or (
        path.suffix.lower() == ".mat" and _HDF5_SIGNATURE in head[:1024]
    ):
        return "mat"
    text = head.decode("latin-1")
    lines = [s.strip() for s in text.splitlines() if s.strip() and not s.startswith("**")]
    if any(s.upper().startswith(("*USER ELEMENT", "*MATRIX")) for s in lines) or (
        lines and re.fullmatch(r"\d+\s*,\s*\d+\s*,\s*\d+\s*,\s*\d+\s*,\s*\S+", lines[0])
    ):
        return "abaqus"
    if path.suffix.lower() == ".op4":
        return "op4"
    raise FEModelError(
        f"{path}: not a matrix file clearjoint reads (Matrix Market, MATLAB .mat, Abaqus "
        ".mtx, Nastran .op4): its first line is "
        f"{(lines[0] if lines else text[:40])[:60]!r}; give format = ... if the suffix misleads"
    )


def read_matrix(
    path: str | Path, kind: str, *, key: str | None = None, format: str | None = None
) -> tuple[scipy.sparse.csr_matrix, tuple[str, ...] | None]:
    """Return a model's ``kind`` matrix ("mass", "stiffness", "damping") and its DOF names.

    Parameters
    ----------
    path : str or Path
    kind : str
        Which matrix: for files holding several (MATLAB, Abaqus substructure, OP4).
    key : str, optional
        The variable name in a MATLAB or OP4 file (default ``M``, ``K``, ``C``).
    format : str, optional
        One of :data:`FORMATS`; default sniffed from the content.

    Returns
    -------
    (matrix, names)
        The matrix as scipy.sparse CSR (float64), and the DOF names the file carries
        (Abaqus) or None.

    Raises
    ------
    FEModelError
        No such file; not a format known; the matrix asked for not in it; a malformed
        line (its number and text).
    """
    path = Path(path)
    if kind not in KINDS:
        raise FEModelError(f"kind must be one of {', '.join(KINDS)}, got {kind!r}")
    if not path.is_file():
        raise FEModelError(f"{path}: no such matrix file")
    fmt = sniff_format(path) if format is None else format
    if fmt not in FORMATS:
        raise FEModelError(f"format must be one of {', '.join(FORMATS)}, got {fmt!r}")
    name = key or KINDS[kind]
    if fmt == "matrix-market":
        try:
            matrix = scipy.io.mmread(str(path))
        except (ValueError, OSError) as exc:
            raise FEModelError(f"{path}: not a readable Matrix Market file ({exc})") from None
        return _csr(path, matrix), None
    if fmt == "mat":
        return _csr(path, _read_mat(path, name)), None
    if fmt == "abaqus":
        return _read_abaqus(path, kind)
    return _csr(path, _read_op4(path, name)), None


def _csr(path: Path, matrix: Any) -> scipy.sparse.csr_matrix:
    if scipy.sparse.issparse(matrix):
        out = scipy.sparse.csr_matrix(matrix, dtype=np.float64)
    else:
        array = np.asarray(matrix)
        if array.dtype.kind not in "fiu" or array.ndim != 2:
            raise FEModelError(
                f"{path}: the matrix is not a 2-D array of real numbers (shape {array.shape}, "
                f"type {array.dtype})"
            )
        out = scipy.sparse.csr_matrix(array.astype(np.float64))
    if out.shape[0] != out.shape[1]:
        raise FEModelError(f"{path}: the matrix is {out.shape[0]} x {out.shape[1]}, not square")
    return out


def _read_mat(path: Path, name: str) -> Any:
    with path.open("rb") as handle:
        hdf5 = _HDF5_SIGNATURE in handle.read(1024)
    if not hdf5:
        try:
            data = scipy.io.loadmat(str(path))
        except (ValueError, OSError, NotImplementedError) as exc:
            raise FEModelError(f"{path}: not a readable MATLAB file ({exc})") from None
        names = sorted(k for k in data if not k.startswith("__"))
        if name not in data:
            raise FEModelError(
                f"{path}: no variable {name!r} in this MATLAB file (it holds "
                f"{', '.join(names) or 'none'}); name it in the model file"
            )
        return data[name]
    import h5py

    with h5py.File(path, "r") as f:
        if name not in f:
            raise FEModelError(
                f"{path}: no variable {name!r} in this MATLAB v7.3 file (it holds "
                f"{', '.join(sorted(f)) or 'none'}); name it in the model file"
            )
        item = f[name]
        if isinstance(item, h5py.Group):  # a MATLAB sparse matrix: CSC by data, ir, jc
            rows = int(item.attrs.get("MATLAB_sparse", 0))
            jc = np.asarray(item["jc"], dtype=np.int64)
            ir = np.asarray(item["ir"], dtype=np.int64) if "ir" in item else np.zeros(0, int)
            values = np.asarray(item["data"], dtype=np.float64) if "data" in item else ir * 0.0
            return scipy.sparse.csc_matrix((values, ir, jc), shape=(rows, jc.size - 1))
        return np.asarray(item).T  # MATLAB stores columns first: h5py reads the transpose


def _read_op4(path: Path, name: str) -> Any:
    try:
        from pyyeti.nastran import op4
    except ImportError:
        raise FEModelError(
            f"{path}: reading Nastran OP4 needs pyyeti: pip install 'clearjoint[fe]'"
        ) from None
    try:
        data = op4.load(str(path), into="dct")
    except Exception as exc:  # pyyeti raises plain errors on a bad file
        raise FEModelError(f"{path}: not a readable OP4 file ({exc})") from None
    found = {k.lower(): k for k in data}
    if name.lower() not in found:
        raise FEModelError(
            f"{path}: no matrix {name!r} in this OP4 file (it holds "
            f"{', '.join(sorted(data)) or 'none'}); name it in the model file"
        )
    value = data[found[name.lower()]]
    return value[0] if isinstance(value, tuple) else value


def _data_lines(path: Path) -> list[tuple[int, str]]:
    """(line number, text) of every line that is neither blank nor a ``**`` comment."""
    with path.open(encoding="latin-1") as handle:
        return [
            (i, s.strip())
            for i, s in enumerate(handle, start=1)
            if s.strip() and not s.lstrip().startswith("**")
        ]


def _numbers(path: Path, number: int, text: str) -> list[float]:
    try:
        return [float(v.replace("D", "E").replace("d", "e")) for v in text.split(",") if v.strip()]
    except ValueError:
        raise FEModelError(f"{path}:{number}: not a line of numbers: {text[:60]!r}") from None


def _read_abaqus(path: Path, kind: str) -> tuple[scipy.sparse.csr_matrix, tuple[str, ...] | None]:
    lines = _data_lines(path)
    if any(text.upper().startswith("*USER ELEMENT") for _, text in lines):
        return _read_abaqus_user_element(path, kind, lines)
    if any(text.startswith("*") for _, text in lines):
        first = next(text for _, text in lines if text.startswith("*"))
        raise FEModelError(
            f"{path}: an Abaqus keyword {first[:40]!r} without *USER ELEMENT: clearjoint reads "
            "the substructure (USER DEFINED) and the MATRIX INPUT layouts"
        )
    return _read_abaqus_matrix_input(path, lines)


def _keyword_options(text: str) -> dict[str, str]:
    parts = [p.strip() for p in text.split(",")]
    out = {}
    for part in parts[1:]:
        key, _, value = part.partition("=")
        out[key.strip().upper()] = value.strip().upper()
    return out


def _read_abaqus_user_element(
    path: Path, kind: str, lines: list[tuple[int, str]]
) -> tuple[scipy.sparse.csr_matrix, tuple[str, ...]]:
    header = next(k for k, (_, t) in enumerate(lines) if t.upper().startswith("*USER ELEMENT"))
    options = _keyword_options(lines[header][1])
    try:
        n_nodes = int(options["NODES"])
    except (KeyError, ValueError):
        raise FEModelError(
            f"{path}:{lines[header][0]}: *USER ELEMENT needs NODES=n (the retained nodes)"
        ) from None
    # the DOF lines: the active DOFs of the first node, then (node position, DOFs) changes
    dofs_at: dict[int, list[int]] = {}
    k = header + 1
    first = True
    while k < len(lines) and not lines[k][1].startswith("*"):
        active = [int(v) for v in _numbers(path, *lines[k])]
        if first:
            dofs_at[1] = active
            first = False
        else:
            dofs_at[active[0]] = active[1:]
        k += 1
    if not dofs_at:
        raise FEModelError(f"{path}: *USER ELEMENT has no data line of active DOFs")
    names: list[str] = []
    current = dofs_at[1]
    for node in range(1, n_nodes + 1):
        current = dofs_at.get(node, current)
        names += [f"{node}.{d}" for d in current]
    n = len(names)
    wanted = _ABAQUS_TYPES[kind]
    blocks: dict[str, list[float]] = {}
    block: list[float] | None = None
    for number, text in lines[k:]:
        if text.startswith("*"):
            block = None
            if text.upper().startswith("*MATRIX"):
                matrix_type = _keyword_options(text).get("TYPE", "")
                block = blocks.setdefault(matrix_type, [])
            continue
        if block is not None:
            block.extend(_numbers(path, number, text))
    values = next((blocks[t] for t in wanted if t in blocks), None)
    if values is None:
        raise FEModelError(
            f"{path}: no *MATRIX, TYPE={wanted[0]} block in this Abaqus file (it holds "
            f"{', '.join(sorted(blocks)) or 'none'}); request it in *SUBSTRUCTURE MATRIX OUTPUT"
        )
    if len(values) != n * (n + 1) // 2:
        raise FEModelError(
            f"{path}: the TYPE={wanted[0]} block holds {len(values)} entries; the upper triangle "
            f"of the {n} DOFs of *USER ELEMENT needs {n * (n + 1) // 2}"
        )
    # upper triangle column by column: column j holds rows 0..j
    cols = np.repeat(np.arange(n), np.arange(1, n + 1))
    rows = np.concatenate([np.arange(j + 1) for j in range(n)])
    vals = np.asarray(values)
    off = rows != cols
    full = scipy.sparse.coo_matrix(
        (
            np.concatenate((vals, vals[off])),
            (np.concatenate((rows, cols[off])), np.concatenate((cols, rows[off]))),
        ),
        shape=(n, n),
    )
    return full.tocsr(), tuple(names)


def _read_abaqus_matrix_input(
    path: Path, lines: list[tuple[int, str]]
) -> tuple[scipy.sparse.csr_matrix, tuple[str, ...]]:
    entries = []
    for number, text in lines:
        values = _numbers(path, number, text)
        if len(values) != 5:
            raise FEModelError(
                f"{path}:{number}: a MATRIX INPUT line has 5 fields (row node, row DOF, column "
                f"node, column DOF, value), got {len(values)}: {text[:60]!r}"
            )
        entries.append(values)
    if not entries:
        raise FEModelError(f"{path}: no matrix entries in this Abaqus file")
    table = np.array(entries)
    keys = sorted(
        {(int(a), int(b)) for a, b in table[:, 0:2]} | {(int(a), int(b)) for a, b in table[:, 2:4]}
    )
    index = {key: i for i, key in enumerate(keys)}
    rows = np.array([index[(int(a), int(b))] for a, b in table[:, 0:2]])
    cols = np.array([index[(int(a), int(b))] for a, b in table[:, 2:4]])
    vals = table[:, 4]
    n = len(keys)
    upper = rows < cols
    lower = rows > cols
    if np.any(upper) and np.any(lower):  # both triangles (the square layout): take it as given
        matrix = scipy.sparse.coo_matrix((vals, (rows, cols)), shape=(n, n))
    else:  # one triangle: mirror it
        off = rows != cols
        matrix = scipy.sparse.coo_matrix(
            (
                np.concatenate((vals, vals[off])),
                (np.concatenate((rows, cols[off])), np.concatenate((cols, rows[off]))),
            ),
            shape=(n, n),
        )
    return matrix.tocsr(), tuple(f"{node}.{dof}" for node, dof in keys)
