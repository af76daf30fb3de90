"""The example mast's first nonlinear mode against its free decay, effects separated.

``python docs/harmonic_mast_decay.py [--bays 10] [--cycles 80]`` prints the table of
docs/harmonic.md ("The nonlinear mode against the free-decay backbone", 10 bays). The
mast of examples/mast.toml (50 um joints, k_c 5e7 N/m, k0 1e5 N/m) with Rayleigh beta
2e-5 s; EPMC (H = 7) from 60 mm down; two exact free decays (structure.free_decay) from
the same tip amplitude, one released on the closed *linear* first mode, one on the EPMC
orbit's own state at phase 0. Each is read two ways:

* per cycle on closed mode 1 (structure.decay_backbone), the decrement's damping ratio
  against EPMC's two ratios at the same peak amplitude;
* by energy, no projection: the decay's total mechanical energy E(t) = 0.5 v^T M v +
  V(u) (members and joint laws) lost over each cycle, Delta E, against EPMC's
  energy_per_cycle at the same total energy, and Delta E / (4 pi E) against EPMC's
  damping_ratio (E_diss / (4 pi E_max)) there.
"""

from __future__ import annotations

import argparse
import math
import time
from typing import Any

import numpy as np

from clearjoint import ClearanceJoint
from clearjoint.harmonic import aft, nonlinear_modes
from clearjoint.harmonic.modes import potential_energy
from clearjoint.harmonic.system import LinearSystem, build
from clearjoint.structure import decay_backbone, free_decay, mast


def _orbit_energy(model: LinearSystem, basis: aft.Basis, coef: np.ndarray, omega: float) -> float:
    """Mean total energy (kinetic + potential) over the HB orbit, J."""
    tau = 2.0 * math.pi * np.arange(256) / 256
    u = basis.evaluate(coef, tau)
    v = omega * basis.evaluate(basis.derivative @ coef, tau)
    kinetic = 0.5 * np.einsum("ti,ij,tj->t", v, model.mass, v)
    return float(np.mean(kinetic + potential_energy(model, u)))


def _mode(s: Any, model: LinearSystem, h: int, tip: float, ref: int) -> dict[str, Any]:
    """EPMC at H = h over 30 amplitudes around ``tip``, with each orbit's total energy."""
    start = time.perf_counter()
    nm = nonlinear_modes(s, 1, np.geomspace(0.25 * tip, 1.25 * tip, 30), harmonics=h)
    took = time.perf_counter() - start
    ok = nm.converged
    basis = aft.Basis.make(h, aft.check_harmonics(h, None)[1])
    total = np.array(
        [
            _orbit_energy(model, basis, nm.harmonic_shapes[i], nm.frequency[i])
            for i in np.flatnonzero(ok)
        ]
    )
    print(f"EPMC H = {h}: {int(ok.sum())}/30 converged in {took:.1f} s")
    return {
        "h": h,
        "nm": nm,
        "basis": basis,
        "ok": ok,
        "peak": 0.5 * (nm.x_max[ok, ref] - nm.x_min[ok, ref]),
        "total": total,
    }


def _compare(motion: Any, model: LinearSystem, ref: int, mode: dict[str, Any]) -> None:
    """Print the decay against one EPMC mode, by energy and by decrement."""
    nm, ok, peak, total = mode["nm"], mode["ok"], mode["peak"], mode["total"]
    bb = decay_backbone(motion, ref, mode=1)
    energy = 0.5 * np.einsum("ti,i,ti->t", motion.v, np.diag(model.mass), motion.v)
    energy = energy + potential_energy(model, motion.u)
    half = math.pi / bb.omega
    loss = np.interp(bb.time - half, motion.t, energy) - np.interp(bb.time + half, motion.t, energy)
    middle = np.interp(bb.time, motion.t, energy)
    order = np.argsort(total)
    e_epmc = np.interp(middle, total[order], nm.energy_per_cycle[ok][order])
    inside = (bb.amplitude >= peak.min()) & (bb.amplitude <= peak.max())
    inside &= (middle >= total.min()) & (middle <= total.max())
    z_a = np.interp(bb.amplitude, peak, nm.damping_ratio[ok])
    z_a_epmc = np.interp(bb.amplitude, peak, nm.epmc_damping_ratio[ok])
    good = inside & np.isfinite(bb.damping_ratio)
    rows = {
        "Delta E per cycle / EPMC energy_per_cycle at the same total energy": loss / e_epmc,
        "decrement zeta on mode 1 / EPMC damping_ratio at the same a": bb.damping_ratio / z_a,
        "decrement zeta on mode 1 / EPMC epmc_damping_ratio at the same a": bb.damping_ratio
        / z_a_epmc,
    }
    print(f"  against H = {mode['h']} ({int(good.sum())} cycles inside its range):")
    for label, ratio in rows.items():
        r = ratio[good]
        print(
            f"    {label}: mean {np.mean(r):.3f}, median {np.median(r):.3f}, "
            f"range {np.min(r):.3f} to {np.max(r):.3f}, std {np.std(r):.3f}"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--bays", type=int, default=10)
    parser.add_argument("--cycles", type=int, default=80)
    parser.add_argument("--tip", type=float, default=50e-3, help="release tip amplitude, m")
    parser.add_argument("--harmonics", default="7,15", help="EPMC H values, e.g. 7,15")
    args = parser.parse_args()
    j = ClearanceJoint(clearance=5e-5, compression_stiffness=5e7, gap_stiffness=1e5)
    s = mast(args.bays, joints=j, rayleigh=(0.0, 2e-5))
    model = build(s, None)
    closed = s.modes("closed")
    phi = closed.shapes[:, 0]
    ref = int(np.argmax(np.abs(phi)))
    period = 2.0 * math.pi / float(closed.omega[0])
    modes = [_mode(s, model, int(h), args.tip, ref) for h in args.harmonics.split(",")]

    # the first EPMC orbit nearest the release amplitude, its state at phase 0
    first = modes[0]
    nm, h = first["nm"], first["h"]
    i = int(np.flatnonzero(first["ok"])[np.argmin(np.abs(first["peak"] - args.tip))])
    coef = nm.harmonic_shapes[i]
    u0_nl = coef[0] + coef[1::2].sum(axis=0)
    rates = first["basis"].derivative @ coef
    v0_nl = nm.frequency[i] * rates[[0, *range(1, 2 * h + 1, 2)]].sum(axis=0)
    scale = 0.5 * (nm.x_max[i, ref] - nm.x_min[i, ref])
    releases = {
        "closed linear mode": (scale * phi / phi[ref], np.zeros(s.n_dof)),
        f"EPMC orbit (H = {h}, phase 0)": (u0_nl, v0_nl),
    }
    for name, initial in releases.items():
        start = time.perf_counter()
        motion = free_decay(s, initial, args.cycles * period)
        took = time.perf_counter() - start
        bb = decay_backbone(motion, ref, mode=1)
        print(
            f"\nreleased on the {name} at {1e3 * scale:.1f} mm: {bb.amplitude.size} cycles "
            f"down to {1e3 * bb.amplitude[-1]:.1f} mm, {motion.events} events, {took:.1f} s"
        )
        for mode in modes:
            _compare(motion, model, ref, mode)


if __name__ == "__main__":
    main()
