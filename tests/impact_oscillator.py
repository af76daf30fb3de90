"""The rigid impact oscillator of Shaw & Holmes (1983) and Budd & Dux (1994), written alone.

    x'' + x = cos(w t)  for x < sigma,   x' -> -r x'  at x = sigma,

in its own time and length units (mass, spring and force amplitude 1). Between impacts
the motion is the closed form x = C cos(t - t0) + D sin(t - t0) + g cos(w t), g = 1 / (1 -
w^2); the next impact is the first time x reaches sigma again (the flight sampled at 1/64
of a forcing period, the crossing closed by Brent's method). The impact map takes (t0, V)
(an impact's time and approach speed) to the next; a period-p orbit of the map (p impacts)
is found by Newton with a finite-difference Jacobian, and its period doubling, where an
eigenvalue of that Jacobian passes -1, by Brent's method in w.

This is the test's reference for clearjoint's structure solver on a one-sided stop with
restitution: it shares no code with clearjoint and has no contact stiffness (the rigid limit).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq


class ImpactOscillator:
    def __init__(self, w: float, sigma: float, r: float) -> None:
        self.w, self.sigma, self.r = w, sigma, r
        self.g = 1.0 / (1.0 - w * w)
        self.period = 2.0 * math.pi / w

    def _coefficients(self, t0: float, speed: float) -> tuple[float, float]:
        c = self.sigma - self.g * math.cos(self.w * t0)
        d = -self.r * speed + self.g * self.w * math.sin(self.w * t0)
        return c, d

    def position(self, t: float, t0: float, speed: float) -> float:
        c, d = self._coefficients(t0, speed)
        return c * math.cos(t - t0) + d * math.sin(t - t0) + self.g * math.cos(self.w * t)

    def velocity(self, t: float, t0: float, speed: float) -> float:
        c, d = self._coefficients(t0, speed)
        return -c * math.sin(t - t0) + d * math.cos(t - t0) - self.g * self.w * math.sin(self.w * t)

    def next_impact(self, t0: float, speed: float, periods: int = 20) -> tuple[float, float]:
        """The next impact after one at t0 with approach speed ``speed``: (time, speed).

        The flight is sampled at 1/64 of a forcing period; a crossing inside a sample
        interval is seen either at its end or at a maximum inside it (the velocity turning
        from positive to negative), so a brief excursion past sigma is not missed.
        """
        h = self.period / 64.0

        def gap(t: float) -> float:
            return self.position(t, t0, speed) - self.sigma

        def rate(t: float) -> float:
            return self.velocity(t, t0, speed)

        a = t0 + 1e-9 * self.period
        if speed <= 0.0 or gap(a) >= 0.0:
            raise RuntimeError("not an impact: the mass does not leave the stop")
        c, d = self._coefficients(t0, speed)
        for lap in range(periods):  # one forcing period of samples at a time
            t = t0 + h * np.arange(64 * lap, 64 * lap + 65)
            t[0] = max(t[0], a)
            x = c * np.cos(t - t0) + d * np.sin(t - t0) + self.g * np.cos(self.w * t) - self.sigma
            v = -c * np.sin(t - t0) + d * np.cos(t - t0) - self.g * self.w * np.sin(self.w * t)
            for k in range(64):
                lo, hi = float(t[k]), float(t[k + 1])
                end = hi if x[k + 1] >= 0.0 else None
                if end is None and v[k] > 0.0 > v[k + 1]:
                    top = brentq(rate, lo, hi, xtol=1e-15, rtol=1e-15)
                    if gap(top) >= 0.0:
                        end = top
                if end is not None:
                    t1 = brentq(gap, lo, end, xtol=1e-14, rtol=1e-15) if gap(end) > 0.0 else end
                    return t1, rate(t1)
        raise RuntimeError("no impact within the horizon")

    def iterate(self, z: np.ndarray, impacts: int) -> np.ndarray:
        t, speed = float(z[0]), float(z[1])
        for _ in range(impacts):
            t, speed = self.next_impact(t, speed)
        return np.array([t, speed])

    def residual(self, z: np.ndarray, impacts: int) -> np.ndarray:
        end = self.iterate(z, impacts)
        lap = round((end[0] - z[0]) / self.period)
        return np.array([end[0] - z[0] - lap * self.period, end[1] - z[1]])

    def jacobian(self, z: np.ndarray, impacts: int) -> np.ndarray:
        base = self.iterate(z, impacts)
        jac = np.empty((2, 2))
        for k in range(2):
            step = np.zeros(2)
            step[k] = 1e-7 * max(1.0, abs(z[k]))
            jac[:, k] = (self.iterate(z + step, impacts) - base) / step[k]
        return jac

    def orbit(self, z: np.ndarray, impacts: int) -> np.ndarray:
        """Newton on the p-impact map's fixed point, halving a step that leaves the map."""
        z = np.asarray(z, dtype=np.float64).copy()
        r = self.residual(z, impacts)
        for _ in range(40):
            if np.linalg.norm(r) < 1e-12:
                return np.array([z[0] % self.period, z[1]])
            step = -np.linalg.solve(self.jacobian(z, impacts) - np.eye(2), r)
            for _ in range(30):
                trial = z + step
                try:
                    r_trial = self.residual(trial, impacts) if trial[1] > 0.0 else None
                except RuntimeError:
                    r_trial = None
                if r_trial is not None and np.linalg.norm(r_trial) < 2.0 * np.linalg.norm(r):
                    break
                step = 0.5 * step
            else:
                break
            z, r = trial, r_trial
        raise RuntimeError("Newton did not converge")


def _seed(z: np.ndarray, w_from: float, w_to: float) -> np.ndarray:
    """An orbit's (impact time, speed) at w_from as a seed at w_to: the same forcing phase."""
    return np.array([z[0] * w_from / w_to, z[1]])


def lowest_eigenvalue(w: float, sigma: float, r: float, z: np.ndarray, impacts: int) -> float:
    values = np.linalg.eigvals(ImpactOscillator(w, sigma, r).jacobian(z, impacts))
    real = values[np.abs(values.imag) < 1e-12].real
    return float(real.min()) if real.size else 1.0


def cascade(
    sigma: float, r: float, w_start: float, z_start: np.ndarray, doublings: int
) -> list[float]:
    """The frequencies of the first ``doublings`` period doublings met going down from w_start."""
    found: list[float] = []
    impacts, w = 1, w_start
    z = ImpactOscillator(w_start, sigma, r).orbit(z_start, 1)
    step = -0.002
    while len(found) < doublings:
        known = {w: z}
        while True:  # down in w until the orbit's lowest eigenvalue is below -1
            w_next = w + step
            z_next = ImpactOscillator(w_next, sigma, r).orbit(_seed(known[w], w, w_next), impacts)
            values = np.linalg.eigvals(ImpactOscillator(w_next, sigma, r).jacobian(z_next, impacts))
            real = values[np.abs(values.imag) < 1e-12].real
            if real.size and real.min() < -1.0:
                known[w_next] = z_next
                break
            if np.max(np.abs(values)) > 1.0:  # Newton left the branch: a shorter step
                step *= 0.25
                if abs(step) < 1e-9:
                    raise RuntimeError("the branch was lost")
                continue
            known[w_next] = z_next
            w = w_next

        def past(x: float, impacts: int = impacts, known: dict = known) -> float:
            near = min(known, key=lambda k: abs(k - x))
            known[x] = ImpactOscillator(x, sigma, r).orbit(_seed(known[near], near, x), impacts)
            return lowest_eigenvalue(x, sigma, r, known[x], impacts) + 1.0

        doubling = brentq(past, w_next, w, xtol=1e-12)
        found.append(doubling)
        gap = found[-2] - found[-1] if len(found) > 1 else 0.05
        # the doubled orbit, just below: Newton from the orbit pushed along the eigenvector
        w = doubling - 0.02 * gap
        model = ImpactOscillator(w, sigma, r)
        near = min(known, key=lambda k: abs(k - w))
        base = model.orbit(_seed(known[near], near, w), impacts)
        values, vectors = np.linalg.eig(model.jacobian(base, impacts))
        direction = vectors[:, np.argmin(values.real)].real
        for size in (1e-3, 3e-3, 1e-2, 3e-2, 1e-1):
            try:
                z = model.orbit(base + size * direction, 2 * impacts)
            except (RuntimeError, np.linalg.LinAlgError):
                continue
            lag = (z[0] - base[0]) / model.period
            other = math.hypot(model.period * (lag - round(lag)), z[1] - base[1]) > 1e-6
            # not the base orbit again (an impact time counts modulo T), and stable: the
            # orbit a supercritical doubling leaves just below it
            if other and np.max(np.abs(np.linalg.eigvals(model.jacobian(z, 2 * impacts)))) < 1:
                break
        else:
            raise RuntimeError("the doubled orbit was not found")
        impacts, step = 2 * impacts, -gap / 50
    return found
