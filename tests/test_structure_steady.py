"""Exact steady response of structures: orbits, curves and stepped sine (MODEL.md 5.1, 5.2).

Checked by independent routes: the one-joint solver (clearjoint.periodic) on a one-link
chain, a solve_ivp integration of our own restarted at every gap-edge event, a finite-
difference monodromy of the exact map, the closed-form linear FRF and the closed-form
decay rate of a linear damped chain.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import clearjoint as cj
from clearjoint import periodic
from clearjoint.structure import (
    SteppedSineError,
    StructureError,
    chain,
    frequency_response,
    periodic_orbit,
    stepped_sine,
)
from clearjoint.structure.orbit import ShootingMap

LAW = cj.ClearanceJoint(0.2e-3, 4e5, gap_stiffness=2e4)


def _chain(n: int = 5):
    return chain([0.5] * n, [math.inf] * n, [LAW] * n, [2.0] * n)


def _force(n: int, value: float = 30.0) -> np.ndarray:
    f = np.zeros(n)
    f[-1] = value
    return f


def _reference_map(n: int, force: np.ndarray, omega: float, z0: np.ndarray) -> np.ndarray:
    """P(z0) over one period by solve_ivp (DOP853, rtol 1e-12), restarted at each gap edge.

    Written from MODEL.md 5.2 alone: a chain of masses m linked by the clearance law
    (k0 inside +-g, k0 u + k_c (u -+ g) beyond) and dashpots c, ground at the left.
    """
    m, c, k0, kc, g = 0.5, 2.0, 2e4, 4e5, 1e-4

    def link_force(d: float) -> float:
        if d > g:
            return k0 * d + kc * (d - g)
        if d < -g:
            return k0 * d + kc * (d + g)
        return k0 * d

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        u, v = y[:n], y[n:]
        du = np.diff(np.concatenate(([0.0], u)))
        dv = np.diff(np.concatenate(([0.0], v)))
        link = np.array([link_force(d) for d in du]) + c * dv
        a = -link.copy()
        a[:-1] += link[1:]
        return np.concatenate((v, (a + force * math.sin(omega * t)) / m))

    def edge(j: int, level: float):
        def hit(t: float, y: np.ndarray) -> float:
            u = y[:n]
            return (u[j] - (u[j - 1] if j else 0.0)) - level

        return hit

    events = [edge(j, s * g) for j in range(n) for s in (1.0, -1.0)]
    for hit in events:
        hit.terminal = True  # type: ignore[attr-defined]
    t, y, end = 0.0, z0.copy(), 2.0 * math.pi / omega
    while t < end:
        sol = solve_ivp(rhs, (t, end), y, method="DOP853", rtol=1e-12, atol=1e-15, events=events)
        t, y = float(sol.t[-1]), sol.y[:, -1]
        if sol.status == 1 and t < end:
            # leave the edge without looking for events, then look again
            step = solve_ivp(rhs, (t, min(t + 1e-10, end)), y, method="DOP853", rtol=1e-12)
            t, y = float(step.t[-1]), step.y[:, -1]
    return y


def test_one_link_chain_orbit_is_the_one_joint_orbit():
    s = _chain(1)
    j, losses = s.to_system().to_joint()
    w = 2 * math.pi * 40.0
    reference = periodic.periodic_orbit(j, 30.0, w, losses=losses)
    x0, v0 = np.asarray(reference.initial_state)
    orbit = periodic_orbit(s, [30.0], w, initial=([x0 * 1.01], [v0]))
    assert orbit.x_max[0] == pytest.approx(reference.x_max, abs=1e-8 * reference.amplitude)
    assert orbit.x_min[0] == pytest.approx(reference.x_min, abs=1e-8 * reference.amplitude)
    mine = np.sort_complex(orbit.multipliers)
    theirs = np.sort_complex(np.asarray(reference.multipliers))
    assert np.max(np.abs(mine - theirs)) < 1e-6
    assert orbit.stable == reference.stable
    assert orbit.closure < 1e-10


def _three_masses_in_contact():
    """A 3-mass chain at 2 N and 15 Hz: a stable orbit with many gap-edge events."""
    s = _chain(3)
    f = _force(3, 2.0)
    w = 2 * math.pi * 15.0
    return s, f, w, periodic_orbit(s, f, w)


def test_map_and_orbit_against_solve_ivp_restarted_at_events():
    n = 3
    s, f, w, orbit = _three_masses_in_contact()
    assert orbit.events > 10  # in contact, many times a period
    z = np.concatenate(orbit.initial_state)
    ref = _reference_map(n, f, w, z)
    scale = np.concatenate((np.full(n, w), np.ones(n)))
    assert np.max(np.abs((ref - z) * scale)) < 1e-7 * np.max(np.abs(z * scale))
    # the map off the orbit (a Poincaré map step) agrees too
    z1 = z + 0.05 * np.concatenate((orbit.amplitude, np.zeros(n)))
    mine = ShootingMap(s.to_system(), f, w)(z1)[0]
    ref1 = _reference_map(n, f, w, z1)
    assert np.max(np.abs((ref1 - mine) * scale)) < 1e-7 * np.max(np.abs(z1 * scale))


def test_monodromy_is_the_finite_difference_jacobian_of_the_exact_map():
    n = 3
    s, f, w, orbit = _three_masses_in_contact()
    shoot = ShootingMap(s.to_system(), f, w)
    z = np.concatenate(orbit.initial_state)
    fd = np.empty((2 * n, 2 * n))
    for k in range(2 * n):
        h = 1e-6 * (np.max(np.abs(z[:n])) if k < n else np.max(np.abs(z[n:])))
        dz = np.zeros(2 * n)
        dz[k] = h
        fd[:, k] = (shoot(z + dz)[0] - shoot(z - dz)[0]) / (2 * h)
    scale = np.concatenate((np.full(n, w), np.ones(n)))
    rel = np.abs((fd - orbit.monodromy) * scale[:, None] / scale[None, :])
    assert np.max(rel) < 1e-5 * np.max(np.abs(orbit.monodromy * scale[:, None] / scale[None, :]))
    mu_fd = np.sort(np.abs(np.linalg.eigvals(fd)))
    assert np.max(np.abs(mu_fd - np.sort(np.abs(orbit.multipliers)))) < 1e-5


def test_shooting_curve_points_are_one_joint_orbits():
    s = _chain(1)
    j, losses = s.to_system().to_joint()
    curve = frequency_response(s, [30.0], 2 * math.pi * 30, 2 * math.pi * 34, max_points=60)
    assert curve.method == "shooting"
    assert curve.x_max.shape == (curve.omega.size, 1)
    for i in range(0, curve.omega.size, max(1, curve.omega.size // 4)):
        ref = periodic.periodic_orbit(
            j, 30.0, float(curve.omega[i]), losses=losses, initial=curve.initial_state[i]
        )
        # the curve samples 64 points a period (its extremes to ~1e-4 of X; the orbit 1e-9)
        assert curve.x_max[i, 0] == pytest.approx(ref.x_max, abs=1e-4 * ref.amplitude)
        assert bool(curve.stable[i]) == bool(ref.stable)


def test_linear_limit_is_the_closed_form_frf_and_decays_at_the_least_damped_rate():
    n = 5
    s = _chain(n)
    system = s.to_system()
    f = _force(n, 3e-3)  # 1.5e-7 m against gaps of 1e-4 m: every joint stays open
    hz = np.array([2.0, 10.0, 20.0])
    diagram = stepped_sine(s, f, 2 * np.pi * hz, settle_periods=50, record_periods=100)
    k, m, c = system.open_stiffness(), system.mass, system.damping
    for i, w in enumerate(2 * np.pi * hz):
        x = np.abs(np.linalg.solve(k - w * w * m + 1j * w * c, f))
        assert diagram.kind[0, i] == "periodic"
        assert np.max(np.abs(diagram.amplitude[0, i] - x)) < 1e-6 * np.max(x)
    # linear, damped: the largest exponent is the largest real part of the eigenvalues
    a = np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(m, k), -np.linalg.solve(m, c)]])
    rate = float(np.max(np.linalg.eigvals(a).real))
    assert rate < 0
    for i in range(hz.size):
        assert diagram.lyapunov[0, i] == pytest.approx(
            rate, rel=0.02, abs=3 * diagram.lyapunov_error[0, i]
        )


def test_positive_exponent_where_nearby_motions_separate_exponentially():
    n = 5
    s = _chain(n)
    f = _force(n)
    w = 2 * math.pi * 20.0
    diagram = stepped_sine(s, f, [w], settle_periods=100, record_periods=100)
    lam = float(diagram.lyapunov[0, 0])
    assert diagram.kind[0, 0] == "chaotic"
    assert lam > 0
    # our own estimate: two exact runs 1e-9 apart, the growth of their distance
    system = s.to_system()
    start = np.concatenate((diagram.poincare[0, 0, -1, :n], diagram.poincare[0, 0, -1, n:]))
    shoot = ShootingMap(system, f, w)
    a, b = start.copy(), start + 1e-9 * np.max(np.abs(start)) * np.linspace(1, -1, 2 * n)
    scale = np.concatenate((np.full(n, w), np.ones(n)))
    d0 = np.linalg.norm((a - b) * scale)
    logs = []
    for _ in range(12):
        a, b = shoot(a)[0], shoot(b)[0]
        logs.append(math.log(np.linalg.norm((a - b) * scale) / d0))
    slope = np.polyfit(np.arange(1, 13) * shoot.period, logs, 1)[0]
    assert slope > 0
    assert slope == pytest.approx(lam, rel=0.6)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"omegas": [10.0, -1.0]}, "finite and > 0"),
        ({"omegas": [20.0, 10.0]}, "strictly increasing"),
        ({"settle_periods": 0}, "settle_periods must be an integer >= 1"),
        ({"record_periods": 0}, "record_periods must be an integer >= 1"),
        ({"direction": "sideways"}, "direction must be"),
    ],
)
def test_stepped_sine_refuses_bad_input_in_one_line(kwargs, message):
    args = {"omegas": [10.0, 20.0], **kwargs}
    omegas = args.pop("omegas")
    with pytest.raises(SteppedSineError, match=message) as info:
        stepped_sine(_chain(2), _force(2), omegas, **args)
    assert "\n" not in str(info.value)


def test_a_force_of_the_wrong_length_is_one_line():
    with pytest.raises(StructureError) as info:
        stepped_sine(_chain(2), [1.0, 2.0, 3.0], [10.0])
    assert "\n" not in str(info.value)
    with pytest.raises(StructureError):
        periodic_orbit(_chain(2), [1.0], 10.0)


def test_restitution_is_refused_where_the_jacobian_would_miss_its_jumps():
    """A restitution of 0 leaves no speed before the impact to form its saltation matrix
    from: the orbit, curve and stepped-sine solvers refuse it in one line."""
    dead = cj.ClearanceJoint(0.2e-3, 4e5, gap_stiffness=2e4, restitution=0.0)
    s = chain([0.5], [math.inf], [dead], [2.0])
    with pytest.raises(StructureError, match="restitution of 0"):
        stepped_sine(s, [30.0], 2 * math.pi * np.array([40.0, 41.0]))
    with pytest.raises(StructureError, match="restitution of 0"):
        periodic_orbit(s, [30.0], 2 * math.pi * 40)
    with pytest.raises(StructureError, match="restitution of 0"):
        frequency_response(s, [30.0], 2 * math.pi * 40, 2 * math.pi * 41)


def test_impacts_at_the_same_instant_each_get_their_saltation_matrix():
    """A mass between two supports through two equal joints with restitution 0.5: both
    joints meet their edges at the same displacement, so their impacts come in pairs at
    the same instant (some at the same float time). The monodromy against central
    differences of the exact map, and orbits at the frequencies where the pairs tie."""
    from clearjoint.structure import time_response
    from clearjoint.structure.model import Member, Structure

    law = cj.ClearanceJoint(0.2e-3, 4e5, gap_stiffness=2e4, restitution=0.5)
    s = Structure(
        nodes=[0.0, 1.0, 2.0],
        masses=[0.0, 0.5, 0.0],
        members=[
            Member(0, 1, stiffness=math.inf, joint=law, damping=1.0),
            Member(1, 2, stiffness=math.inf, joint=law, damping=1.0),
        ],
        supports=[0, 2],
    )
    f, w = np.array([20.0]), 2 * math.pi * 40
    z = np.concatenate(time_response(s, f, w, 40 * 2 * math.pi / w).final_state)
    shoot = ShootingMap(s.to_system(), f, w)
    _, phi, motion = shoot(z)
    assert np.min(np.diff(motion.event_times)) < 1e-15  # impacts tie
    fd = np.empty((2, 2))
    scale = np.array([w, 1.0])
    for k in range(2):
        dz = np.zeros(2)
        dz[k] = 1e-8 / scale[k]
        fd[:, k] = (shoot(z + dz)[0] - shoot(z - dz)[0]) / (2 * dz[k])
    size = np.max(np.abs(phi * scale[:, None] / scale[None, :]))
    assert np.max(np.abs((fd - phi) * scale[:, None] / scale[None, :])) < 1e-6 * size
    for hz in (38.0, 39.0, 41.0, 42.0):
        assert periodic_orbit(s, f, 2 * math.pi * hz).closure < 1e-10


def test_lyapunov_exponent_with_impacts_is_the_log_of_the_largest_multiplier():
    """Restitution 0.7 on a 3-mass chain at 2 N and 15 Hz, a stable periodic motion with
    impacts: the stepped sine's exponent (its tangent flow with each impact's saltation
    matrix) against log|mu|max / T of a finite-difference monodromy of the exact map."""
    n = 3
    law = cj.ClearanceJoint(0.2e-3, 4e5, gap_stiffness=2e4, restitution=0.7)
    s = chain([0.5] * n, [math.inf] * n, [law] * n, [2.0] * n)
    f, w = _force(n, 2.0), 2 * math.pi * 15.0
    diagram = stepped_sine(s, f, [w], settle_periods=100, record_periods=100)
    assert diagram.kind[0, 0] == "periodic"
    z = diagram.poincare[0, 0, -1]
    shoot = ShootingMap(s.to_system(), f, w)
    scale = np.concatenate((np.full(n, w), np.ones(n)))
    fd = np.empty((2 * n, 2 * n))
    for k in range(2 * n):
        dz = np.zeros(2 * n)
        dz[k] = 1e-9 / scale[k]
        fd[:, k] = (shoot(z + dz)[0] - shoot(z - dz)[0]) / (2 * dz[k])
    expected = math.log(np.abs(np.linalg.eigvals(fd)).max()) / shoot.period
    assert float(diagram.lyapunov[0, 0]) == pytest.approx(expected, rel=0.02)


def test_monodromy_with_impacts_is_the_finite_difference_jacobian_of_the_exact_map():
    """Restitution 0.7 on a 3-mass chain: the monodromy with each impact's saltation matrix
    against central differences of the exact map (without the jumps it is off by O(1))."""
    n = 3
    law = cj.ClearanceJoint(0.2e-3, 4e5, gap_stiffness=2e4, restitution=0.7)
    s = chain([0.5] * n, [math.inf] * n, [law] * n, [2.0] * n)
    f, w = _force(n, 2.0), 2 * math.pi * 15.0
    from clearjoint.structure import time_response

    z = np.concatenate(time_response(s, f, w, 50 * 2 * math.pi / w).final_state)
    shoot = ShootingMap(s.to_system(), f, w)
    _, phi, motion = shoot(z)
    assert motion.energy.impact > 0.0  # the run has impacts
    fd = np.empty_like(phi)
    scale = np.concatenate((np.full(n, w), np.ones(n)))
    for k in range(2 * n):
        h = 1e-9 / scale[k]
        dz = np.zeros(2 * n)
        dz[k] = h
        fd[:, k] = (shoot(z + dz)[0] - shoot(z - dz)[0]) / (2 * h)
    size = np.max(np.abs(phi * scale[:, None] / scale[None, :]))
    assert np.max(np.abs((fd - phi) * scale[:, None] / scale[None, :])) < 1e-6 * size
    plain = ShootingMap(chain([0.5] * n, [math.inf] * n, [LAW] * n, [2.0] * n).to_system(), f, w)
    assert np.max(np.abs((plain(z)[1] - phi) * scale[:, None] / scale[None, :])) > 0.1 * size


def test_results_have_repr_plot_and_xarray():
    import matplotlib

    matplotlib.use("Agg")
    s = _chain(2)
    diagram = stepped_sine(
        s,
        _force(2),
        2 * np.pi * np.array([20.0, 30.0]),
        direction="both",
        settle_periods=20,
        record_periods=8,
    )
    assert "SteppedSine(2 frequencies" in repr(diagram)
    ds = diagram.to_xarray()
    assert ds["amplitude"].dims == ("direction", "frequency", "dof")
    assert list(ds["direction"].values) == ["up", "down"]
    assert ds["frequency"].attrs["units"] == "Hz"
    assert diagram.plot() is not None
    orbit = periodic_orbit(s, _force(2), 2 * math.pi * 30)
    assert "StructureOrbit(30 Hz" in repr(orbit)
    assert orbit.to_xarray()["x_max"].attrs["units"] == "m"
    assert orbit.plot() is not None


def test_stepped_sine_from_the_command_line(tmp_path, capsys):
    import json
    import shutil

    import xarray as xr

    from clearjoint.cli import main

    study = tmp_path / "chain.toml"
    shutil.copy(Path(__file__).parents[1] / "examples" / "chain.toml", study)
    out = tmp_path / "map.nc"
    args = ["structure", str(study), "stepped-sine", "--from", "20Hz", "--to", "30Hz"]
    args += ["--points", "2", "--settle-periods", "5", "--record-periods", "8"]
    assert main([*args, "--direction", "both", "--out", str(out), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["frequencies"] == 2
    assert summary["directions"] == ["up", "down"]
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        np.testing.assert_allclose(ds["frequency"].values, [20.0, 30.0], rtol=1e-14)
        assert ds["amplitude"].attrs["units"] == "m"
    # the same run through the Python API gives the same numbers
    from clearjoint.structure.study import load_structure_study

    s = load_structure_study(study)
    direct = stepped_sine(
        s.structure,
        s.force,
        2 * np.pi * np.array([20.0, 30.0]),
        direction="both",
        settle_periods=5,
        record_periods=8,
    )
    assert summary["max_amplitude_m"] == pytest.approx(float(np.max(direct.amplitude)), rel=1e-12)
    # its options belong to stepped-sine, and a range must go up: one line, exit 2
    for bad, text in (
        (["structure", str(study), "modes", "--points", "5"], "goes with the stepped-sine"),
        ([*args[:3], "--from", "30Hz", "--to", "20Hz"], "must be above --from"),
        (args[:3], "needs --from and --to"),
    ):
        assert main([*bad, "--out", str(tmp_path / "x.nc")]) == 2
        err = capsys.readouterr().err
        assert text in err
        assert len(err.strip().splitlines()) == 1


def test_one_link_curve_has_the_one_joint_curves_period_doublings():
    """Two independent exact solvers (the one-joint kernel with its own shooting, and the
    structure's march with its pattern exponentials) follow the same branch from the same
    orbit and find the same period doublings."""
    s = _chain(1)
    j, losses = s.to_system().to_joint()
    w0, w1 = 2 * math.pi * 46, 2 * math.pi * 40
    theirs = periodic.frequency_response(j, 30.0, w0, w1, losses=losses)
    x0, v0 = theirs.initial_state[0]
    mine = frequency_response(s, [30.0], w0, w1, initial=([x0], [v0]))
    assert mine.stop_reason == "reached"
    a = sorted(e.omega for e in mine.events if e.kind == "period_doubling")
    b = sorted(e.omega for e in theirs.events if e.kind == "period_doubling")
    assert len(a) == len(b) == 2  # near 41.56 and 44.71 Hz
    np.testing.assert_allclose(a, b, atol=2 * math.pi * 2e-3)


def test_a_massless_dof_is_one_line_for_modes_motion_and_orbits():
    from clearjoint.structure import from_matrices, system_modes, time_response

    m = np.diag([1.0, 0.0])
    k = np.array([[2e4, -1e4], [-1e4, 2e4]])
    s = from_matrices(m, k, joints=[(0, None, LAW)])
    for call in (
        lambda: system_modes(s),
        lambda: time_response(s, [1.0, 0.0], 10.0, 1.0),
        lambda: periodic_orbit(s, [1.0, 0.0], 10.0),
    ):
        with pytest.raises(StructureError, match=r"DOF 1 .* mass of 0\.0 kg") as info:
            call()
        assert "\n" not in str(info.value)


def test_impact_oscillator_cascade_against_the_rigid_limit_and_feigenbaum():
    """The period-doubling cascade of the impact oscillator (Shaw & Holmes 1983; Budd & Dux
    1994): x'' + x = cos(w t) below a stop at sigma = 0.3, restitution 0.8, going down from
    w = 2.83, where one impact every two forcing periods doubles again and again.

    The reference (tests/impact_oscillator.py) is the rigid limit in closed form, sharing no
    code with clearjoint; its cascade converges at Feigenbaum's rate (delta = 4.6692...,
    Feigenbaum 1978, J. Stat. Phys. 19, 25-52), as a smooth cascade must: the ratios of
    successive intervals fall, the last within 2 % of delta.
    clearjoint's structure solver models the stop as a one-sided clearance joint with a
    contact stiffness 1e6 times the spring's and the same restitution, and carries the
    impacts' saltation matrices in its monodromy: its first three doublings fall within
    2e-3 of the rigid limit's (the contact's finite stiffness), the first ratio of their
    intervals within 1 % of the reference's, and its first doubling where the one-joint
    solver (clearjoint.periodic, its own kernel and saltation) finds it. No published
    table of the doublings is compared (none was within reach): the literature gives the
    model and Feigenbaum's constant, and the constant checks the reference.
    """
    from scipy.optimize import brentq

    import impact_oscillator as rigid
    from clearjoint.structure import time_response
    from clearjoint.structure.poincare import ShootingMap, newton_orbit

    sigma, r, w_top = 0.3, 0.8, 2.83
    model = rigid.ImpactOscillator(w_top, sigma, r)
    z = np.array([0.0, 0.5])
    for _ in range(300):
        z = model.iterate(z, 1)
    reference = rigid.cascade(sigma, r, w_top, np.array([z[0] % model.period, z[1]]), 5)
    gaps = -np.diff(reference)
    ratios = gaps[:-1] / gaps[1:]
    assert np.all(np.diff(ratios) < 0)
    assert ratios[-1] == pytest.approx(4.6692, rel=0.02)

    law = cj.ClearanceJoint(10.0, 1e6, gap_stiffness=1.0, gap_offset=sigma - 5.0, restitution=r)
    structure = chain([1.0], [math.inf], [law], [0.0])
    system, force = structure.to_system(), np.array([1.0])

    def orbit(w: float, p: int, seed: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        found = newton_orbit(ShootingMap(system, force, w, p), seed, 1e-12)
        assert found is not None, f"no period-{p} orbit at {w}"
        return found[0], np.linalg.eigvals(found[1])

    def lowest(mu: np.ndarray) -> float:
        real = mu[np.abs(mu.imag) < 1e-9].real
        return float(real.min()) if real.size else 1.0

    def doubling(p: int, w: float, z: np.ndarray, largest: float) -> tuple[float, dict]:
        known, step = {w: z}, largest
        while True:
            z_next, mu = orbit(w + step, p, known[w])
            if lowest(mu) < -1.0:
                known[w + step] = z_next
                break
            if np.abs(mu).max() > 1.0:  # left the branch: a shorter step
                step *= 0.25
                continue
            w += step
            known[w] = z_next
            step = max(1.5 * step, largest)  # steps are negative: grow back to the largest

        def past(x: float) -> float:
            known[x], mu = orbit(x, p, known[min(known, key=lambda k: abs(k - x))])
            return lowest(mu) + 1.0

        return brentq(past, w + step, w, xtol=1e-11), known

    start = time_response(structure, force, w_top, 300 * 2 * math.pi / w_top)
    z0, _ = orbit(w_top, 2, np.concatenate(start.final_state))

    def doubled(p: int, w: float, known: dict) -> np.ndarray:
        """Just below a doubling, the stable orbit of twice the period: Newton from the
        unstable one pushed along the eigenvector of its multiplier past -1."""
        shoot = ShootingMap(system, force, w, p)
        found = newton_orbit(shoot, known[min(known, key=lambda k: abs(k - w))], 1e-12)
        assert found is not None
        base, phi = found[0], found[1]
        values, vectors = np.linalg.eig(phi)
        push = vectors[:, np.argmin(values.real)].real
        size = shoot.size(base) / shoot.size(push)

        def seeds():  # pushes, else the motion from there, which settles on the orbit
            for scale in (1e-3, 1e-2, 3e-2, 1e-1, -3e-2):
                yield base + scale * size * push
            start = base + 1e-3 * size * push
            yield np.concatenate(
                time_response(
                    structure, force, w, 400 * p * 2 * math.pi / w, initial=(start[:1], start[1:])
                ).final_state
            )

        for seed in seeds():
            z, mu = orbit(w, 2 * p, seed)
            if np.abs(mu).max() < 1.0 and shoot.size(z - base) > 1e-6 * shoot.size(base):
                return z  # stable, and not the orbit of period p run twice
        pytest.fail(f"no stable period-{2 * p} orbit just below the doubling at {w}")

    first, known = doubling(2, w_top, z0, -0.01)
    second, known = doubling(4, first - 1e-3, doubled(2, first - 1e-3, known), -0.05)
    w = second - 0.02 * (first - second)
    third, _ = doubling(8, w, doubled(4, w, known), -(first - second) / 50)
    found = np.array([first, second, third])
    np.testing.assert_allclose(found, reference[:3], atol=2e-3)
    ratio = (first - second) / (second - third)
    assert ratio == pytest.approx(ratios[0], rel=0.01)

    # the one-joint solver on the same joint finds the first doubling at the same frequency
    j, losses = system.to_joint()
    one = periodic.periodic_orbit(j, 1.0, first + 1e-3, losses=losses, period_multiple=2,
                                  initial=(float(z0[0]), float(z0[1])))  # fmt: skip

    def theirs(x: float) -> float:
        o = periodic.periodic_orbit(j, 1.0, x, losses=losses, period_multiple=2,
                                    initial=tuple(one.initial_state))  # fmt: skip
        return lowest(np.asarray(o.multipliers)) + 1.0

    assert brentq(theirs, first - 1e-4, first + 1e-4, xtol=1e-11) == pytest.approx(first, abs=1e-7)
