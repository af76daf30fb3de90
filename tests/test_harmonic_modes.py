"""Nonlinear modes by EPMC (MODEL.md 5.4) against the exact period T(A) and the dissipation."""

from __future__ import annotations

import math

import matplotlib
import numpy as np
import pytest

from clearjoint import Friction, Joint, ParameterError, dissipation, stiffness
from clearjoint.harmonic import HarmonicError, NonlinearMode, nonlinear_modes

matplotlib.use("Agg")

from helpers import CASES, joint

AMPLITUDES = np.geomspace(70e-6, 2e-3, 5)


def _backbone_error(j: Joint, harmonics: int) -> float:
    nm = nonlinear_modes(j, 1, AMPLITUDES, harmonics=harmonics)
    assert nm.converged.all()
    assert np.max(np.abs(nm.damping_ratio)) < 1e-12  # no losses: xi = 0
    exact = 2.0 * math.pi / stiffness.period(j, nm.x_max - j.compression_gap)
    return float(np.max(np.abs(nm.frequency / exact - 1.0)))


@pytest.mark.parametrize("name", ["symmetric", "off-centre"])
def test_backbone_is_the_exact_free_period_and_converges_with_h(name: str) -> None:
    """w at x_max equals 2 pi / T(A), A = x_max - g_c, within the truncation error."""
    j = CASES[name]
    errors = [_backbone_error(j, h) for h in (3, 7, 15)]
    assert errors[1] < 3e-3
    assert errors[2] < 1e-3
    assert errors[2] < errors[0] / 4.0


def test_viscous_loss_and_damping_ratio() -> None:
    j = joint()
    zeta = 0.02
    nm = nonlinear_modes(j, 1, AMPLITUDES, harmonics=15, damping_ratio=zeta)
    penetration = nm.x_max - j.compression_gap
    # E_diss per cycle: the closed form on the free cycle of clearjoint.dissipation
    e_diss = dissipation.viscous(j, penetration, zeta)
    np.testing.assert_allclose(nm.energy_per_cycle, e_diss, rtol=2e-3)
    # zeta = E_diss / (4 pi E_max) holds for near-harmonic motion: far above the gap
    loss = e_diss / (4.0 * math.pi * j.potential_energy(nm.x_max))
    ratio = nm.damping_ratio / loss
    assert ratio[-1] == pytest.approx(1.0, abs=0.03)
    assert abs(ratio[-1] - 1.0) < abs(ratio[0] - 1.0)  # and less so near it


def test_no_mode_inside_the_gap_is_flagged() -> None:
    j = joint()  # k0 = 0: no restoring force inside the gap
    nm = nonlinear_modes(j, 1, [0.1 * j.clearance, 1e-3], harmonics=5)
    assert list(nm.converged) == [False, True]
    assert math.isnan(nm.frequency[0])
    assert "1 not converged" in repr(nm)


def test_result_object() -> None:
    nm = nonlinear_modes(joint(), 1, AMPLITUDES, harmonics=5, damping_ratio=0.01)
    assert isinstance(nm, NonlinearMode)
    assert nm.harmonic_shapes.shape == (5, 11)
    ds = nm.to_xarray()
    assert ds["frequency"].attrs["units"] == "Hz"
    assert ds["energy_per_cycle"].attrs["units"] == "J"
    assert nm.plot().get_ylabel() == "natural frequency (Hz)"
    assert len(repr(nm)) < 250


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"mode": 2}, ParameterError, "a Joint has only mode 1"),
        ({"amplitudes": [0.0, 1e-3]}, ParameterError, "amplitudes must be > 0"),
        ({"amplitudes": [-1e-6, 1e-3]}, ParameterError, "starts at -1e-06"),
        ({"harmonics": 0}, HarmonicError, "harmonics must be an integer >= 1"),
        ({"samples": 5}, HarmonicError, "samples must be an integer"),
        ({"friction": Friction(0.1, 10.0)}, HarmonicError, "does not carry Coulomb friction"),
        ({"restitution": 0.5}, HarmonicError, "clearjoint.periodic"),
    ],
)
def test_bad_input(kwargs: dict[str, object], error: type, match: str) -> None:
    args: dict[str, object] = {"mode": 1, "amplitudes": AMPLITUDES}
    args.update(kwargs)
    with pytest.raises(error, match=match):
        nonlinear_modes(joint(), **args)  # type: ignore[arg-type]
