"""Why the example mast's first nonlinear mode fails at some amplitudes above contact onset.

``python docs/harmonic_mast_onset.py`` prints the legs of docs/harmonic.md ("Where the
nonlinear mode fails near contact onset"): the EPMC branch of examples/mast.toml's first
mode (H = 7) followed by pseudo-arclength continuation in all its unknowns, the harmonic
coefficients Q / a, w, xi and log a together (so that it may turn back in amplitude),
from a converged amplitude towards another; each leg stops where the amplitude turns
back (a fold) or where it reaches its target. Where the Jacobian jumps (a sample of a
joint crossing a gap edge: the residual is piecewise linear in Q) the tangent turns
sharply; at the smallest step such a turn is taken (a corner). A diagnostic, not part of
the package: it rebuilds the EPMC residual of clearjoint.harmonic.modes from
clearjoint.harmonic.aft.evaluate, with the derivative in log a as its last column.
"""

from __future__ import annotations

import math
import time

import numpy as np
import scipy.linalg

from clearjoint.harmonic import NonlinearMode, aft, nonlinear_modes
from clearjoint.harmonic.solve import newton
from clearjoint.harmonic.system import build
from clearjoint.structure.study import load_structure_study

H = 7
#: the 30 amplitudes of ``clearjoint modes examples/mast.toml --mode 1 --amplitude 2mm..7mm
#: --points 30``; each leg (start index, stop in m) starts on the solution found there
AMPLITUDES = np.geomspace(2e-3, 7e-3, 30)
LEGS = ((29, 2e-3), (0, 2.5e-3), (5, 2e-3), (3, 2e-3), (3, 2.5e-3), (4, 2e-3))


class Epmc:
    """R(y) = 0 of EPMC at y = (Q / a, w / w_lin, xi / w_lin, log a), scaled as modes.py."""

    def __init__(self, structure: object) -> None:
        self.model = build(structure, None)
        w2, shapes = scipy.linalg.eigh(self.model.closed_stiffness(), self.model.mass)
        self.ref = int(np.argmax(np.abs(shapes[:, 0])))
        self.w_lin = math.sqrt(float(w2[0]))
        h, n_t = aft.check_harmonics(H, None)
        self.basis = aft.Basis.make(h, n_t)
        self.n = self.model.n_dof
        self.n_u = (2 * h + 1) * self.n

    def mass_norm(self, y: np.ndarray) -> float:
        """sqrt(a_1^T M a_1 + b_1^T M b_1) of the orbit at y, m kg^0.5."""
        a, n, m = math.exp(y[-1]), self.n, self.model.mass
        c, s = y[n : 2 * n] * a, y[2 * n : 3 * n] * a
        return math.sqrt(float(c @ m @ c + s @ m @ s))

    def __call__(self, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        n, n_u, ref, model = self.n, self.n_u, self.ref, self.model
        a, ws, k = math.exp(y[-1]), self.w_lin, model.reference_stiffness
        q, w, xi = y[:n_u] * a, y[n_u] * ws, y[n_u + 1] * ws
        ev = aft.evaluate(model, self.basis, q, w, np.zeros(n), negative_damping=xi)
        r = np.empty(n_u + 2)
        r[:n_u] = ev.residual / (k * a)
        r[n_u], r[n_u + 1] = y[n + ref] - 1.0, y[2 * n + ref]
        jac = np.zeros((n_u + 2, n_u + 3))
        jac[:n_u, :n_u] = ev.jacobian / k
        jac[:n_u, n_u] = ev.d_omega * ws / (k * a)
        d_xi = -w * ((self.basis.derivative @ q.reshape(-1, n)) @ model.mass).ravel()
        jac[:n_u, n_u + 1] = d_xi * ws / (k * a)
        jac[:n_u, n_u + 2] = jac[:n_u, :n_u] @ y[:n_u] - r[:n_u]  # d r / d log a
        jac[n_u, n + ref] = jac[n_u + 1, 2 * n + ref] = 1.0
        return r, jac


def _tangent(jac: np.ndarray, previous: np.ndarray) -> np.ndarray:
    t = np.linalg.solve(np.vstack([jac, previous]), np.r_[np.zeros(jac.shape[0]), 1.0])
    t /= np.linalg.norm(t)
    return t if t @ previous > 0.0 else -t


def leg(epmc: Epmc, nm: NonlinearMode, i: int, stop: float, points: int = 2000) -> str:
    """Follow the branch from ``nm``'s solution ``i`` towards amplitude ``stop`` (m); one line."""
    start = float(nm.amplitude[i])
    w = float(nm.frequency[i])
    xi = float(nm.epmc_damping_ratio[i]) * 2.0 * w
    y = np.r_[nm.harmonic_shapes[i].ravel() / start, w / epmc.w_lin, xi / epmc.w_lin]
    y = np.r_[y, math.log(start)]
    side = 1.0 if stop > start else -1.0
    _, jac = epmc(y)
    direction = np.zeros(y.size)
    direction[-1] = side
    t = _tangent(jac, direction)
    ds, least, corners, sharpest = 0.02, 1e-8, 0, 0.0
    norms = [epmc.mass_norm(y)]
    for _ in range(points):
        while True:
            guess = y + ds * t
            z = guess.copy()
            ok = False
            tries = 0
            while tries < 12:
                tries += 1
                r, jac = epmc(z)
                if np.max(np.abs(r)) < 1e-11:
                    ok = True
                    break
                step = np.linalg.solve(np.vstack([jac, t]), np.r_[-r, -(t @ (z - guess))])
                z = z + step
                if not np.all(np.isfinite(z)) or abs(z[-1] - guess[-1]) > 0.5:
                    break
            if ok:
                t_new = _tangent(jac, t)
                if t_new @ t >= math.cos(0.3) or ds <= least * 1.01:
                    if t_new @ t < math.cos(0.3):
                        corners += 1
                        sharpest = max(sharpest, math.degrees(math.acos(float(t_new @ t))))
                    break
            if ds <= least * 1.01:
                return f"stops (no step converges) at {_at(epmc, y)}, {corners} corner(s) crossed"
            ds = max(0.5 * ds, least)
        y, t = z, t_new
        norms.append(epmc.mass_norm(y))
        ds = min(1.5 * ds, 0.1) if tries <= 4 else (0.7 * ds if tries >= 8 else ds)
        if (y[-1] - math.log(stop)) * side > 0.0:
            return f"reaches {stop * 1e3:.4g} mm ({corners} corner(s) crossed)"
        if t[-1] * side < 0.0:
            ahead = epmc.mass_norm(y + 1e-6 * t) - norms[-1]  # along the new tangent
            same = ahead * (norms[-1] - norms[-2]) < 0.0
            return (
                f"turns back in amplitude at {_at(epmc, y)}, after {corners} corner(s), the "
                f"sharpest {sharpest:.0f} deg; the fundamental's mass norm over all DOFs turns "
                f"back {'at the same step' if same else 'elsewhere'}"
            )
    return f"{points} points without reaching {stop * 1e3:.4g} mm, at {_at(epmc, y)}"


def _at(epmc: Epmc, y: np.ndarray) -> str:
    f = y[epmc.n_u] * epmc.w_lin / (2.0 * math.pi)
    xi = y[epmc.n_u + 1] * epmc.w_lin
    return f"a = {math.exp(y[-1]) * 1e3:.4f} mm ({f:.3f} Hz, xi {xi:.3g} 1/s)"


def main() -> None:
    structure = load_structure_study("examples/mast.toml").structure
    epmc = Epmc(structure)
    began = time.perf_counter()
    nm = nonlinear_modes(structure, 1, AMPLITUDES, harmonics=H)
    took = time.perf_counter() - began
    count = int(nm.converged.sum())
    print(f"nonlinear_modes, 30 amplitudes 2..7 mm: {count} converged ({took:.0f} s)")
    print(f"  {nm.note}")
    for i, stop in LEGS:
        began = time.perf_counter()
        line = leg(epmc, nm, i, stop)
        took = time.perf_counter() - began
        start = AMPLITUDES[i] * 1e3
        print(f"from {start:.4g} mm towards {stop * 1e3:.4g} mm: {line} ({took:.0f} s)")
    # plain Newton (400 iterations) at the two amplitudes left, from 2 and 2.48 mm's solutions
    for i in np.flatnonzero(~nm.converged).tolist():
        a = float(AMPLITUDES[i])
        for j in (0, 5):
            w = float(nm.frequency[j])
            xi = float(nm.epmc_damping_ratio[j]) * 2.0 * w
            z = np.r_[
                nm.harmonic_shapes[j].ravel() / AMPLITUDES[j], w / epmc.w_lin, xi / epmc.w_lin
            ]

            def fixed(z: np.ndarray, a: float = a) -> tuple[np.ndarray, np.ndarray]:
                r, jac = epmc(np.r_[z, math.log(a)])
                return r, jac[:, :-1]

            found = newton(fixed, z, 1.0, max_iterations=400)
            print(
                f"Newton at {a * 1e3:.4g} mm from the solution at {AMPLITUDES[j] * 1e3:.4g} mm: "
                + ("no convergence in 400 iterations" if found is None else "converged")
            )


if __name__ == "__main__":
    main()
