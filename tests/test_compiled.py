"""compiled: the kernels compiled at install give the JIT kernels' results to the bit, a
documented command's cold run compiles nothing with them, and anything they cannot take
(another dtype, a view, a stale module, ``CLEARJOINT_COMPILED=0``) goes to the JIT kernels.

The module is built by the install (``pip install -e .``, its build hook) or by
``python -m clearjoint.compiled``; without it these tests skip, unless
``CLEARJOINT_REQUIRE_COMPILED=1`` (CI) makes its absence a failure.
"""

from __future__ import annotations

import math
import os
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import xarray as xr
from numba.core.errors import TypingError

from clearjoint import Joint, Losses, compiled, continuation, harmonic, periodic
from clearjoint.exact import shooting, single
from clearjoint.laws import clearance
from clearjoint.periodic import frequency_response
from clearjoint.simulate import time_response

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "src" / "clearjoint"

#: pyHarm's SDOF clearance case (as tests/test_periodic.py): a curve with folds and grazings.
PYHARM = Joint(
    mass=1.0, clearance=0.349, gap_stiffness=1.0, compression_stiffness=3.0, tension_stiffness=3.0
)
LOSSES = Losses(damping_ratio=0.05 / (2.0 * math.sqrt(3.0)))


def _require_module() -> None:
    if compiled.load() is None:
        message = (
            "the kernels compiled at install are absent: build them with "
            "`python -m clearjoint.compiled` (or reinstall: pip install -e .)"
        )
        if os.environ.get("CLEARJOINT_REQUIRE_COMPILED") == "1":
            pytest.fail(message)
        pytest.skip(message)


def _jit_only(monkeypatch: pytest.MonkeyPatch) -> int:
    """Point every Python caller back at the JIT kernels; return how many were switched."""
    switched = 0
    for module in (single, shooting, periodic, continuation):
        for name, value in list(vars(module).items()):
            if callable(value) and hasattr(value, "jit"):
                monkeypatch.setattr(module, name, value.jit)
                switched += 1
    monkeypatch.setattr(compiled, "_loaded", None)  # prefer() at call time: joint.py
    monkeypatch.setattr(compiled, "_preferred", {})
    return switched


def _same_bits(a: xr.Dataset, b: xr.Dataset) -> list[str]:
    """The variables and coordinates of two datasets whose bytes differ."""
    names = [*a.data_vars, *a.coords]
    return [
        str(n)
        for n in names
        if a[n].dtype.kind in "fiub" and a[n].values.tobytes() != b[n].values.tobytes()
    ]


def test_the_compiled_kernels_give_the_jit_kernels_results_to_the_bit(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    _require_module()
    assert periodic._correct_orbit is not shooting.correct_orbit  # the compiled one in use

    def run() -> tuple[xr.Dataset, xr.Dataset, xr.Dataset]:
        curve = frequency_response(PYHARM, 0.03, 0.05, 1.8, losses=LOSSES)
        motion = time_response(PYHARM, 0.03, 1.1, 60.0, initial=(0.3, 0.0), losses=LOSSES)
        balanced = harmonic.frequency_response(
            PYHARM, 0.03, 1.0, 1.7, harmonics=12, losses=LOSSES, max_step=0.1
        )
        return curve.to_xarray(), motion.to_xarray(), balanced.to_xarray()

    compiled_runs = run()
    # 4 in single, 2 in shooting, 3 in periodic, 2 in continuation; harmonic.aft asks each call
    assert _jit_only(monkeypatch) == 11
    jit_runs = run()
    assert compiled_runs[0].sizes["point"] > 50
    assert compiled_runs[2].sizes["point"] > 50
    for ours, theirs in zip(compiled_runs, jit_runs, strict=True):
        assert ours.sizes == theirs.sizes
        assert _same_bits(ours, theirs) == []
    monkeypatch.undo()
    samples = np.linspace(-0.5, 0.5, 101)[:, None].copy()  # across both gap edges
    parameters = clearance.parameters((PYHARM,))
    for kernel, arguments in (
        (clearance.forces_and_tangents, parameters),
        (clearance.potentials, parameters),
        (clearance.contact_forces, parameters[1:]),
    ):
        ours = compiled.prefer(kernel)
        assert ours is not kernel
        got, expected = ours(samples, *arguments), kernel(samples, *arguments)
        for a, b in zip(np.atleast_1d(got), np.atleast_1d(expected), strict=True):
            assert np.asarray(a).tobytes() == np.asarray(b).tobytes()


def _small_mast_motion() -> xr.Dataset:
    """Two forcing periods of a 3-bay mast near its first closed mode: over 40 events."""
    from clearjoint import ClearanceJoint
    from clearjoint.structure import mast, time_response

    s = mast(3, joints=ClearanceJoint(50e-6, 5e7, gap_stiffness=1e5), rayleigh=(0.5, 2e-6))
    force = np.zeros(s.n_dof)
    force[-2] = 20.0
    omega = 0.9 * float(s.modes("closed").omega[0])
    motion = time_response(s, force, omega, 4.0 * math.pi / omega, samples_per_period=32)
    assert motion.events > 40
    return motion.to_xarray()


def test_a_structures_exact_motion_is_the_jit_kernels_to_the_bit(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The event-driven march of a small mast (structure/motion.py: march, the state
    tables, the contact states, the pattern history): the same motion to the bit."""
    _require_module()
    ours = _small_mast_motion()
    _jit_only(monkeypatch)
    theirs = _small_mast_motion()
    assert ours.sizes == theirs.sizes
    assert _same_bits(ours, theirs) == []


@pytest.mark.parametrize(
    "samples",
    [
        np.linspace(-0.5, 0.5, 8, dtype=np.float32)[:, None],  # another dtype
        np.asfortranarray(np.linspace(-0.5, 0.5, 16).reshape(8, 2))[:, :1],  # a strided view
    ],
    ids=["float32", "view"],
)
def test_arguments_the_export_cannot_take_go_to_the_jit_kernel(samples: np.ndarray) -> None:
    """The extension converts its arguments unchecked (a float32 array would crash the
    process): the wrapper checks them and hands anything else to numba."""
    _require_module()
    law = compiled.prefer(clearance.forces_and_tangents)
    assert law is not clearance.forces_and_tangents
    parameters = clearance.parameters((PYHARM,))
    force, tangent = law(samples, *parameters)
    expected = clearance.forces_and_tangents(
        np.ascontiguousarray(samples, dtype=np.float64), *parameters
    )
    np.testing.assert_allclose(force, expected[0], rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(tangent, expected[1], rtol=1e-6)


@pytest.mark.parametrize(
    ("kind", "value", "taken"),
    [
        ("f8[::1]", np.zeros(3), True),
        ("f8[::1]", np.zeros(3, dtype=np.float32), False),
        ("f8[::1]", np.zeros((3, 1)), False),
        ("f8[::1]", np.zeros(6)[::2], False),
        ("f8[::1]", [0.0, 0.0], False),
        ("f8[:, ::1]", np.zeros((2, 3)), True),
        ("f8[:, ::1]", np.zeros((2, 3), order="F"), False),
        ("f8[::1, :]", np.zeros((2, 3), order="F"), True),
        ("f8[::1, :]", np.zeros((2, 3)), False),
        ("f8[::1, :]", np.zeros((2, 3), dtype=np.float32, order="F"), False),
        ("i1[::1]", np.zeros(3, dtype=np.int8), True),
        ("i1[::1]", np.zeros(3, dtype=np.int64), False),
        ("i8[::1]", np.zeros(3, dtype=np.int64), True),
        ("i8[::1]", np.zeros(3), False),
        ("i1[:, ::1]", np.zeros((2, 2), dtype=np.int8), True),
        ("i8", 3, True),
        ("i8", np.int32(3), True),
        ("i8", 2**63, False),
        ("i8", 3.0, False),
        ("f8", 0.5, True),
        ("f8", 2, True),
        ("f8", "0.5", False),
        ("f8", 1j, False),
        ("b1", True, True),
        ("b1", np.bool_(False), True),
        ("b1", 1, False),
    ],
)
def test_each_argument_kind_is_checked(kind: str, value: Any, taken: bool) -> None:
    assert compiled._ACCEPTS[kind](value) is taken


def test_a_read_only_array_is_not_handed_to_the_export() -> None:
    frozen = np.zeros(3)
    frozen.flags.writeable = False
    assert not compiled._ACCEPTS["f8[::1]"](frozen)


def test_every_export_signature_is_read_as_its_kernel_takes_it() -> None:
    """Each signature's argument count is its Python function's (no kernel's arguments
    were dropped or added without the table following)."""
    import importlib
    import inspect

    for module, name, signature in compiled.EXPORTS:
        function = getattr(importlib.import_module(module), name).py_func
        assert len(compiled.argument_kinds(signature)) == len(
            inspect.signature(function).parameters
        ), name


def _copy_package(tmp_path: Path) -> Path:
    copy = tmp_path / "clearjoint"
    shutil.copytree(PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__", "_kernels_*"))
    return copy


def test_the_module_name_follows_the_kernels_source_only(tmp_path: Path) -> None:
    copy = _copy_package(tmp_path)
    name = compiled.module_name(copy)
    assert name == compiled.module_name()
    assert name.startswith("_kernels_")
    (copy / "cli.py").write_text((copy / "cli.py").read_text() + "\n# no kernel here\n")
    assert compiled.module_name(copy) == name
    law = copy / "laws" / "clearance.py"
    law.write_text(law.read_text() + "\n# a changed kernel file\n")
    assert compiled.module_name(copy) != name


def _python(code: str, **env: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-c", code],
        cwd=ROOT,
        env=dict(os.environ, **env),
        capture_output=True,
        text=True,
        check=True,
        timeout=600,
    )


def test_the_switch_turns_the_compiled_kernels_off() -> None:
    code = "from clearjoint import compiled; print(compiled.load() is None)"
    assert _python(code, CLEARJOINT_COMPILED="0").stdout.split() == ["True"]


def test_a_documented_commands_cold_run_compiles_nothing(tmp_path: Path) -> None:
    """`clearjoint frf examples/frf.toml --from 10Hz --to 360Hz` with an empty numba cache:
    every kernel it calls from Python is exported, so numba never compiles (it would say
    "compiling the solvers, first run only")."""
    _require_module()
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "clearjoint",
            "frf",
            "examples/frf.toml",
            "--from",
            "10Hz",
            "--to",
            "360Hz",
            "--out",
            str(tmp_path / "frf.nc"),
        ],
        cwd=ROOT,
        env=dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "empty-cache")),
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr
    assert "compiling the solvers" not in done.stderr
    assert (tmp_path / "frf.nc").is_file()
    cached = list((tmp_path / "empty-cache").rglob("*.nbc"))
    assert cached == []


def test_a_kernel_of_an_exported_name_from_another_module_stays_itself() -> None:
    """The export is looked up by name: a function of that name from another module (here
    a plain Python ``state_law``) must not be sent to the compiled one."""
    _require_module()

    def state_law(state: int, k0: float, k_c: float, k_t: float, g_c: float, g_t: float) -> Any:
        return ("not the clearance law", state)

    ours = compiled.prefer(state_law)
    assert ours(1, 1.0, 3.0, 3.0, 0.1, 0.1) == ("not the clearance law", 1)


def test_keyword_arguments_go_to_the_jit_kernel() -> None:
    """The extension takes its arguments by position only: a call by keyword gives the
    same result as by position (it failed with a TypeError of the wrapper)."""
    _require_module()
    law = compiled.prefer(clearance.contact_forces)
    assert law is not clearance.contact_forces
    samples = np.linspace(-0.5, 0.5, 11)[:, None].copy()
    _, k_c, k_t, g_c, g_t = clearance.parameters((PYHARM,))
    by_position = law(samples, k_c, k_t, g_c, g_t)
    by_keyword = law(samples, k_c=k_c, k_t=k_t, g_c=g_c, g_t=g_t)
    assert by_keyword.tobytes() == by_position.tobytes()
    # an independent value: the contact force is zero inside the gap, positive beyond it
    assert by_position[5, 0] == 0.0
    assert by_position[0, 0] > 0.0
    assert by_position[-1, 0] > 0.0


@pytest.mark.parametrize(
    ("samples", "taken"),
    [
        (np.zeros((8, 2))[:, :1], False),  # every other element: strided
        (np.zeros(8)[::-1][:, None], False),  # negative stride
        # numpy counts these as C-contiguous (a size-1 axis's stride is ignored), and so
        # does the compiled code, which addresses a C array by its shape
        (np.asfortranarray(np.zeros((8, 2)))[:, :1], True),
        (np.lib.stride_tricks.as_strided(np.zeros(3), (1, 3), (0, 8), writeable=True), True),
    ],
    ids=["strided", "reversed", "size-1-axis", "zero-stride-size-1-axis"],
)
def test_which_views_the_export_takes_and_that_they_give_the_same_forces(
    samples: np.ndarray, taken: bool
) -> None:
    """Checked by value against the law on a fresh C array of the same numbers."""
    _require_module()
    assert compiled._ACCEPTS["f8[:, ::1]"](samples) is taken
    samples[...] = np.linspace(-0.5, 0.5, samples.size).reshape(samples.shape)
    law = compiled.prefer(clearance.forces_and_tangents)
    parameters = clearance.parameters((PYHARM,))
    force, _ = law(samples, *parameters)
    expected, _ = clearance.forces_and_tangents(
        np.array(samples, dtype=np.float64, order="C"), *parameters
    )
    assert force.tobytes() == expected.tobytes()


def test_a_big_endian_array_is_refused_not_read_as_other_numbers() -> None:
    """float64 but big-endian: the extension would read its bytes as little-endian
    numbers, unchecked; the check sends it to numba, which refuses it by name."""
    _require_module()
    samples = np.linspace(-0.5, 0.5, 8)[:, None].astype(">f8")
    assert not compiled._ACCEPTS["f8[:, ::1]"](samples)
    law = compiled.prefer(clearance.forces_and_tangents)
    with pytest.raises(TypingError, match="dtype"):
        law(samples, *clearance.parameters((PYHARM,)))


class _Counting:
    """The compiled module, counting the calls that reach each of its functions."""

    def __init__(self, module: Any) -> None:
        self.module = module
        self.calls: dict[str, int] = {}

    def __getattr__(self, name: str) -> Any:
        exported = getattr(self.module, name)

        def counted(*args: Any) -> Any:
            self.calls[name] = self.calls.get(name, 0) + 1
            return exported(*args)

        return counted


def test_a_structures_motion_reaches_the_compiled_kernels(monkeypatch: pytest.MonkeyPatch) -> None:
    """The comparison to the bit above would pass too if every call fell back to the JIT
    kernels (an argument the checks refuse): the structure's march, state tables, contact
    states and pattern history must each reach the module."""
    _require_module()
    counting = _Counting(compiled.load())
    monkeypatch.setattr(compiled, "_loaded", counting)
    monkeypatch.setattr(compiled, "_preferred", {})
    _small_mast_motion()
    for name in ("march", "state_tables", "contact_states", "pattern_history"):
        assert counting.calls.get(name, 0) >= 1, (name, counting.calls)
