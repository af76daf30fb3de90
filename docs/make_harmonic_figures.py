"""Tables of docs/harmonic.md: ``python docs/make_harmonic_figures.py``.

Prints the H-convergence tables (HB against exact shooting orbits, and the EPMC
backbone against the exact free period). Its pictures are drawn by
examples/gallery/plot_harmonic.py, which the docs build runs.
"""

from __future__ import annotations

import math

import numpy as np

from clearjoint import Joint, Losses, dissipation, stiffness
from clearjoint.harmonic import aft, nonlinear_modes, solve, system
from clearjoint.periodic import periodic_orbit

PYHARM = Joint(mass=1.0, clearance=2 * 0.1745, compression_stiffness=3.0, gap_stiffness=1.0)
ZETA = 0.05 / (2.0 * math.sqrt(3.0))
PAPER = Joint(mass=2.0, clearance=0.106e-3, compression_stiffness=8e7)
HARMONICS = (3, 7, 15, 31, 63)


def _hb_point(h: int, omega: float, guess: np.ndarray) -> tuple[np.ndarray, aft.Basis]:
    model = system.from_joint(PYHARM, Losses(damping_ratio=ZETA))
    hh, n_t = aft.check_harmonics(h, None)
    basis = aft.Basis.make(hh, n_t)
    q0 = np.zeros(2 * hh + 1)
    q0[: min(q0.size, guess.size)] = guess[: q0.size]

    def function(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        ev = aft.evaluate(model, basis, q, omega, np.array([0.03]))
        return ev.residual, ev.jacobian

    found = solve.newton(function, q0, 0.1)
    assert found is not None
    return found[0], basis


def convergence_table() -> None:
    """x_max error of HB against the exact orbit, upper (contacting) branch."""
    print("| omega (rad/s) | exact x_max | " + " | ".join(f"H = {h}" for h in HARMONICS) + " |")
    print("|---|---|" + "---|" * len(HARMONICS))
    for omega in (1.0, 1.3, 1.5):
        guess = np.array([0.0, -0.3, 0.1])
        exact = None
        cells = []
        for h in HARMONICS:
            q, basis = _hb_point(h, omega, guess)
            guess = q
            if exact is None:
                x0 = q[0] + q[1::2].sum()
                v0 = omega * float(np.arange(1, h + 1) @ q[2::2])
                exact = periodic_orbit(
                    PYHARM, 0.03, omega, losses=Losses(damping_ratio=ZETA), initial=(x0, v0)
                )
            top, _ = basis.extremes(q[:, None])
            cells.append(f"{abs(top[0] - exact.x_max) / exact.amplitude:.1e}")
        assert exact is not None
        print(f"| {omega} | {exact.x_max:.6f} | " + " | ".join(cells) + " |")


def backbone_table() -> None:
    """EPMC frequency at x_max against 2 pi / T(A), the paper's joint (k0 = 0)."""
    amplitudes = np.geomspace(70e-6, 2e-3, 8)
    print("| H | max rel. error of w vs 2 pi / T(A) | ")
    print("|---|---|")
    for h in HARMONICS:
        nm = nonlinear_modes(PAPER, 1, amplitudes, harmonics=h)
        exact = 2 * math.pi / stiffness.period(PAPER, nm.x_max - PAPER.compression_gap)
        print(f"| {h} | {np.max(np.abs(nm.frequency / exact - 1)):.1e} |")
    zeta = 0.02
    nm = nonlinear_modes(PAPER, 1, amplitudes, harmonics=15, losses=Losses(damping_ratio=zeta))
    a = nm.x_max - PAPER.compression_gap
    e = dissipation.viscous(PAPER, a, zeta)
    exact = dissipation.energies(PAPER, a, losses=Losses(damping_ratio=zeta)).loss_factor / 2
    print(
        "\n| A (um) | damping_ratio | E_diss / (4 pi E_max), dissipation | epmc_damping_ratio "
        "| E per cycle / dissipation.viscous |"
    )
    print("|---|---|---|---|---|")
    for i in range(a.size):
        print(
            f"| {a[i] * 1e6:.4g} | {nm.damping_ratio[i]:.5f} | {exact[i]:.5f} | "
            f"{nm.epmc_damping_ratio[i]:.5f} | {nm.energy_per_cycle[i] / e[i]:.5f} |"
        )


if __name__ == "__main__":
    convergence_table()
    print()
    backbone_table()
