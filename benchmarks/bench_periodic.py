"""Whole frequency-response curves: continuation of exact orbits vs frequency_sweep vs pyHarm.

Run on demand::

    python benchmarks/bench_periodic.py [--pyharm /work/venv-pyharm/bin/python]

Case (issue 10): pyHarm's SDOF clearance case, m = 1, c_v = 0.05, k0 = 1, gap edges
at +-0.1745, contact adds 3, F0 = 0.03, omega from 0.05 to 1.8 rad/s.

1. ``periodic.frequency_response`` (after a first call that compiles), the whole
   curve: both stable branches and the unstable one.
2. ``simulate.frequency_sweep`` on the same omega grid (sorted), swept up, and
   both ways.
3. pyHarm (harmonic balance, 12 harmonics) when ``--pyharm PYTHON`` names an
   interpreter that has it (pyHarm pins old jax and pandas: keep it in its own
   venv, ``python3.11 -m venv /work/venv-pyharm && /work/venv-pyharm/bin/pip
   install pyharm-os``). The script it runs is written here at run time and uses
   pyHarm's public API (Maestro with a substructure, a PenaltyBilateralGap and a
   SinusForcing); its second run is timed, after the first one has compiled.
4. Stiff contact (k_contact / k0 = 1e8, restitution 0.8): ``time_response`` against
   a fair solve_ivp (``per_state_reference``: event location on the gap edges, each
   state integrated by itself with its step capped at its own period, restarts with
   the restitution jump) at equal final-state accuracy, both measured against that
   solve_ivp at rtol 2.3e-14 (its floor).

Targets: >= 300 points with all branches, >= 20x faster than pyHarm and than
frequency_sweep on the same grid; the stiff time response >= 50x faster than
solve_ivp. The ratios are printed; nothing here asserts them.
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

import numpy as np

from clearjoint import Joint
from clearjoint.periodic import frequency_response
from clearjoint.simulate import frequency_sweep, time_response

PYHARM_JOINT = Joint(
    mass=1.0,
    clearance=2 * 0.1745,
    gap_stiffness=1.0,
    compression_stiffness=3.0,
    tension_stiffness=3.0,
)
ZETA = 0.05 / (2.0 * math.sqrt(3.0))  # c_v = 2 zeta sqrt(m k_c) = 0.05
F0, W_START, W_STOP = 0.03, 0.05, 1.8

PYHARM_SCRIPT = textwrap.dedent(
    """
    import json, sys, time
    import numpy as np
    import pyHarm
    from pyHarm.DynamicOperator import compute_DFT

    def problem():
        return {
            "analysis": {"frf": {
                "study": "frf", "puls_inf": 0.05, "puls_start": 0.05, "puls_sup": 1.8,
                "ds0": 1e-2, "ds_min": 1e-4, "ds_max": 0.01, "sign_ds": 1, "verbose": False,
                "stepsizer": "acceptance", "predictor": "tangent", "corrector": "arc_length",
                "stopper": "bounds", "solver": "scipyroot"}},
            "system": {"type": "Base", "nh": 12, "nti": 512},
            "substructures": {"sdof": {"type": "substructure", "ndofs": 1, "matrix": {
                "M": np.array([[1.0]]), "K": np.array([[1.0]]), "C": np.array([[0.05]])}}},
            "connectors": {
                "gap": {"connect": {"sdof": [0]}, "dirs": [0], "type": "PenaltyBilateralGap",
                        "g": 0.1745, "k": 3.0},
                "force": {"connect": {"sdof": [0]}, "dirs": [0], "type": "SinusForcing",
                          "amp": 0.03},
            },
        }

    times = []
    for _ in range(2):
        start = time.perf_counter()
        m = pyHarm.Maestro(problem())
        m.operate()
        times.append(time.perf_counter() - start)
    sols = [s for s in m.nls["frf"].SolList if s.flag_accepted]
    dft = compute_DFT(m.system.nti, m.system.nh)
    idx = m.getIndex("sdof", 0, 0)
    xt = np.array([s.x[idx] @ dft["ft"] for s in sols])
    out = {
        "times": times,
        "omega": [float(s.x[-1]) for s in sols],
        "amplitude": ((xt.max(axis=1) - xt.min(axis=1)) / 2).tolist(),
    }
    with open(sys.argv[1], "w") as f:
        json.dump(out, f)
    """
)


def best_of(fn, repeat: int = 3) -> tuple[float, object]:  # type: ignore[no-untyped-def]
    best, result = math.inf, None
    for _ in range(repeat):
        start = time.perf_counter()
        result = fn()
        best = min(best, time.perf_counter() - start)
    return best, result


def run_pyharm(python: str) -> dict[str, object] | None:
    with tempfile.TemporaryDirectory() as tmp:
        script = Path(tmp) / "pyharm_sdof_clearance.py"
        script.write_text(PYHARM_SCRIPT, encoding="utf-8")
        out = Path(tmp) / "out.json"
        done = subprocess.run(
            [python, str(script), str(out)],
            capture_output=True,
            text=True,
            timeout=3600,
            cwd=tmp,  # pyHarm writes a .pyHarm/ folder into its working directory
        )
        if done.returncode != 0 or not out.exists():
            print(f"pyHarm failed (exit {done.returncode}): {done.stderr.strip()[-400:]}")
            return None
        result: dict[str, object] = json.loads(out.read_text(encoding="utf-8"))
        return result


def curve_summary(omega: np.ndarray, amplitude: np.ndarray) -> str:
    peak = int(np.argmax(amplitude))
    turns = np.nonzero(np.sign(np.diff(omega[:-1])) * np.sign(np.diff(omega[1:])) < 0)[0] + 1
    folds = ", ".join(f"{omega[i]:.4f}" for i in turns)
    return f"peak {amplitude[peak]:.4f} at {omega[peak]:.4f} rad/s; omega turns back at {folds}"


def per_state_reference(
    joint: Joint,
    force_amplitude: float,
    omega: float,
    duration: float,
    restitution: float,
    rtol: float,
    steps_per_period: float = 20.0,
) -> tuple[float, float]:
    """A fair solve_ivp reference: (x, x') at ``duration`` from rest at x = 0.

    Frictionless and undamped (the stiff case below): each state (free play,
    compression, tension) is integrated by itself with DOP853, its step capped at
    *its own* shortest period (its natural period or the forcing period) over
    ``steps_per_period``; solve_ivp locates the gap edge that ends it (entering
    contact from the free play, leaving it from a contact) and the integration
    restarts there, with x' -> e x' on entering contact (MODEL.md sec. 2).
    """
    from scipy.integrate import solve_ivp

    m, k0 = joint.mass, joint.gap_stiffness
    g_c, g_t = joint.compression_gap, joint.tension_gap
    states = {  # region: (stiffness, force offset): the restoring force is k x - offset
        0: (k0, 0.0),
        1: (k0 + joint.compression_stiffness, joint.compression_stiffness * g_c),
        -1: (k0 + joint.tension_stiffness, -joint.tension_stiffness * g_t),
    }
    t_force = 2.0 * math.pi / omega
    x_size = max(joint.clearance, force_amplitude / joint.large_amplitude_stiffness)
    t, y, region = 0.0, np.zeros(2), 0
    while t < duration:
        k, offset = states[region]
        own = min(t_force, 2.0 * math.pi * math.sqrt(m / k)) if k > 0.0 else t_force

        def rhs(time_: float, z: np.ndarray, k: float = k, offset: float = offset) -> list[float]:
            return [z[1], (force_amplitude * math.sin(omega * time_) + offset - k * z[0]) / m]

        def edge(_t: float, z: np.ndarray, region: int = region) -> float:
            if region == 0:  # leaves the free play at either edge
                return float(min(g_c - z[0], z[0] + g_t))
            return float(z[0] - g_c) if region == 1 else float(-g_t - z[0])

        edge.terminal = True  # type: ignore[attr-defined]
        edge.direction = -1  # type: ignore[attr-defined]
        sol = solve_ivp(
            rhs,
            (t, duration),
            y,
            method="DOP853",
            rtol=rtol,
            atol=[1e-14 * x_size, 1e-14 * x_size * omega],
            events=edge,
            max_step=own / steps_per_period,
        )
        if sol.status != 1:  # reached the end
            return float(sol.y[0, -1]), float(sol.y[1, -1])
        t = float(sol.t_events[0][0])
        x, v = (float(val) for val in sol.y_events[0][0])
        if region == 0:
            region = 1 if x > 0.0 else -1
            y = np.array([g_c if region == 1 else -g_t, restitution * v])
        else:
            y = np.array([g_c if region == 1 else -g_t, v])
            region = 0
    return float(y[0]), float(y[1])


def stiff_contact() -> None:
    """time_response against the per-state solve_ivp reference at equal accuracy."""
    stiff = Joint(
        mass=1.0,
        clearance=0.2,
        gap_stiffness=1.0,
        compression_stiffness=1e8,
        tension_stiffness=1e8,
    )
    omega, periods = 1.0, 1
    duration = periods * 2 * math.pi / omega
    print(f"stiff contact, k_contact/k0 = 1e8, e = 0.8, F0 = 1, {periods} forcing periods:")
    truth = per_state_reference(stiff, 1.0, omega, duration, 0.8, rtol=2.3e-14)
    time_response(stiff, 1.0, omega, duration, restitution=0.8)  # compile
    t_ed, motion = best_of(lambda: time_response(stiff, 1.0, omega, duration, restitution=0.8))
    err_ed = abs(motion.final_state[0] - truth[0]) / 0.1  # type: ignore[attr-defined]
    print(
        f"  time_response: {t_ed * 1e3:.2f} ms, error {err_ed:.1e} (final x against solve_ivp "
        "rtol 2.3e-14, relative to the gap edge)"
    )
    print("  solve_ivp, each state with its own step cap (its period / 20), events, restarts:")
    matched, best = None, None
    for rtol in (1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13):
        t_ref, ref = best_of(
            lambda rtol=rtol: per_state_reference(stiff, 1.0, omega, duration, 0.8, rtol)
        )
        err = abs(ref[0] - truth[0]) / 0.1  # type: ignore[index]
        print(f"    rtol {rtol:g}: {t_ref:.3f} s, error {err:.1e}, ratio {t_ref / t_ed:.0f}x")
        if matched is None and err <= err_ed:
            matched = (rtol, t_ref / t_ed)
        if best is None or err < best[1]:
            best = (rtol, err, t_ref / t_ed)
    if matched is not None:
        print(
            f"  at equal accuracy (the loosest rtol as accurate as time_response, {matched[0]:g}): "
            f"time_response is {matched[1]:.0f}x faster"
        )
    elif best is not None:
        print(
            f"  at equal accuracy: no solve_ivp run was as accurate as time_response; its most "
            f"accurate (rtol {best[0]:g}, error {best[1]:.1e}) is {best[2]:.0f}x slower, a lower "
            "bound of the ratio at equal accuracy"
        )
    start = time.perf_counter()
    long = time_response(stiff, 1.0, omega, 100 * 2 * math.pi / omega, restitution=0.8)
    print(
        f"  time_response over 100 periods: {time.perf_counter() - start:.3f} s, "
        f"{long.impact_times.size} impacts, ledger balance {long.energy.balance_error:.1e}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pyharm", help="a Python interpreter with pyharm-os installed")
    parser.add_argument("--skip-sweep-both", action="store_true", help="sweep up only")
    parser.add_argument(
        "--stiff-only", action="store_true", help="run only the stiff-contact comparison"
    )
    args = parser.parse_args()
    if args.stiff_only:
        stiff_contact()
        return

    print("case: pyHarm SDOF clearance, F0 = 0.03, omega 0.05 -> 1.8 rad/s, c_v = 0.05")
    frequency_response(PYHARM_JOINT, F0, W_START, W_STOP, damping_ratio=ZETA)  # compile
    t_curve, curve = best_of(
        lambda: frequency_response(PYHARM_JOINT, F0, W_START, W_STOP, damping_ratio=ZETA)
    )
    fr = curve  # type: ignore[assignment]
    n = fr.omega.size  # type: ignore[attr-defined]
    print(
        f"continuation (exact orbits): {t_curve:.3f} s, {n} points, "
        f"{int(np.sum(~fr.stable))} unstable, events: "  # type: ignore[attr-defined]
        + ", ".join(f"{e.kind} {e.omega:.4f}" for e in fr.events)  # type: ignore[attr-defined]
    )
    print("  " + curve_summary(fr.omega, fr.amplitude))  # type: ignore[attr-defined]

    grid = np.sort(fr.omega)  # type: ignore[attr-defined]
    frequency_sweep(PYHARM_JOINT, F0, grid[:3], direction="up", damping_ratio=ZETA)  # compile
    start = time.perf_counter()
    up = frequency_sweep(PYHARM_JOINT, F0, grid, direction="up", damping_ratio=ZETA)
    t_up = time.perf_counter() - start
    print(
        f"frequency_sweep up on the same {grid.size} frequencies: {t_up:.3f} s "
        f"(ratio {t_up / t_curve:.1f}x), {int(np.sum(np.isnan(up.amplitude_up)))} without a "
        f"steady state; it never reaches the unstable branch"
    )
    if not args.skip_sweep_both:
        start = time.perf_counter()
        frequency_sweep(PYHARM_JOINT, F0, grid, direction="both", damping_ratio=ZETA)
        t_both = time.perf_counter() - start
        print(f"frequency_sweep both ways: {t_both:.3f} s (ratio {t_both / t_curve:.1f}x)")

    if args.pyharm:
        ph = run_pyharm(args.pyharm)
        if ph is not None:
            times = ph["times"]  # type: ignore[index]
            om = np.array(ph["omega"])
            amp = np.array(ph["amplitude"])
            print(
                f"pyHarm (12 harmonics): first run {times[0]:.3f} s, second {times[1]:.3f} s, "  # type: ignore[index]
                f"{om.size} points (ratio {times[1] / t_curve:.1f}x)"  # type: ignore[index]
            )
            print("  " + curve_summary(om, amp))
    else:
        print("pyHarm: not run (give --pyharm PYTHON)")

    stiff_contact()
    print(
        "targets: curve >= 300 points; >= 20x faster than pyHarm and than frequency_sweep; "
        "stiff time_response >= 50x faster than solve_ivp at equal accuracy"
    )


if __name__ == "__main__":
    sys.exit(main())
