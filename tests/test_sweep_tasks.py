"""The sweep tasks built on clearjoint.periodic and clearjoint.harmonic, by independent routes.

- ``frequency_response`` on a joint without clearance is the forced linear oscillator:
  its peak is F0 / (2 zeta k sqrt(1 - zeta^2)) at w_n sqrt(1 - 2 zeta^2) (textbook).
- ``nonlinear_mode`` of a lossless joint: its frequency at the orbit's x_max is the exact
  free frequency 1 / T(A) of MODEL.md section 1, A = x_max - g_c (eq 4: T = 2 pi / w1 +
  2 c / (A w1) for k0 = 0, symmetric), written out here, within the harmonic truncation.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from clearjoint.sweep import SERIAL, Sweep, run_sweep
from helpers import LINEAR_STUDY

LOSSLESS_GAP = """
[joint]
mass = "2kg"
clearance = "0.1mm"
compression_stiffness = "8e7N/m"
[excitation]
force_amplitude = "500N"
frequency = "400Hz"
"""


def _sweep(tmp_path: Path, study: str, sweep: str) -> Path:
    (tmp_path / "study.toml").write_text(study, encoding="utf-8")
    path = tmp_path / "sweep.toml"
    path.write_text(sweep, encoding="utf-8")
    return path


def test_frequency_response_peak_is_the_linear_resonance(tmp_path: Path) -> None:
    path = _sweep(
        tmp_path,
        LINEAR_STUDY,
        """
base = "study.toml"
[task]
name = "frequency_response"
frequency_start = "600Hz"
frequency_stop = "1400Hz"
outputs = ["peak_amplitude_m", "peak_frequency_hz", "folds", "unstable_points"]
[axes.excitation]
force_amplitude = ["100N", "300N"]
""",
    )
    results = run_sweep(Sweep.from_toml(path), client=SERIAL)
    assert (results.status == "ok").all(), results.status.values
    m, k, zeta = 2.0, 8e7, 0.05
    f0 = results["excitation.force_amplitude"].values
    peak = f0 / (2 * zeta * k * math.sqrt(1 - zeta**2))
    hz = math.sqrt(k / m) * math.sqrt(1 - 2 * zeta**2) / (2 * math.pi)
    # the curve is sampled: its largest point sits within the step of the true peak
    np.testing.assert_allclose(results.peak_amplitude_m, peak, rtol=1e-3)
    np.testing.assert_allclose(results.peak_frequency_hz, hz, rtol=1e-2)
    assert (results.folds == 0).all()
    assert (results.unstable_points == 0).all()


def test_nonlinear_mode_frequency_is_the_exact_free_frequency(tmp_path: Path) -> None:
    path = _sweep(
        tmp_path,
        LOSSLESS_GAP,
        """
base = "study.toml"
[task]
name = "nonlinear_mode"
harmonics = 31
outputs = ["frequency_hz", "damping_ratio", "x_max_m"]
[axes.task]
amplitude = ["80um", "200um"]
""",
    )
    results = run_sweep(Sweep.from_toml(path), client=SERIAL)
    assert (results.status == "ok").all(), results.status.values
    m, k, c = 2.0, 8e7, 0.1e-3
    w1 = math.sqrt(k / m)
    a = results.x_max_m.values - c / 2  # penetration beyond the centred gap's edge
    assert (a > 0).all()
    exact_hz = 1.0 / (2 * math.pi / w1 + 2 * c / (a * w1))
    np.testing.assert_allclose(results.frequency_hz, exact_hz, rtol=1e-4)
    np.testing.assert_allclose(results.damping_ratio, 0.0, atol=1e-9)  # no losses


# ---- structure_mode: a structure study's nonlinear mode, its joints drawn one by one ---------

ONE_JOINT_CHAIN = """
[structure]
kind = "chain"
masses = ["2kg"]
stiffnesses = ["inf"]        # a rigid link: the chain is exactly the joint
joints = [true]
{extra}
[joint]
clearance = "0.1mm"
compression_stiffness = "8e7N/m"
"""


def test_structure_mode_of_a_one_joint_chain_is_the_exact_free_frequency(tmp_path: Path) -> None:
    # a rigid link in series with the joint is the lossless joint: eq 4 as above
    path = _sweep(
        tmp_path,
        ONE_JOINT_CHAIN.format(extra=""),
        """
base = "study.toml"
[task]
name = "structure_mode"
harmonics = 31
[axes.task]
amplitude = ["80um", "200um"]
""",
    )
    results = run_sweep(Sweep.from_toml(path), client=SERIAL)
    assert (results.status == "ok").all(), results.status.values
    m, k, c = 2.0, 8e7, 0.1e-3
    w1 = math.sqrt(k / m)
    a = results.x_max_m.values - c / 2
    assert (a > 0).all()
    exact_hz = 1.0 / (2 * math.pi / w1 + 2 * c / (a * w1))
    np.testing.assert_allclose(results.frequency_hz, exact_hz, rtol=1e-4)
    np.testing.assert_allclose(results.damping_ratio, 0.0, atol=1e-9)
    np.testing.assert_allclose(results.closed_frequency_hz, w1 / (2 * math.pi), rtol=1e-12)


def test_structure_mode_without_clearance_is_the_damped_linear_oscillator(tmp_path: Path) -> None:
    # c = 0 and a dashpot across the link: w = sqrt(k/m), zeta = d / (2 sqrt(k m)) (textbook;
    # EPMC's negative damping cancels the dashpot exactly, xi = d/m)
    path = _sweep(
        tmp_path,
        ONE_JOINT_CHAIN.format(extra='dampers = ["400N*s/m"]').replace("0.1mm", "0mm"),
        """
base = "study.toml"
[task]
name = "structure_mode"
harmonics = 3
[axes.task]
amplitude = ["50um"]
""",
    )
    results = run_sweep(Sweep.from_toml(path), client=SERIAL)
    assert (results.status == "ok").all(), results.status.values
    m, k, d = 2.0, 8e7, 400.0
    np.testing.assert_allclose(results.frequency_hz, math.sqrt(k / m) / (2 * math.pi), rtol=1e-9)
    np.testing.assert_allclose(results.damping_ratio, d / (2 * math.sqrt(k * m)), rtol=1e-9)


THREE_JOINT_CHAIN = """
[structure]
kind = "chain"
masses = ["2kg", "1kg", "0.5kg"]
stiffnesses = ["3e7N/m", "2e7N/m", "1e7N/m"]
dampers = ["100N*s/m", "50N*s/m", "20N*s/m"]
joints = [true, true, true]
[joint]
clearance = "0.1mm"
compression_stiffness = "5e7N/m"
gap_stiffness = "1e5N/m"
"""


def test_per_joint_draws_reach_each_joint_of_a_structure(tmp_path: Path) -> None:
    from clearjoint import ClearanceJoint
    from clearjoint.harmonic import nonlinear_modes
    from clearjoint.structure import chain

    path = _sweep(
        tmp_path,
        THREE_JOINT_CHAIN,
        """
base = "study.toml"
seed = 7
samples = 3
chunk_size = 2
[task]
name = "structure_mode"
harmonics = 3
amplitude = "2mm"
[draws.joint.clearance]
distribution = "uniform"
low = "0.05mm"
high = "0.15mm"
per_joint = true
""",
    )
    results = run_sweep(Sweep.from_toml(path), client=SERIAL)
    drawn = results["joint.clearance"].values
    assert drawn.shape == (3, 3)
    # the draws as documented: default_rng(SeedSequence(seed)), samples x joints at once
    rng = np.random.default_rng(np.random.SeedSequence(7))
    np.testing.assert_array_equal(drawn, rng.uniform(0.05e-3, 0.15e-3, 9).reshape(3, 3))
    for s in range(3):  # each sample's three clearances, joint by joint, built by hand
        joints = [ClearanceJoint(c, 5e7, gap_stiffness=1e5) for c in drawn[s]]
        by_hand = chain([2.0, 1.0, 0.5], [3e7, 2e7, 1e7], joints, [100.0, 50.0, 20.0])
        mode = nonlinear_modes(by_hand, 1, [2e-3], harmonics=3)
        if not mode.converged[0]:  # harmonic balance found no mode: the point says so
            assert str(results.status.values[s]).startswith("SimulationError: the nonlinear")
            assert np.isnan(results.frequency_hz.values[s])
            continue
        assert results.status.values[s] == "ok"
        assert results.frequency_hz.values[s] == mode.frequency[0] / (2 * math.pi)
        assert results.damping_ratio.values[s] == mode.damping_ratio[0]
    # and the clearances matter: the samples that converged differ
    found = results.frequency_hz.values[results.status.values == "ok"]
    assert found.size >= 2
    assert np.unique(found).size == found.size


def test_structure_mode_reuses_a_ladder_only_when_the_numbers_are_the_same(tmp_path: Path) -> None:
    # the 4 mm point is the top of the 2 mm point's ladder: served from it, it must be
    # bit for bit what a fresh call gives (each point below solved with nothing kept)
    from clearjoint.sweep import TASKS
    from clearjoint.sweep import tasks as tasks_module

    path = _sweep(
        tmp_path,
        THREE_JOINT_CHAIN,
        """
base = "study.toml"
seed = 3
samples = 2
chunk_size = 4
[task]
name = "structure_mode"
harmonics = 3
start_amplitude = "4mm"
ladder_steps = 1
[axes.task]
amplitude = ["2mm", "4mm"]
[draws.joint.clearance]
distribution = "uniform"
low = "0.05mm"
high = "0.15mm"
per_joint = true
""",
    )
    from clearjoint.simulate import SimulationError

    sweep = Sweep.from_toml(path)
    results = run_sweep(sweep, client=SERIAL)
    assert np.count_nonzero(results.status.values == "ok") >= 3, results.status.values
    task = TASKS["structure_mode"]
    for s in range(2):
        for i, amplitude in enumerate((2e-3, 4e-3)):
            values = dict(sweep.fixed) | {"task.amplitude": amplitude}
            values |= {
                f"joint.clearance[{j}]": c
                for j, c in enumerate(results["joint.clearance"].values[s])
            }
            tasks_module._LAST_LADDER.keep(None, (), None)  # nothing kept: a fresh solve
            try:
                fresh = task.evaluate(sweep.base, values, np.random.SeedSequence(0))
            except SimulationError:
                assert np.isnan(results.frequency_hz.values[s, i])
                continue
            assert results.frequency_hz.values[s, i] == fresh["frequency_hz"]
            assert results.damping_ratio.values[s, i] == fresh["damping_ratio"]


def test_the_committed_mast_tolerance_results_come_from_the_shipped_sweep_file() -> None:
    # examples/mast_tolerance_sweep.nc (drawn by the gallery) is this sweep file's output:
    # the same hash and draws, and a sample's values are those of a direct call on a mast
    # built by hand with that sample's 20 clearances (clearjoint.structure.mast)
    import xarray as xr

    from clearjoint import ClearanceJoint
    from clearjoint.harmonic import nonlinear_modes
    from clearjoint.structure import mast

    examples = Path(__file__).resolve().parents[1] / "examples"
    sweep = Sweep.from_toml(examples / "mast_tolerance_sweep.toml")
    results = xr.load_dataset(examples / "mast_tolerance_sweep.nc", engine="h5netcdf")
    assert results.attrs["clearjoint_sweep_fingerprint"] == sweep.fingerprint
    drawn = sweep.drawn()["joint.clearance"]
    done = results.status.values[:, 0] != ""
    assert done.all()  # all 1000 samples were computed
    np.testing.assert_array_equal(results["joint.clearance"].values[done], drawn[done])
    s = int(np.flatnonzero(done)[-1])
    joints = [ClearanceJoint(c, 5e7, gap_stiffness=1e5) for c in drawn[s]]
    by_hand = mast(10, joints=joints, rayleigh=(0.0, 2e-6))
    mode = nonlinear_modes(by_hand, 1, [0.01, 0.03], harmonics=3)
    np.testing.assert_allclose(
        results.frequency_hz.values[s], mode.frequency / (2 * math.pi), rtol=1e-9
    )
    # committed when damping_ratio was EPMC's xi / (2 w), now epmc_damping_ratio (a rerun
    # of the sweep, about 50 min, writes the energy ratio E_diss / (4 pi E_max) instead)
    np.testing.assert_allclose(results.damping_ratio.values[s], mode.epmc_damping_ratio, rtol=1e-7)


def test_periodic_orbit_of_a_joint_without_clearance_is_the_linear_oscillators(
    tmp_path: Path,
) -> None:
    """Amplitude F / |k - m w^2 + i c w|, multipliers of modulus exp(-zeta w_n T), input
    pi c w X^2 per period: the textbook forced linear oscillator, written out here."""
    path = _sweep(
        tmp_path,
        LINEAR_STUDY,
        """
base = "study.toml"
[task]
name = "periodic_orbit"
[axes.excitation]
frequency = ["300Hz", "1100Hz"]
""",
    )
    results = run_sweep(Sweep.from_toml(path), client=SERIAL)
    assert (results.status == "ok").all(), results.status.values
    m, k, zeta, force = 2.0, 8e7, 0.05, 100.0
    c = 2 * zeta * math.sqrt(k * m)
    w = 2 * math.pi * results["excitation.frequency"].values
    amplitude = force / np.hypot(k - m * w**2, c * w)
    np.testing.assert_allclose(results.amplitude_m, amplitude, rtol=1e-9)
    w_n = math.sqrt(k / m)
    np.testing.assert_allclose(
        results.largest_multiplier, np.exp(-zeta * w_n * 2 * np.pi / w), rtol=1e-6
    )
    np.testing.assert_allclose(results.energy_input_j, np.pi * c * w * amplitude**2, rtol=1e-9)
    assert (results.stable == 1.0).all()
