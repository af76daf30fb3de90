"""Hill's method (MODEL.md 5.3) against exact references, and a curve's Neimark-Sacker events.

Run on demand:

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_hill.py --agreement
    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_hill.py --neimark-sacker

``--agreement`` prints, for H = 3, 7, 15, Hill's multipliers (centroid sorting,
clearjoint.harmonic.hill, and the imaginary-part sorting beside it) against the exact
monodromy of the same HB orbit (a 3-link chain, two 2-bay masts), against the exact
orbit's multipliers by shooting (one joint, with and without friction), and on the
stiff mast the same orbit with the perturbation carried by H' = 7..63 harmonics.
``--neimark-sacker`` runs 200 periods of exact motion from the HB states either side of
and between the Neimark-Sacker events of the softer mast's curve. docs/harmonic.md,
"Stability", quotes both.
"""

from __future__ import annotations

import os

from clearjoint import Losses

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse
import math
import sys
import time
from typing import Any

import numpy as np

from clearjoint import Joint
from clearjoint.harmonic import frequency_response

#: pyHarm's SDOF clearance case (as in bench_harmonic.py): c_v = 0.05, k0 = 1, k_c = 3.
JOINT = Joint(mass=1.0, clearance=2 * 0.1745, compression_stiffness=3.0, gap_stiffness=1.0)
ZETA = 0.05 / (2.0 * math.sqrt(3.0))


def _set_distance(a: np.ndarray, b: np.ndarray) -> float:
    """Largest distance between two sets of multipliers, paired to minimise it."""
    from scipy.optimize import linear_sum_assignment

    cost = np.abs(a[:, None] - b[None, :])
    rows, cols = linear_sum_assignment(cost)
    return float(cost[rows, cols].max())


def _hill_pair(model: Any, q: np.ndarray, w: float, h: int | None = None) -> tuple[Any, Any]:
    """Hill's spectrum of one orbit with the centroid and with the imaginary-part sorting."""
    from clearjoint.harmonic import HarmonicError, hill

    out = []
    for sorting in ("centroid", "imaginary"):
        try:
            out.append(hill.orbit_spectrum(model, q, w, harmonics=h, sorting=sorting))
        except HarmonicError:
            out.append(None)
    return out[0], out[1]


def _line(ref: np.ndarray, found: Any) -> str:
    if found is None:
        return "   unresolved        "
    mu = found.multipliers
    same = (np.max(np.abs(mu)) < 1.0) == (np.max(np.abs(ref)) < 1.0)
    return f"{np.max(np.abs(mu)):8.4f} {_set_distance(ref, mu):8.1e} {'ok' if same else 'NO'}"


def _mast_agreement(m: Any, tip: np.ndarray, f0: float, f1: float, max_step: float) -> None:
    """Hill (both sortings) against the exact monodromy on every 6th point of a mast curve."""
    from clearjoint.harmonic import aft, monodromy
    from clearjoint.harmonic.system import build

    mm = build(m, None)
    for h in (3, 7, 15):
        fr = frequency_response(
            m,
            tip,
            2 * math.pi * f0,
            2 * math.pi * f1,
            harmonics=h,
            max_points=150,
            check_points=0,
            max_step=max_step,
        )
        basis = aft.Basis.make(h, fr.settings["samples"])
        print(f"  H = {h}: {fr.omega.size} points to {fr.omega[-1] / (2 * math.pi):.1f} Hz")
        counts = {"centroid": [0, 0, 0, 0.0], "imaginary": [0, 0, 0, 0.0]}
        for k in range(0, fr.omega.size, 6):
            w, q = float(fr.omega[k]), fr.coefficients[k]
            ref = monodromy.multipliers(mm, basis, q, w)
            for name, found in zip(counts, _hill_pair(mm, q, w), strict=True):
                tally = counts[name]
                tally[0] += 1
                if found is None:
                    tally[2] += 1
                    continue
                mu = found.multipliers
                tally[1] += (np.max(np.abs(mu)) < 1.0) != (np.max(np.abs(ref)) < 1.0)
                tally[3] = max(tally[3], _set_distance(ref, mu))
        for name, (n, wrong, unresolved, worst) in counts.items():
            print(
                f"    {name:9s}: {n} points, {wrong} other verdicts, {unresolved} unresolved, "
                f"worst set distance {worst:.2e}"
            )


def hill_agreement() -> None:
    """Hill's method (centroid and imaginary-part sortings) against exact references.

    For each case and H: the largest |mu| of the reference, then per sorting the largest
    |mu|, the worst distance between the two sets of 2N multipliers (paired to minimise
    it) and whether the stable/unstable verdict is the same (ok / NO). References: the
    exact monodromy of the same HB orbit (structures), the exact orbit's multipliers by
    shooting (clearjoint.periodic, one joint). Then the 2-bay mast's contact orbits with
    the perturbation carried by H' > H harmonics (the same orbit, padded).
    """
    from clearjoint import ClearanceJoint, Friction
    from clearjoint.harmonic import aft, hill, monodromy
    from clearjoint.harmonic.system import build, friction_speed
    from clearjoint.periodic import periodic_orbit
    from clearjoint.structure import chain, mast

    head = "ref |mu|  | centroid: |mu| set-dist verdict | imaginary: |mu| set-dist verdict"
    j = ClearanceJoint(clearance=1e-4, compression_stiffness=1e7, gap_stiffness=1e5)
    s = chain([1.0] * 3, [1e6] * 3, [j] * 3, dampers=[150.0] * 3)
    force = np.array([0.0, 0.0, 40.0])
    model = build(s, None)
    print("3-link chain (tests/test_harmonic_hill.py), 40 N, against the exact monodromy")
    print(f"  H    w rad/s  {head}")
    for h in (3, 7, 15):
        for w in (200.0, 300.0, 400.0, 600.0, 800.0):
            fr = frequency_response(
                s, force, w, 1.001 * w, harmonics=h, max_points=2, check_points=0
            )
            q = fr.coefficients[0]
            ref = monodromy.multipliers(model, aft.Basis.make(h, fr.settings["samples"]), q, w)
            c, i = _hill_pair(model, q, w)
            print(
                f"  {h:2d} {w:8.0f}    {np.max(np.abs(ref)):8.4f} | "
                f"{_line(ref, c)} | {_line(ref, i)}"
            )

    m = mast(2, joints=ClearanceJoint(1e-4, 1e8, gap_stiffness=1e6), rayleigh=(0, 2e-6))
    mm = build(m, None)
    tip = np.zeros(m.n_dof)
    tip[m.dof_names.index("n5x")] = 5.0
    print("2-bay mast (joints 1e-4 m, 1e8 N/m), 5 N at the tip, 40 Hz up, 150 points,")
    print("every 6th point against the exact monodromy (contact from about 49.1 Hz)")
    _mast_agreement(m, tip, 40.0, 260.0, 0.05)
    soft = mast(2, joints=ClearanceJoint(5e-5, 5e7, gap_stiffness=1e5), rayleigh=(0, 2e-5))
    print("2-bay mast of tests/test_harmonic_structure.py (joints 5e-5 m, 5e7 N/m, highest")
    print("closed mode 2377 Hz), 20 N at the tip, 60 to 110 Hz")
    _mast_agreement(soft, 4.0 * tip, 60.0, 110.0, 0.02)
    print("  the same H = 7 orbit, the perturbation with H' harmonics (orbit_spectrum):")
    for hz in (51.92, 54.17):
        w = 2 * math.pi * hz
        fr = frequency_response(m, tip, w, 1.0001 * w, harmonics=7, max_points=2, check_points=0)
        q = fr.coefficients[0]
        ref = monodromy.multipliers(mm, aft.Basis.make(7, fr.settings["samples"]), q, w)
        for hp in (7, 15, 31, 63):
            start = time.perf_counter()
            c, i = _hill_pair(mm, q, w, hp)
            took = time.perf_counter() - start
            print(
                f"    {hz:6.2f} Hz H' = {hp:2d}: {np.max(np.abs(ref)):8.4f} | {_line(ref, c)} | "
                f"{_line(ref, i)} | both sortings {took:.1f} s (size {2 * m.n_dof * (2 * hp + 1)})"
            )

    joint_model = build(JOINT, Losses(damping_ratio=ZETA))
    print("one joint (pyHarm's case, 0.03 N, the curve 1.0 to 1.7 rad/s), every 3rd contact")
    print("point against the exact orbit's multipliers (shooting), abs(mu) - 1 > 0.03 there")
    for h in (3, 7, 15, 31):
        curve = frequency_response(
            JOINT, 0.03, 1.0, 1.7, harmonics=h, losses=Losses(damping_ratio=ZETA), max_step=0.1
        )
        for name in ("centroid", "imaginary"):
            wrong = 0
            worst_top = 0.0
            dist: list[float] = []
            for k in range(0, curve.omega.size, 3):
                if curve.amplitude[k] < 1.1 * 0.1745:
                    continue
                w = float(curve.omega[k])
                try:
                    exact = periodic_orbit(
                        JOINT,
                        0.03,
                        w,
                        losses=Losses(damping_ratio=ZETA),
                        initial=curve.initial_state[k],
                    )
                except Exception:  # no exact orbit near this HB one (low H): skip it
                    continue
                ref = np.asarray(exact.multipliers)
                if abs(float(np.max(np.abs(ref))) - 1.0) < 0.03:
                    continue
                found = hill.orbit_spectrum(
                    joint_model, curve.coefficients[k][:, None], w, sorting=name
                )
                top = float(np.max(np.abs(found.multipliers)))
                wrong += (top < 1.0) != exact.stable
                dist.append(_set_distance(ref, found.multipliers))
                worst_top = max(worst_top, abs(top / float(np.max(np.abs(ref))) - 1.0))
            print(
                f"  H = {h:2d} {name:9s}: {len(dist)} points, {wrong} other verdicts, set "
                f"distance median {np.median(dist):.2e} worst {max(dist):.2e}, "
                f"largest |mu| within {worst_top:.1%}"
            )
    rub = Friction(0.005, 1.0)
    print("one joint with friction Friction(0.005, 1.0), the regularised HB orbit's Hill")
    print("multipliers against the exact stick-slip orbit's (regularisation error included)")
    print(f"  H    w rad/s  {head}")
    for h in (7, 15):
        for w in (0.8, 1.0, 1.3, 1.6):
            fr = frequency_response(
                JOINT,
                0.03,
                w,
                1.0001 * w,
                harmonics=h,
                losses=Losses(damping_ratio=ZETA, friction=rub),
                max_points=2,
            )
            exact = periodic_orbit(
                JOINT,
                0.03,
                w,
                losses=Losses(damping_ratio=ZETA, friction=rub),
                initial=fr.initial_state[0],
            )
            ref = np.asarray(exact.multipliers)
            losses = Losses(damping_ratio=ZETA, friction=rub)
            fm = build(JOINT, losses, friction_speed(JOINT, w, None))
            c, i = _hill_pair(fm, fr.coefficients[0][:, None], w)
            print(
                f"  {h:2d} {w:8.2f}    {np.max(np.abs(ref)):8.4f} | "
                f"{_line(ref, c)} | {_line(ref, i)}"
            )
    sys.stdout.flush()


def neimark_sacker_check() -> None:
    """The Neimark-Sacker events of the softer 2-bay mast's curve against the exact motion.

    The curve (20 N at the tip, 60 to 110 Hz, H = 15, stability by the exact monodromy of
    each HB orbit) and, at points either side of and between its events, the one-period
    orbit check's residual and 200 periods of the exact motion (structure.time_response)
    from the HB state: its distance at forcing phase 0 from the HB state every 25 periods
    and the change over the last period, relative to the HB state (a constant distance and
    no change: a stable period-1 motion near the HB orbit).
    """
    from clearjoint import ClearanceJoint
    from clearjoint.harmonic.check import check_orbits
    from clearjoint.structure import mast, time_response

    s = mast(2, joints=ClearanceJoint(5e-5, 5e7, gap_stiffness=1e5), rayleigh=(0.0, 2e-5))
    f = np.zeros(s.n_dof)
    f[s.dof_names.index("n5x")] = 20.0
    n = s.n_dof
    fr = frequency_response(
        s, f, 2 * math.pi * 60, 2 * math.pi * 110, harmonics=15, max_points=150, check_points=0
    )
    marks = [(e.kind, round(e.omega / (2 * math.pi), 2)) for e in fr.events]
    print(f"softer 2-bay mast, 20 N, H = 15: {fr.omega.size} points, events {marks}")
    hz = fr.omega / (2 * math.pi)
    for target in (74.0, 76.5, 78.5, 80.5, 82.5, 85.0):
        i = int(np.argmin(np.abs(hz - target)))
        w = float(fr.omega[i])
        period = 2 * math.pi / w
        mu = fr.multipliers[i]
        top = mu[np.argmax(np.abs(mu))]
        residual = check_orbits(fr, [i]).residual[0]
        x = fr.initial_state[i]
        motion = time_response(s, f, w, 200 * period, initial=(x[:n], x[n:]), samples_per_period=64)
        u = motion.u[::64][:201]
        dev = np.linalg.norm(u - x[:n], axis=1) / np.linalg.norm(x[:n])
        step = float(np.linalg.norm(u[-1] - u[-2]) / np.linalg.norm(x[:n]))
        print(
            f"  {hz[i]:6.2f} Hz: largest mu {top:.3f} (abs {abs(top):.3f}), orbit residual "
            f"{residual:.1e}; exact motion at phase 0, periods 25, 50, ..., 200: "
            + " ".join(f"{d:.3f}" for d in dev[25::25])
            + f"; last period-to-period change {step:.1e}"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--agreement", action="store_true", help="Hill against exact references")
    parser.add_argument(
        "--neimark-sacker", action="store_true", help="a curve's NS events against exact motion"
    )
    args = parser.parse_args()
    if args.neimark_sacker:
        neimark_sacker_check()
    if args.agreement or not args.neimark_sacker:
        hill_agreement()


if __name__ == "__main__":
    main()
