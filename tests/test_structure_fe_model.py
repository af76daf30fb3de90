"""A model TOML ([model]: matrix files and joints) through read_model and the command line
(issue 26). The matrix files are written by scipy.io.mmwrite; the references are the
hand-assembled matrices' eigenvalues and the Python API on the same matrices."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
import scipy.io
import scipy.linalg
import scipy.sparse

from clearjoint import ClearanceJoint
from clearjoint.cli import main
from clearjoint.structure import from_matrices, read_model, reduce, time_response
from clearjoint.structure.fe import ReducedSystem
from clearjoint.structure.study import StructureStudyError

N_SIDE = 10
MODEL = """
[model]
mass = "m.mtx"
stiffness = "k.mtx"
dof_names = "dofs.txt"
rayleigh_alpha = "2/s"
joints = [["m10", "m11"]]
{extra}

[joint]
clearance = "50um"
compression_stiffness = "1e5N/m"
gap_stiffness = "2e3N/m"

[excitation]
frequency = "20Hz"
force_dof = "m18"
force_amplitude = "3N"
periods = 5

[decay]
dof = "m18"
initial_amplitude = "0.2mm"
duration = "0.2s"
"""


def _chains() -> tuple[np.ndarray, np.ndarray]:
    """Two chains of N_SIDE masses (0.1 kg, springs 1e5 N/m), grounded at the outer ends."""
    n = 2 * N_SIDE
    k = np.zeros((n, n))
    for i, j in [(0, None), (n - 1, None)] + [(i, i + 1) for i in range(n - 1) if i != N_SIDE - 1]:
        k[i, i] += 1e5
        if j is not None:
            k[j, j] += 1e5
            k[i, j] -= 1e5
            k[j, i] -= 1e5
    return np.diag(np.full(n, 0.1)), k


def _write(tmp_path: Path, extra: str = "") -> Path:
    m, k = _chains()
    scipy.io.mmwrite(str(tmp_path / "m.mtx"), scipy.sparse.coo_matrix(m))
    scipy.io.mmwrite(str(tmp_path / "k.mtx"), scipy.sparse.coo_matrix(k), symmetry="symmetric")
    (tmp_path / "dofs.txt").write_text("\n".join(f"m{i + 1}" for i in range(2 * N_SIDE)))
    path = tmp_path / "model.toml"
    path.write_text(MODEL.format(extra=extra))
    return path


def run(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    try:
        code = main(args)
    except SystemExit as exc:
        code = int(exc.code or 0)
    out, err = capsys.readouterr()
    return code, out, err


def test_read_model_gives_the_matrices_and_joints_of_the_file(tmp_path: Path) -> None:
    system = read_model(_write(tmp_path))
    m, k = _chains()
    b = np.zeros(2 * N_SIDE)
    b[N_SIDE - 1], b[N_SIDE] = 1.0, -1.0
    np.testing.assert_array_equal(system.directions[0], b)
    assert system.dof_names[0] == "m1"
    closed = np.sqrt(scipy.linalg.eigvalsh(k + (2e3 + 1e5) * np.outer(b, b), m))
    from clearjoint.structure.model import system_modes

    np.testing.assert_allclose(system_modes(system).omega, closed, rtol=1e-9)
    np.testing.assert_allclose(system.damping.toarray(), 2.0 * m, rtol=1e-15)


def test_a_reduced_model_file_equals_the_python_reduction(tmp_path: Path) -> None:
    path = _write(tmp_path, "reduce_modes = 6")
    reduced = read_model(path)
    assert isinstance(reduced, ReducedSystem)
    assert set(reduced.boundary) == {N_SIDE - 1, N_SIDE, 17}  # the joint and the forced DOF
    m, k = _chains()
    law = ClearanceJoint(50e-6, 1e5, gap_stiffness=2e3)
    by_hand = reduce(
        from_matrices(m, k, joints=[(N_SIDE - 1, N_SIDE, law)], rayleigh=(2.0, 0.0)),
        modes=6,
        keep=[17],
    )
    np.testing.assert_allclose(reduced.stiffness, by_hand.stiffness, rtol=1e-12, atol=1e-6)


@pytest.mark.parametrize("extra", ["", "reduce_modes = 6"])
def test_the_cli_runs_modes_respond_decay_and_frf_on_a_model_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], extra: str
) -> None:
    path = _write(tmp_path, extra)
    for task in ("modes", "respond", "decay"):
        out = tmp_path / f"{task}.nc"
        code, text, err = run(["structure", str(path), task, "--out", str(out), "--json"], capsys)
        assert code == 0, err
        summary = json.loads(text)
        if task == "modes":
            m, k = _chains()
            b = np.zeros(2 * N_SIDE)
            b[N_SIDE - 1], b[N_SIDE] = 1.0, -1.0
            w = np.sqrt(scipy.linalg.eigvalsh(k + (2e3 + 1e5) * np.outer(b, b), m))
            rtol = 1e-9 if not extra else 1e-2  # 6 of 17 interior modes kept
            np.testing.assert_allclose(summary["closed_hz"][:3], w[:3] / (2 * math.pi), rtol=rtol)
        if task == "respond":
            assert summary["balance_error"] < 1e-8
    out = tmp_path / "frf.nc"
    args = ["frf", str(path), "--from", "19Hz", "--to", "21Hz", "--out", str(out)]
    code, text, err = run([*args, "--method", "harmonic", "--harmonics", "3", "--json"], capsys)
    assert code == 0, err


def test_the_forced_response_of_a_model_file_is_the_python_apis(tmp_path: Path) -> None:
    m, k = _chains()
    law = ClearanceJoint(50e-6, 1e5, gap_stiffness=2e3)
    system = from_matrices(m, k, joints=[(N_SIDE - 1, N_SIDE, law)], rayleigh=(2.0, 0.0))
    from clearjoint.structure.study import load_structure_study

    study = load_structure_study(_write(tmp_path))
    force = np.zeros(2 * N_SIDE)
    force[17] = 3.0
    np.testing.assert_array_equal(study.force, force)
    w = 2 * math.pi * 20.0
    a = time_response(system, force, w, 0.1)
    b = time_response(study.structure, study.force, w, 0.1)
    # the file's matrices are sparse, the API's dense: equal to round-off, not bitwise
    np.testing.assert_allclose(a.u, b.u, rtol=1e-9, atol=1e-12 * np.abs(a.u).max())


@pytest.mark.parametrize(
    ("change", "match"),
    [
        (('joints = [["m10", "m11"]]', 'joints = [["m10", "m99"]]'), "'m99', which does not"),
        (('mass = "m.mtx"', 'mass = "none.mtx"'), "no such matrix file"),
        (('force_dof = "m18"', 'force_dof = "m77"'), r"\[excitation\] names DOF 'm77'"),
        (('joints = [["m10", "m11"]]', "joints = [3]"), "must be a pair of DOF names"),
        (("[joint]", "[jointx]"), "unknown section"),
    ],
)
def test_a_bad_model_file_is_one_line_naming_the_problem(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], change: tuple[str, str], match: str
) -> None:
    path = _write(tmp_path)
    path.write_text(path.read_text().replace(*change))
    with pytest.raises(StructureStudyError, match=match):
        read_model(path)
    code, _, err = run(["structure", str(path), "modes", "--out", str(tmp_path / "x.nc")], capsys)
    assert code == 2
    assert len(err.strip().splitlines()) == 1
