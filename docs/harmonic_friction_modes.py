"""Nonlinear modes with Coulomb friction: the errors against the exact free orbit.

``python docs/harmonic_friction_modes.py`` prints the table of docs/harmonic.md
("Nonlinear modes with Coulomb friction"). The paper's joint (2 kg, c = 0.106 mm,
k_c = 80 MN/m; symmetric, and off-centre with k_t = 30 MN/m and k0 = 1 MN/m) with 1 kN
of sliding friction over the whole path (mu_s 0.5, P 2 kN) and no viscous damping;
EPMC at 6 modal amplitudes 0.1..2 mm (x_max 1.7 to 30 times the stick limit
g_c + mu_s P / k_c), at H = 7, 15, 31, 63 and v_eps = 100, 10, 1, 0.1 times the
default 1e-3 w c (w the closed-pattern frequency). Columns: the largest relative error
over the amplitudes of

* ``zeta``: damping_ratio against E_diss / (4 pi E_max) of :mod:`clearjoint.dissipation`
  on the exact free orbit of the same A = x_max - g_c (Coulomb's 4 mu_s P X);
* ``E``: energy_per_cycle (xi * integral of m x'^2 dt) against Coulomb's work on the HB
  orbit itself, 2 mu_s P (x_max - x_min) (MODEL.md section 2).

Then, per amplitude, the off-centre joint's zeta and its error at H = 31 (default v_eps):
where zeta is large EPMC's periodic orbit is not the conservative free orbit.
"""

from __future__ import annotations

import math
import time

import numpy as np

from clearjoint import Friction, Joint, Losses, dissipation
from clearjoint.harmonic import nonlinear_modes

HEAVY = Friction(coefficient=0.5, lateral_load=2000.0)
AMPLITUDES = np.geomspace(1e-4, 2e-3, 6)
BASE = {"mass": 2.0, "clearance": 0.106e-3, "compression_stiffness": 8e7}
JOINTS = {
    "symmetric": Joint(**BASE),
    "off-centre": Joint(**BASE, tension_stiffness=3e7, gap_stiffness=1e6, gap_offset=0.03e-3),
}


def errors(j: Joint, harmonics: int, sharper: float) -> tuple[float, float, int]:
    """(zeta error, E error, converged count) at H and v_eps = sharper x the default."""
    v_eps = 1e-3 * math.sqrt(j.compression_stiffness / j.mass) * j.clearance * sharper
    nm = nonlinear_modes(
        j,
        1,
        AMPLITUDES,
        harmonics=harmonics,
        losses=Losses(friction=HEAVY),
        friction_regularization=v_eps,
    )
    ok = nm.converged
    a = nm.x_max[ok] - j.compression_gap
    exact = dissipation.energies(j, a, losses=Losses(friction=HEAVY)).loss_factor / 2.0
    closed = 2.0 * HEAVY.force * (nm.x_max[ok] - nm.x_min[ok])
    return (
        float(np.max(np.abs(nm.damping_ratio[ok] / exact - 1.0))),
        float(np.max(np.abs(nm.energy_per_cycle[ok] / closed - 1.0))),
        int(ok.sum()),
    )


def main() -> None:
    start = time.perf_counter()
    print("joint       v_eps/default   H   zeta error   E error   converged")
    for name, j in JOINTS.items():
        for sharper in (100.0, 10.0, 1.0, 0.1):
            for h in (7, 15, 31, 63):
                z, e, n = errors(j, h, sharper)
                print(
                    f"{name:11s} {sharper:13g} {h:3d} {z:12.2e} {e:9.2e} {n:5d}/{AMPLITUDES.size}"
                )
    j = JOINTS["off-centre"]
    nm = nonlinear_modes(j, 1, AMPLITUDES, harmonics=31, losses=Losses(friction=HEAVY))
    exact = dissipation.energies(
        j, nm.x_max - j.compression_gap, losses=Losses(friction=HEAVY)
    ).loss_factor
    print("off-centre, H = 31: zeta       ", " ".join(f"{z:9.3g}" for z in nm.damping_ratio))
    error = nm.damping_ratio / (exact / 2.0) - 1.0
    print("                    zeta error ", " ".join(f"{e:9.2e}" for e in error))
    print(f"({time.perf_counter() - start:.1f} s)")


if __name__ == "__main__":
    main()
