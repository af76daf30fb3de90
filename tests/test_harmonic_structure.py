"""Harmonic balance of a Structure (MODEL.md 5.2-5.4) against its exact time response."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from clearjoint import ClearanceJoint, Losses, ParameterError
from clearjoint.harmonic import HarmonicError, frequency_response, nonlinear_modes
from clearjoint.structure import Structure, chain, time_response

FORCE = np.array([0.0, 0.0, 40.0])
SAMPLES = 256


def _exact_from(structure: Structure, omega: float, state: np.ndarray, periods: int) -> np.ndarray:
    n = structure.n_dof
    motion = time_response(
        structure,
        FORCE,
        omega,
        periods * 2.0 * math.pi / omega,
        initial=(state[:n], state[n:]),
        samples_per_period=SAMPLES,
    )
    return motion.u


@pytest.mark.parametrize("omega", [200.0, 300.0, 400.0, 500.0, 800.0])
def test_stable_steady_states_agree_with_the_exact_time_response(
    three_links: Structure, omega: float
) -> None:
    """Started on the HB orbit, the exact motion stays on it: x_max per DOF agree.

    At each of these frequencies some joint goes beyond a gap edge (checked on the
    exact motion's relative displacements).
    """
    fr = frequency_response(three_links, FORCE, omega, 1.001 * omega, harmonics=7, max_points=2)
    assert fr.x_max.shape == (2, 3)
    assert fr.multipliers.shape == (2, 6)
    assert fr.stable[0]
    u = _exact_from(three_links, omega, fr.initial_state[0], 6)
    last = u[-SAMPLES:]
    scale = float(np.max(np.abs(last)))
    assert np.max(np.abs(fr.x_max[0] - last.max(axis=0))) < 3e-3 * scale
    assert np.max(np.abs(fr.x_min[0] - last.min(axis=0))) < 3e-3 * scale
    relative = last @ three_links.joint_directions.T
    assert np.max(relative) > 1.2 * three_links.joint_laws[0].compression_gap


def test_an_orbit_hill_calls_unstable_is_left_by_the_exact_motion(three_links: Structure) -> None:
    omega = 600.0
    fr = frequency_response(three_links, FORCE, omega, 1.001 * omega, harmonics=7, max_points=2)
    assert not fr.stable[0]
    ds = fr.to_xarray()
    assert ds["x_max"].dims == ("point", "dof")
    assert ds["coefficients"].dims == ("point", "coefficient", "dof")
    u = _exact_from(three_links, omega, fr.initial_state[0], 6)
    first = np.max(np.abs(u[:SAMPLES].max(axis=0) - fr.x_max[0]))
    last = np.max(np.abs(u[-SAMPLES:].max(axis=0) - fr.x_max[0]))
    assert last > 5.0 * first


def test_first_nonlinear_mode_lies_between_the_linear_bounds(three_links: Structure) -> None:
    """MODEL.md 5.2: the all-open and all-closed linear modes bound the nonlinear one."""
    nm = nonlinear_modes(three_links, 1, np.geomspace(2e-4, 2e-2, 6), harmonics=7)
    assert nm.converged.all()
    assert nm.x_max.shape == (6, 3)
    assert nm.reference_dof == three_links.dof_names[2]
    assert list(nm.to_xarray()["dof"].values) == list(three_links.dof_names)
    w_open = three_links.modes("open").omega[0]
    w_closed = three_links.modes("closed").omega[0]
    assert np.all(nm.frequency > w_open)
    assert np.all(nm.frequency < w_closed)
    assert np.all(np.diff(nm.frequency) > 0.0)  # the joints stiffen with amplitude
    assert nm.frequency[-1] == pytest.approx(w_closed, rel=0.02)
    assert np.all(nm.damping_ratio > 0.0)


def test_damping_ratio_tends_to_the_closed_linear_modal_ratio(three_links: Structure) -> None:
    """Far above the clearance the mode is the closed linear one, so both damping ratios
    (E_diss / (4 pi E_max) and EPMC's xi / (2 w)) tend to phi^T C phi / (2 w phi^T M phi),
    the gap falling like c / a (measured: 2.9e-2, 8.8e-3, 2.7e-3, 8.6e-4 for the energy
    ratio at a = 63, 200, 632, 2000 clearances)."""
    closed = three_links.modes("closed")
    phi, w = closed.shapes[:, 0], float(closed.omega[0])
    c, m = three_links.damping_matrix(), np.diag(three_links.mass_diagonal())
    modal = float(phi @ c @ phi / (2.0 * w * phi @ m @ phi))
    nm = nonlinear_modes(three_links, 1, 1e-4 * np.geomspace(63.25, 2000.0, 4), harmonics=7)
    assert nm.converged.all()
    gap = nm.damping_ratio / modal - 1.0
    assert np.all(gap > 0.0)
    assert gap[-1] < 1.5e-3
    assert np.all(gap[1:] < gap[:-1] / 2.5)  # about 1 / a: 3.16-fold per step
    np.testing.assert_allclose(nm.epmc_damping_ratio[-1], modal, rtol=1e-3)


def test_bad_structure_input(three_links: Structure) -> None:
    with pytest.raises(ParameterError, match=r"one amplitude per DOF, shape \(3,\)"):
        frequency_response(three_links, [1.0, 2.0], 100.0, 200.0)
    with pytest.raises(ParameterError, match="the structure has modes 1 to 3"):
        nonlinear_modes(three_links, 4, [1e-3])
    with pytest.raises(ParameterError, match="apply to a Joint"):
        frequency_response(three_links, FORCE, 100.0, 200.0, losses=Losses(damping_ratio=0.1))


def test_first_nonlinear_mode_is_the_free_decay_backbone() -> None:
    """EPMC (H = 15) against the exact free decay of a two-mass chain with two joints.

    The decay starts on the closed linear mode at 2 mm, 20 times the clearance; its
    per-cycle peaks, projected on closed mode 1 (structure.decay_backbone(..., mode=1),
    so the second mode the initial deflection also excites does not beat into them),
    give amplitude, frequency and damping ratio. They agree with the EPMC curve at the
    same peak amplitude (half peak-to-peak of the reference DOF) within 1e-3 in
    frequency (measured 2e-4 at the start to 6e-4 at the end, always above) and 20 % in
    EPMC's damping ratio xi / (2 w) (per cycle the decay's ratio scatters +-8 %).

    Which damping ratio a decay measures: along a slowly decaying backbone the energy
    E(a) falls by E_diss a cycle, so zeta_decay = -(1/w) d ln a / dt =
    E_diss / (2 pi s E_max) = damping_ratio * 2 / s, s = d ln E_max / d ln a (2 for a
    linear mode; 2.12 to 2.19 here, the joints stiffening). Measured, the mean over the
    cycles of zeta_decay over that prediction is 1.013 (over damping_ratio 0.943, over
    xi / (2 w) 0.978: for V ~ |x|^n, EPMC's ratio is (n + 2) / 4 times the decay's).
    They differ because the decay is no periodic orbit: its amplitude
    falls within each cycle (about 1 % per cycle here) while the backbone steepens, and
    its peaks measure a cycle of a shrinking motion; EPMC makes the motion periodic with
    an artificial mass-proportional negative damping -xi M u', which slightly changes
    the mode's shape, and truncates to H harmonics.
    """
    from clearjoint.structure import decay_backbone, free_decay

    j = ClearanceJoint(clearance=1e-4, compression_stiffness=1e7, gap_stiffness=1e5)
    s = chain([1.0, 1.0], [1e6, 1e6], [j, j], dampers=[5.0, 5.0])
    phi = s.modes("closed").shapes[:, 0]
    ref = int(np.argmax(np.abs(phi)))
    motion = free_decay(s, (2e-3 * phi / phi[ref], np.zeros(2)), 0.45, samples_per_period=256)
    backbone = decay_backbone(motion, ref, mode=1)
    a, w, zeta = backbone.amplitude, backbone.omega, backbone.damping_ratio
    assert a.size >= 35
    assert a[-1] < 0.7 * a[0]  # a real stretch of the backbone, 2 to 1.2 mm
    nm = nonlinear_modes(s, 1, np.geomspace(0.8 * a[-1], 1.2 * a[0], 30), harmonics=15)
    assert nm.converged.all()
    assert nm.reference_dof == s.dof_names[ref]
    peak = 0.5 * (nm.x_max[:, ref] - nm.x_min[:, ref])
    assert np.all(np.diff(peak) > 0.0)
    w_epmc = np.interp(a, peak, nm.frequency)
    np.testing.assert_array_less(np.abs(w / w_epmc - 1.0), 1e-3)
    z_epmc = np.interp(a, peak, nm.epmc_damping_ratio)
    ok = np.isfinite(zeta)
    np.testing.assert_allclose(zeta[ok], z_epmc[ok], rtol=0.2)
    # the energy balance of the decay: zeta_decay = damping_ratio * 2 / s
    e_max = nm.energy_per_cycle / (4.0 * math.pi * nm.damping_ratio)
    s_slope = np.gradient(np.log(e_max), np.log(peak))
    predicted = np.interp(a, peak, nm.damping_ratio * 2.0 / s_slope)
    assert np.all((s_slope > 2.05) & (s_slope < 2.3))
    assert np.mean(zeta[ok] / predicted[ok]) == pytest.approx(1.0, abs=0.03)
    np.testing.assert_allclose(zeta[ok], predicted[ok], rtol=0.15)
    # the backbone is nonlinear here: 1 % of frequency over the stretch compared
    assert w[0] / w[-1] > 1.01


def test_sparse_and_dense_newton_give_the_same_mode(
    three_links: Structure, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Newton's sparse LU (used above solve.SPARSE_ABOVE unknowns) and the dense one agree."""
    from clearjoint.harmonic import solve

    amplitudes = np.geomspace(2e-4, 2e-2, 5)
    dense = nonlinear_modes(three_links, 1, amplitudes, harmonics=7)
    monkeypatch.setattr(solve, "SPARSE_ABOVE", 0)
    sparse = nonlinear_modes(three_links, 1, amplitudes, harmonics=7)
    assert dense.converged.all()
    assert sparse.converged.all()
    np.testing.assert_allclose(sparse.frequency, dense.frequency, rtol=1e-9)
    np.testing.assert_allclose(sparse.damping_ratio, dense.damping_ratio, rtol=1e-7)
    np.testing.assert_allclose(sparse.x_max, dense.x_max, rtol=1e-8, atol=1e-14)


def test_sparse_and_dense_continuation_give_the_same_curve(
    three_links: Structure, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The sparse arclength corrector (solve.SparseResidual, above SPARSE_ABOVE unknowns)
    follows the same curve as the continuation's own dense one, through the resonance."""
    from clearjoint.harmonic import solve

    dense = frequency_response(three_links, FORCE, 300.0, 700.0, harmonics=5, max_points=25)
    monkeypatch.setattr(solve, "SPARSE_ABOVE", 0)
    calls = []
    original = solve.SparseResidual.corrector

    def counted(self: solve.SparseResidual, *args: object) -> object:
        calls.append(1)
        return original(self, *args)  # type: ignore[arg-type]

    monkeypatch.setattr(solve.SparseResidual, "corrector", counted)
    sparse = frequency_response(three_links, FORCE, 300.0, 700.0, harmonics=5, max_points=25)
    assert len(calls) >= 24  # every point corrected by the sparse corrector
    assert dense.omega.size == sparse.omega.size == 25
    np.testing.assert_allclose(sparse.omega, dense.omega, rtol=1e-9)
    np.testing.assert_allclose(sparse.coefficients, dense.coefficients, rtol=1e-7, atol=1e-12)
    assert np.array_equal(sparse.stable, dense.stable)


def test_first_nonlinear_mode_of_a_small_mast_is_its_free_decay_backbone() -> None:
    """EPMC (H = 7) against the exact free decay of a 2-bay mast with 4 joints.

    The example mast's members and joints (examples/mast.toml: 50 um clearance,
    k_c = 5e7 N/m, k0 = 1e5 N/m) on 2 bays, with Rayleigh beta 2e-5 s so that the
    decay covers a stretch of the backbone in ten cycles: released on the closed first
    mode at 1.9 mm on the tip (37 clearances), it falls to 0.71 mm while its frequency
    falls from 206.6 to 193.6 Hz (closed mode 214.1 Hz, open 17.8 Hz). Per cycle,
    projected on closed mode 1, the decay is measured 1.0e-3 to 4.2e-3 below the EPMC
    frequency at the same peak amplitude, and its damping ratio 1 % to 8 % above EPMC's.
    Why they differ: the decay's amplitude falls 9 to 12 % within each cycle, and a
    cycle between two maxima is read at the mean of its peaks while the hardening
    backbone (slope d ln w / d ln a = 0.07 here) makes the later, smaller half slower:
    half of 12 % times 0.07 is 4e-3, the size of the gap; it grows as the decay speeds
    up. EPMC's damping is an artificial -xi M u' that keeps the motion periodic, and the
    decay's logarithmic decrement spans a cycle of a shrinking, changing motion. Hence
    the bounds: 5e-3 in frequency (decay below), 12 % in damping ratio.
    """
    from clearjoint.structure import decay_backbone, free_decay, mast

    j = ClearanceJoint(clearance=5e-5, compression_stiffness=5e7, gap_stiffness=1e5)
    s = mast(2, joints=j, rayleigh=(0.0, 2e-5))
    closed = s.modes("closed")
    phi = closed.shapes[:, 0]
    ref = int(np.argmax(np.abs(phi)))
    period = 2.0 * math.pi / float(closed.omega[0])
    motion = free_decay(s, (2e-3 * phi / phi[ref], np.zeros(s.n_dof)), 12 * period)
    backbone = decay_backbone(motion, ref, mode=1)
    a, w, zeta = backbone.amplitude[:9], backbone.omega[:9], backbone.damping_ratio[:9]
    assert a[-1] < 0.5 * a[0]
    assert w[0] / w[-1] > 1.05  # a nonlinear stretch of the backbone
    nm = nonlinear_modes(s, 1, np.geomspace(0.8 * a[-1], 1.2 * a[0], 20), harmonics=7)
    assert nm.converged.all()
    peak = 0.5 * (nm.x_max[:, ref] - nm.x_min[:, ref])
    assert np.all(np.diff(peak) > 0.0)
    gap = w / np.interp(a, peak, nm.frequency) - 1.0
    assert np.all(gap < 0.0)
    assert np.all(gap > -5e-3)
    # EPMC's xi / (2 w), as measured above; the energy ratio damping_ratio is within 2.5 %
    # of the decay here (0.975-0.993), but by two biases cancelling: the decay's energy
    # balance predicts damping_ratio * 2 / s (s = 2.10-2.27), which the decay exceeds by
    # 3 % to 12 % as its decay speeds up (docs/harmonic.md)
    np.testing.assert_allclose(zeta, np.interp(a, peak, nm.epmc_damping_ratio), rtol=0.12)


def test_friction_in_a_structure_joint_is_carried_and_a_sticking_orbit_flagged() -> None:
    """Friction in rigid members' joints is carried by HB (tests/test_harmonic_friction.py
    checks it; nonlinear modes, tests/test_harmonic_modes.py); the exact structure motion
    still refuses it, and an orbit whose joints stick (20 N of friction against 40 N of
    forcing) is flagged untrusted."""
    from clearjoint import Friction
    from clearjoint.structure import StructureError

    rub = Friction(coefficient=0.2, lateral_load=100.0)
    j = ClearanceJoint(clearance=1e-4, compression_stiffness=1e7, gap_stiffness=1e5, friction=rub)
    s = chain([1.0, 1.0], [math.inf, math.inf], [j, j], dampers=[5.0, 5.0])  # friction: rigid
    fr = frequency_response(s, np.array([0.0, 40.0]), 300.0, 310.0, max_points=2)
    assert fr.omega.size == 2
    sticking = [e for e in fr.events if e.kind == "untrusted"]
    assert len(sticking) == 2
    assert "it sticks" in sticking[0].note
    with pytest.raises(StructureError, match="friction"):
        time_response(s, np.array([0.0, 40.0]), 300.0, 0.01)


def test_energy_per_cycle_of_a_small_mast_is_what_its_free_decay_loses() -> None:
    """No amplitude reading and no projection: the exact free decay's mechanical energy
    (structure.motion's own ledger: 0.5 v^T M v + 0.5 u^T K u + each joint law's V) lost
    over each cycle, against EPMC's energy_per_cycle at the same total energy. The 2-bay
    mast of the test above, released on the H = 15 EPMC orbit's state at 2.3 mm (so that
    no other mode rings): measured 0.998 to 1.009 at H = 15 and 1.014 to 1.070 at H = 7,
    the gap being H truncation (Rayleigh beta K damps each harmonic in proportion to its
    frequency squared, so the harmonics H = 7 drops carry dissipation); on 10 bays see
    docs/harmonic.md (python docs/harmonic_mast_decay.py)."""
    from clearjoint.harmonic import aft
    from clearjoint.structure import decay_backbone, free_decay, mast
    from clearjoint.structure.motion import _Flow

    j = ClearanceJoint(clearance=5e-5, compression_stiffness=5e7, gap_stiffness=1e5)
    s = mast(2, joints=j, rayleigh=(0.0, 2e-5))
    flow = _Flow(s, np.zeros(s.n_dof), 0.0)
    closed = s.modes("closed")
    ref = int(np.argmax(np.abs(closed.shapes[:, 0])))
    period = 2.0 * math.pi / float(closed.omega[0])
    tau = 2.0 * math.pi * np.arange(64) / 64
    modes = {}
    for h in (15, 7):
        nm = nonlinear_modes(s, 1, np.geomspace(0.5e-3, 2.5e-3, 30), harmonics=h)
        ok = nm.converged  # H = 15 misses 8 of the 30 (1.2 to 1.8 mm): left out
        assert ok.sum() >= 20
        basis = aft.Basis.make(h, 2 * (2 * h + 1))
        states = [
            (basis.evaluate(coef, tau), w * basis.evaluate(basis.derivative @ coef, tau))
            for coef, w in zip(nm.harmonic_shapes[ok], nm.frequency[ok], strict=True)
        ]
        total = [
            np.mean([flow.mechanical_energy(a, b) for a, b in zip(u, v, strict=True)])
            for u, v in states
        ]
        assert np.all(np.diff(total) > 0.0)
        modes[h] = (np.array(total), nm.energy_per_cycle[ok], states[-2])
    u, v = modes[15][2]
    motion = free_decay(s, (u[0], v[0]), 10 * period)
    energy = np.array(
        [flow.mechanical_energy(a, b) for a, b in zip(motion.u, motion.v, strict=True)]
    )
    bb = decay_backbone(motion, ref, mode=1)
    half = math.pi / bb.omega
    lost = np.interp(bb.time - half, motion.t, energy) - np.interp(bb.time + half, motion.t, energy)
    middle = np.interp(bb.time, motion.t, energy)
    ratios = {}
    for h, (total, per_cycle, _) in modes.items():
        inside = (middle > total[0]) & (middle < total[-1])
        assert inside.sum() >= 6
        ratios[h] = (lost / np.interp(middle, total, per_cycle))[inside]
    assert np.all(np.abs(ratios[15] - 1.0) < 0.015)
    assert np.mean(ratios[7]) > np.mean(ratios[15]) + 0.015  # H = 7 misses a few % of the loss


def test_first_nonlinear_mode_of_the_example_mast_is_its_free_decay_backbone() -> None:
    """The shipped examples/mast.toml as it is (10 bays, 20 joints, Rayleigh beta 2e-6 s):
    released on its closed first mode at 50 mm on the tip (n21x, the file's decay DOF; about
    18 times the 2.75 mm its free play alone allows), 8 cycles of exact free decay read per
    cycle on closed mode 1, against EPMC at H = 7 at the same amplitude: the decay's
    frequency is measured 3.1e-4 to 3.7e-4 above EPMC's (15.97 Hz; closed linear mode 16.46
    Hz). Why they differ at all: the decay starts on the linear mode shape, not the
    nonlinear one, so other modes ring in it and beat into the projected peaks, and EPMC
    truncates to H harmonics (docs/harmonic.md, "The nonlinear mode against the free-decay
    backbone"). Bound: 1e-3. Damping is not compared here: with beta 2e-6 the per-cycle
    decrement scatters 0.8 to 7 times EPMC's from that ringing; the energy route on a
    2-bay mast above and docs/harmonic_mast_decay.py on 10 bays compare it."""
    from clearjoint.structure import decay_backbone, free_decay
    from clearjoint.structure.study import load_structure_study

    root = Path(__file__).resolve().parents[1]
    study = load_structure_study(root / "examples" / "mast.toml")
    s = study.structure
    ref = list(s.dof_names).index("n21x")
    closed = s.modes("closed")
    phi = closed.shapes[:, 0]
    period = 2.0 * math.pi / float(closed.omega[0])
    motion = free_decay(s, (50e-3 * phi / phi[ref], np.zeros(s.n_dof)), 8 * period)
    bb = decay_backbone(motion, ref, mode=1)
    a, w = bb.amplitude, bb.omega
    assert a.size >= 5
    assert np.all(w < 0.99 * closed.omega[0])  # the joints open within each cycle
    nm = nonlinear_modes(s, 1, np.geomspace(0.95 * a.min(), 1.05 * a.max(), 6), harmonics=7)
    assert nm.converged.all()
    peak = 0.5 * (nm.x_max[:, ref] - nm.x_min[:, ref])
    assert np.all(np.diff(peak) > 0.0)
    gap = w / np.interp(a, peak, nm.frequency) - 1.0
    assert np.all(np.abs(gap) < 1e-3)


def test_a_structure_curve_names_its_dofs_in_the_plot(three_links: Structure) -> None:
    """The legend of a Structure's curve carries the DOF names, not "DOF k"."""
    import matplotlib

    matplotlib.use("Agg")
    fr = frequency_response(three_links, FORCE, 400.0, 410.0, max_points=3, check_points=0)
    assert fr.settings["dof_names"] == list(three_links.dof_names)
    labels = fr.plot().get_legend_handles_labels()[1]
    assert any(name in label for label in labels for name in three_links.dof_names)
    assert not any(label.startswith("DOF ") for label in labels)


def test_a_size_beyond_the_memory_bound_is_one_clear_error() -> None:
    """frequency_response refuses, as nonlinear_modes does, an H whose AFT basis would not
    fit (H = 3000 on one DOF: 262144 samples x 6001 coefficients, 11.7 GiB)."""
    from clearjoint import Joint

    joint = Joint(mass=1.0, clearance=1e-4, compression_stiffness=1e6)
    with pytest.raises(HarmonicError, match=r"harmonics 3000 .* needs an array of 11\.7 GiB"):
        frequency_response(joint, 1.0, 100.0, 200.0, harmonics=3000)
