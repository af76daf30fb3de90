"""The identification's fast paths against the calls they replace (issue 15, speed)."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from clearjoint.identify.cycles import _hanning


@pytest.mark.parametrize("n", [16, 3600, 8221])
def test_cached_window_is_numpys_hanning_and_read_only(n: int) -> None:
    window = _hanning(n)
    assert window.tobytes() == np.hanning(n).tobytes()
    assert _hanning(n) is window  # made once per length
    with pytest.raises(ValueError, match="read-only"):
        window[0] = 1.0


@pytest.mark.parametrize("n", [3, 8, 9, 37])
def test_leave_one_out_by_slices_is_the_sum_over_copies_bit_for_bit(n: int) -> None:
    from clearjoint.identify.core import _groups, _leave_one_out

    values = np.random.default_rng(n).standard_normal((n, 257)) * 1e3
    groups = _groups(n)
    total = values.sum(axis=0)
    before = np.array([(total - values[g].sum(axis=0)) / (n - g.size) for g in groups])
    assert _leave_one_out(values, groups).tobytes() == before.tobytes()
    # and against the definition, the mean of the other rows, to rounding
    for k, g in enumerate(groups):
        others = np.delete(values, g, axis=0).mean(axis=0)
        np.testing.assert_allclose(_leave_one_out(values, groups)[k], others, rtol=1e-12)


@pytest.mark.parametrize("m", [2, 5, 48])
def test_cached_pieces_are_numpys_upper_triangle(m: int) -> None:
    from clearjoint.identify.segments import _pieces

    i, j = _pieces(m)
    ref_i, ref_j = np.triu_indices(m + 1, k=2)
    np.testing.assert_array_equal(i, ref_i, strict=True)
    np.testing.assert_array_equal(j, ref_j, strict=True)
    assert np.all(j - i >= 2)
    assert _pieces(m)[0] is i


def test_per_cycle_values_are_python_floats_of_their_own_cycle() -> None:
    # a shipped BRFD record: each cycle's amplitude is nearest to half the range of the
    # record's displacement over that cycle's own samples (not another cycle's; the stack
    # interpolates, so to 1e-4 here, where the cycles differ by 3e-4 to 8e-4)
    from pathlib import Path

    from clearjoint.identify import identify
    from clearjoint.records import read_brfd

    shipped = Path(__file__).resolve().parent / "data" / "brfd" / "2Hz30lbtension0.5amplitude.json"
    record = read_brfd(shipped)
    ident = identify(record)
    assert len(ident.cycles) >= 3
    amplitude = np.array([c.values["amplitude_m"] for c in ident.cycles])
    own = np.array([0.5 * np.ptp(record.displacement[c.start : c.stop]) for c in ident.cycles])
    misfit = np.abs(amplitude[:, None] / own[None, :] - 1.0)
    assert np.all(np.argmin(misfit, axis=1) == np.arange(len(ident.cycles)))
    assert np.all(np.diag(misfit) < 1e-4)
    for cycle in ident.cycles:
        assert all(type(v) is float for v in cycle.values.values())


@pytest.mark.parametrize("n", [1, 2, 7, 256, 1001])
def test_robust_rms_is_the_numpy_median_formula_bit_for_bit(n: int) -> None:
    from clearjoint.identify.loopcheck import MAD_TO_RMS, _robust_rms

    rng = np.random.default_rng(n)
    for values in (rng.standard_normal(n) * 3e2, np.round(rng.standard_normal(n), 1)):
        before = float(MAD_TO_RMS * np.median(np.abs(values - np.median(values))))
        assert np.float64(_robust_rms(values)).tobytes() == np.float64(before).tobytes()


def test_identifying_a_rig_record_does_not_import_numpy_ma(tmp_path: Path) -> None:
    """The rig path's noise floor took numpy.median (numpy.ma's import, ~10 ms a process)."""
    from clearjoint.rig import load_campaign, run_campaign

    spec = tmp_path / "campaign.toml"
    spec.write_text(
        'seed = 3\nperiods = 12\n[grid]\nfrequencies = ["60Hz"]\nforce_amplitudes = ["2000N"]\n'
    )
    run_campaign(load_campaign(spec), tmp_path / "records", jobs=1)
    record = sorted((tmp_path / "records").glob("*.nc"))[0]
    code = (
        "import sys\n"
        "from clearjoint.identify import identify\n"
        "from clearjoint.records import read_record\n"
        f"identify(read_record({str(record)!r}))\n"
        "print(sorted(m for m in sys.modules if m.split('.')[:2] == ['numpy', 'ma']))\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "[]"


def _dynamic_through_joint(
    k_c: float, k_t: float, k0: float, c: float, a_c: float, m: float
) -> float:
    """The replicates' dynamic stiffness as it was: a validated Joint, then dynamic_stiffness."""
    from clearjoint import Joint, stiffness
    from clearjoint.errors import ClearjointError

    if not m or not (k_c > k0 and k_t > k0 and a_c > 0):
        return float("nan")
    try:
        joint = Joint(
            mass=m,
            clearance=max(c, 0.0),
            compression_stiffness=k_c - k0,
            tension_stiffness=k_t - k0,
            gap_stiffness=k0,
        )
        return float(stiffness.dynamic_stiffness(joint, a_c))
    except ClearjointError:
        return float("nan")


def test_replicate_dynamic_stiffness_is_the_validated_joints_bit_for_bit() -> None:
    from clearjoint.identify.core import _dynamic
    from clearjoint.identify.segments import _Fit

    rng = np.random.default_rng(15)
    cases = [
        (8e7 * rng.uniform(0.2, 2), 8e7 * rng.uniform(0.2, 2), k0, c, a, m)
        for k0 in (0.0, 2e5, 3e7)
        for c in (0.0, 1.06e-4 * rng.uniform(0.5, 2), -1e-6)
        for a in (1e-9, 2e-5 * rng.uniform(0.5, 2), 3e-3)
        for m in (1.5, 0.02)
    ]
    nan, inf = float("nan"), float("inf")
    # values a Joint refuses (NaN out) and those the guard stops first
    cases += [
        (8e7, 6e7, -1e5, 1e-4, 2e-5, 1.5),
        (inf, 6e7, 0.0, 1e-4, 2e-5, 1.5),
        (8e7, 6e7, 0.0, inf, 2e-5, 1.5),
        (8e7, 6e7, 0.0, nan, 2e-5, 1.5),
        (8e7, 6e7, 0.0, 1e-4, inf, 1.5),
        (8e7, 6e7, 0.0, 1e-4, 2e-5, nan),
        (8e7, 6e7, 0.0, 1e-4, 2e-5, -1.5),
        (8e7, 6e7, 0.0, 1e-4, 2e-5, inf),
        (8e7, 6e7, 0.0, 1e-4, 0.0, 1.5),
        (8e7, 6e7, 9e7, 1e-4, 2e-5, 1.5),
    ]
    finite = 0
    for k_c, k_t, k0, c, a, m in cases:
        fit = _Fit(0.0, 0.0, np.float64(k_c), np.float64(k_t), np.float64(k0), 1.0)
        new = _dynamic(fit, c, a, m)
        old = _dynamic_through_joint(k_c, k_t, k0, c, a, m)
        assert np.float64(new).tobytes() == np.float64(old).tobytes(), (k_c, k_t, k0, c, a, m)
        finite += math.isfinite(new)
    assert finite >= 40  # most regular cases have a value (not a comparison of NaNs)
    # and k_d against MODEL.md eq 9's closed form, k0 = 0 and a symmetric joint
    fit = _Fit(0.0, 0.0, 8e7, 8e7, 0.0, 1.0)
    ratio = _dynamic(fit, 1.06e-4, 2e-5, 2.0) / 8e7
    assert ratio == pytest.approx((math.pi * 2e-5 / (math.pi * 2e-5 + 1.06e-4)) ** 2, rel=1e-12)
