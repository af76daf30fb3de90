"""Frequency response by harmonic balance (MODEL.md 5.3) against exact shooting orbits (5.1)."""

from __future__ import annotations

import math

import matplotlib
import numpy as np
import pytest

from clearjoint import Friction, Losses, ParameterError
from clearjoint.harmonic import HarmonicError, frequency_response
from clearjoint.periodic import FrequencyResponse, periodic_orbit
from clearjoint.simulate import SimulationError
from helpers import with_losses

matplotlib.use("Agg")

from test_harmonic_aft import PYHARM, PYHARM_ZETA


@pytest.fixture(scope="module")
def curve() -> FrequencyResponse:
    """The pyHarm case around its resonance: both folds, three branches (H = 12)."""
    return frequency_response(
        PYHARM, 0.03, 1.0, 1.7, harmonics=12, losses=Losses(damping_ratio=PYHARM_ZETA), max_step=0.1
    )


def test_curve_has_both_folds_and_the_grazing(curve: FrequencyResponse) -> None:
    assert curve.method == "harmonic"
    assert curve.stop_reason == "reached"
    folds = sorted(e.omega for e in curve.events if e.kind == "fold")
    # exact shooting (clearjoint.periodic) puts them at 1.0797 and 1.5350 rad/s
    assert len(folds) == 2
    assert folds[0] == pytest.approx(1.0797, rel=2e-3)
    assert folds[1] == pytest.approx(1.5350, rel=1e-3)
    assert any(e.kind == "grazing" for e in curve.events)
    assert curve.coefficients is not None
    assert curve.coefficients.shape == (curve.omega.size, 25)
    assert np.any(~curve.stable)


def test_hill_stability_agrees_with_floquet_away_from_bifurcations(
    curve: FrequencyResponse,
) -> None:
    """Each HB point, polished into the exact orbit by shooting, has the same stability."""
    compared = 0
    for i in range(0, curve.omega.size, 4):
        try:
            exact = periodic_orbit(
                PYHARM,
                0.03,
                float(curve.omega[i]),
                losses=Losses(damping_ratio=PYHARM_ZETA),
                initial=curve.initial_state[i],
            )
        except SimulationError:
            continue  # right at the grazing fold Newton on the exact map may not start
        assert exact.amplitude == pytest.approx(curve.amplitude[i], rel=2e-3)
        mu_exact = float(np.max(np.abs(exact.multipliers)))
        if abs(mu_exact - 1.0) < 0.03:
            continue
        assert bool(curve.stable[i]) == exact.stable
        mu_hill = float(np.max(np.abs(curve.multipliers[i])))
        assert mu_hill == pytest.approx(mu_exact, rel=0.05)
        compared += 1
    assert compared >= 15


def test_result_plots_and_exports(curve: FrequencyResponse) -> None:
    ds = curve.to_xarray()
    assert ds["coefficients"].attrs["units"] == "m"
    assert ds.attrs["method"] == "harmonic"
    ax = curve.plot()
    assert ax.get_xlabel() == "frequency (Hz)"
    text = repr(curve)
    assert "FrequencyResponse(" in text
    assert len(text) < 300
    with pytest.raises(ParameterError, match="periodic_orbit"):
        curve.cycle(0)


def test_force_continuation_reaches_the_exact_orbit() -> None:
    fr = frequency_response(
        PYHARM,
        0.01,
        0.9,
        None,
        harmonics=15,
        losses=Losses(damping_ratio=PYHARM_ZETA),
        parameter="force",
        force_stop=0.05,
        max_step=0.2,
    )
    assert fr.force_amplitude[-1] == pytest.approx(0.05)
    exact = periodic_orbit(
        PYHARM, 0.05, 0.9, losses=Losses(damping_ratio=PYHARM_ZETA), initial=fr.initial_state[-1]
    )
    assert exact.x_max > PYHARM.compression_gap
    assert fr.x_max[-1] == pytest.approx(exact.x_max, rel=1e-4)


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"omega_stop": 1.0}, ParameterError, "zero width"),
        ({"omega_start": math.nan}, ParameterError, "omega_start must be finite"),
        ({"harmonics": 0}, HarmonicError, "harmonics must be an integer >= 1"),
        ({"samples": 10}, HarmonicError, "samples must be an integer >= 2"),
        ({"restitution": 0.7}, HarmonicError, "clearjoint.periodic"),
        ({"friction": Friction(0.01, 1.0, "free-play")}, HarmonicError, "free-play stroke only"),
        ({"friction": Friction(0.01, 1.0), "friction_regularization": 0.0}, ParameterError, "> 0"),
        ({"parameter": "force"}, ParameterError, "force_stop is required"),
        ({"force": [0.1, 0.2]}, Exception, "force"),
    ],
)
def test_bad_input_one_clear_message(kwargs: dict[str, object], error: type, match: str) -> None:
    args: dict[str, object] = {"force": 0.03, "omega_start": 1.0, "omega_stop": 1.7}
    args.update(kwargs)
    with pytest.raises(error, match=match):
        frequency_response(
            PYHARM,
            args.pop("force"),  # type: ignore[arg-type]
            args.pop("omega_start"),  # type: ignore[arg-type]
            args.pop("omega_stop"),  # type: ignore[arg-type]
            **with_losses(args),  # type: ignore[arg-type]
        )


@pytest.mark.parametrize("omega", [0.8, 1.3])
def test_regularised_friction_against_exact_stick_slip_orbits(omega: float) -> None:
    """mu_s P tanh(v / v_eps) with the default v_eps: x_max and stability vs exact shooting."""
    friction = Friction(0.005, 1.0)
    fr = frequency_response(
        PYHARM,
        0.03,
        omega,
        1.001 * omega,
        harmonics=15,
        losses=Losses(damping_ratio=PYHARM_ZETA, friction=friction),
        max_points=2,
    )
    exact = periodic_orbit(
        PYHARM,
        0.03,
        omega,
        losses=Losses(damping_ratio=PYHARM_ZETA, friction=friction),
        initial=fr.initial_state[0],
    )
    assert abs(fr.x_max[0] - exact.x_max) < 2e-3 * exact.amplitude
    assert bool(fr.stable[0]) == exact.stable
    mu = float(np.max(np.abs(fr.multipliers[0])))
    assert mu == pytest.approx(float(np.max(np.abs(exact.multipliers))), rel=0.01)


def test_stability_is_recomputed_where_the_continuation_kept_no_evaluation(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Stability reuses the continuation's evaluation at each point, or evaluates anew."""
    import dataclasses

    import clearjoint.harmonic.response as response

    def run() -> FrequencyResponse:
        return frequency_response(
            PYHARM, 0.03, 1.0, 1.2, harmonics=7, losses=Losses(damping_ratio=PYHARM_ZETA)
        )

    kept = run()
    real = response.continue_branch

    def without_data(*args: object, **kwargs: object):  # type: ignore[no-untyped-def]
        branch = real(*args, **kwargs)  # type: ignore[arg-type]
        return dataclasses.replace(branch, data=[None] * len(branch.data))

    monkeypatch.setattr(response, "continue_branch", without_data)
    anew = run()
    assert anew.omega.size == kept.omega.size
    np.testing.assert_allclose(anew.multipliers, kept.multipliers, rtol=1e-12, atol=1e-15)


def test_compiled_one_dof_corrector_follows_the_same_curve(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """aft.OneDofResidual's compiled corrector and continuation's own Python one agree."""
    from clearjoint.harmonic import aft

    calls = []
    original = aft.OneDofResidual.corrector

    def counted(self: aft.OneDofResidual, *args: object) -> object:
        calls.append(1)
        return original(self, *args)  # type: ignore[arg-type]

    monkeypatch.setattr(aft.OneDofResidual, "corrector", counted)
    fast = frequency_response(
        PYHARM, 0.03, 0.6, 1.8, harmonics=7, losses=Losses(damping_ratio=PYHARM_ZETA)
    )
    assert len(calls) >= fast.omega.size
    monkeypatch.delattr(aft.OneDofResidual, "corrector")
    plain = frequency_response(
        PYHARM, 0.03, 0.6, 1.8, harmonics=7, losses=Losses(damping_ratio=PYHARM_ZETA)
    )
    # the same Newton steps from the same start (continuation's own corrector, asked for
    # the compiled one's, keeps dR/dw as a chord; step sizes then differ a little)
    np.testing.assert_allclose(fast.omega[:4], plain.omega[:4], rtol=1e-9)
    np.testing.assert_allclose(fast.coefficients[:4], plain.coefficients[:4], atol=1e-10)
    assert fast.stop_reason == plain.stop_reason == "reached"
    assert np.max(fast.amplitude) == pytest.approx(np.max(plain.amplitude), rel=1e-4)
    mine = sorted((e.kind, e.omega) for e in fast.events)
    theirs = sorted((e.kind, e.omega) for e in plain.events)
    assert [k for k, _ in mine] == [k for k, _ in theirs]
    np.testing.assert_allclose([w for _, w in mine], [w for _, w in theirs], rtol=2e-3)
