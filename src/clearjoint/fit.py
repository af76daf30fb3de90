"""The paper's fitted laws, with standard errors, R^2 and residuals (MODEL.md section 3).

* eq 19: stiffness linear in frequency and amplitude, k = a1 w + a2 A + a3, for each
  structure and side; Fig. 9's normalised coefficients a1 mean(w) / mean(k) and
  a2 mean(A) / mean(k);
* eq 20: the joint's own stiffness from the jointed (k_d) and non-jointed (k_dn)
  structures in series, k_dj = k_d k_dn / (k_dn - k_d), uncertainty carried through
  (``uncertainties``, with the coefficients' correlations);
* eq 21: E = c1 exp(c2 A) per joint and frequency, fitted on ln E;
* eq 22: one law for all tests, ln E = (d0 + d1 w + d2 c) + (e0 + e1 w + e2 c) A,
  compared by AIC with a power-law alternative, ln E = g0 + g1 ln w + g2 ln A + g3 c.

Units: w in rad/s, A and c in m, k in N/m, E in J. Every fit refuses too few points or a
singular design with a :class:`FitError` that says which.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from clearjoint.errors import ClearjointError

FloatArray = NDArray[np.float64]


class FitError(ClearjointError, ValueError):
    """A law cannot be fitted to these data (too few points, a singular design...)."""


@dataclass(frozen=True)
class LinearFit:
    """Ordinary least squares y = X b: coefficients, standard errors, R^2, residuals.

    Attributes
    ----------
    names, units : tuple of str
        Each coefficient's name and unit.
    values, errors : (p,) ndarray
        The coefficients and their standard errors.
    covariance : (p, p) ndarray
    r_squared : float
    residuals : (n,) ndarray
    n : int
        Number of points.
    """

    names: tuple[str, ...]
    units: tuple[str, ...]
    values: FloatArray
    errors: FloatArray
    covariance: FloatArray
    r_squared: float
    residuals: FloatArray
    n: int

    @property
    def aic(self) -> float:
        """Akaike's criterion for Gaussian errors: n ln(RSS / n) + 2 p."""
        rss = float(np.dot(self.residuals, self.residuals))
        return self.n * math.log(max(rss, 1e-300) / self.n) + 2 * len(self.values)

    def coefficient(self, name: str) -> float:
        return float(self.values[self.names.index(name)])

    def table(self) -> list[dict[str, object]]:
        """One row per coefficient: name, value, standard error, unit."""
        return [
            {"name": n, "value": float(v), "std_error": float(e), "unit": u}
            for n, v, e, u in zip(self.names, self.values, self.errors, self.units, strict=True)
        ]


def linear_fit(
    design: ArrayLike, y: ArrayLike, names: Sequence[str], units: Sequence[str], *, what: str
) -> LinearFit:
    """Fit y = X b by least squares; refuse too few points or a singular design."""
    x = np.asarray(design, dtype=np.float64)
    target = np.asarray(y, dtype=np.float64)
    n, p = x.shape
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(target))):
        raise FitError(f"{what}: the data contain NaN or infinite values")
    if n <= p:
        raise FitError(f"{what}: {n} points for {p} coefficients; need at least {p + 1}")
    if np.linalg.matrix_rank(x) < p:
        raise FitError(
            f"{what}: singular design: the data do not vary in every variable of the law "
            "(e.g. a single frequency or amplitude); it cannot be fitted"
        )
    values, *_ = np.linalg.lstsq(x, target, rcond=None)
    residuals = target - x @ values
    dof = n - p
    sigma2 = float(np.dot(residuals, residuals)) / dof
    covariance = sigma2 * np.linalg.inv(x.T @ x)
    total = float(np.sum((target - target.mean()) ** 2))
    r2 = 1.0 - float(np.dot(residuals, residuals)) / total if total > 0 else 1.0
    return LinearFit(
        names=tuple(names),
        units=tuple(units),
        values=np.asarray(values, dtype=np.float64),
        errors=np.sqrt(np.diag(covariance)),
        covariance=covariance,
        r_squared=r2,
        residuals=residuals,
        n=n,
    )


# ---- eq 19 and Fig. 9 ---------------------------------------------------------------------


def stiffness_law(
    omega: ArrayLike, amplitude: ArrayLike, stiffness: ArrayLike, *, what: str = "eq 19"
) -> LinearFit:
    """Return eq 19, k = a1 w + a2 A + a3, fitted by least squares (w rad/s, A m, k N/m)."""
    w = np.asarray(omega, dtype=np.float64)
    a = np.asarray(amplitude, dtype=np.float64)
    return linear_fit(
        np.column_stack((w, a, np.ones_like(w))),
        stiffness,
        ("a1", "a2", "a3"),
        ("N s/(m rad)", "N/m^2", "N/m"),
        what=what,
    )


def normalised_coefficients(
    law: LinearFit, omega: ArrayLike, amplitude: ArrayLike, stiffness: ArrayLike
) -> tuple[float, float]:
    """Fig. 9: (a1 mean(w) / mean(k), a2 mean(A) / mean(k)), our definition (MODEL.md)."""
    k = float(np.mean(np.asarray(stiffness, dtype=np.float64)))
    return (
        law.coefficient("a1") * float(np.mean(np.asarray(omega, dtype=np.float64))) / k,
        law.coefficient("a2") * float(np.mean(np.asarray(amplitude, dtype=np.float64))) / k,
    )


def predict(law: LinearFit, omega: ArrayLike, amplitude: ArrayLike) -> FloatArray:
    """Evaluate eq 19 at (w, A)."""
    w = np.asarray(omega, dtype=np.float64)
    a = np.asarray(amplitude, dtype=np.float64)
    return np.asarray(law.values[0] * w + law.values[1] * a + law.values[2], dtype=np.float64)


# ---- eq 20 --------------------------------------------------------------------------------


@dataclass(frozen=True)
class JointStiffness:
    """eq 20 at given points: k_dj and its standard uncertainty (NaN where k_dn <= k_d)."""

    omega: FloatArray
    amplitude: FloatArray
    value: FloatArray
    error: FloatArray


def joint_stiffness(
    jointed: LinearFit, beam: LinearFit, omega: ArrayLike, amplitude: ArrayLike
) -> JointStiffness:
    """Return eq 20, k_dj = k_d k_dn / (k_dn - k_d), from the two eq 19 laws, with uncertainty.

    The coefficients' covariances are carried through with ``uncertainties``; the
    two laws are fitted on different tests, so they are taken as independent.
    Defined only where k_dn > k_d (NaN elsewhere).
    """
    from uncertainties import correlated_values

    w = np.atleast_1d(np.asarray(omega, dtype=np.float64))
    a = np.atleast_1d(np.asarray(amplitude, dtype=np.float64))
    cj = correlated_values(jointed.values, jointed.covariance)
    cb = correlated_values(beam.values, beam.covariance)
    value = np.full(w.size, np.nan)
    error = np.full(w.size, np.nan)
    for i, (wi, ai) in enumerate(zip(w, a, strict=True)):
        k_d = cj[0] * wi + cj[1] * ai + cj[2]
        k_dn = cb[0] * wi + cb[1] * ai + cb[2]
        if k_dn.nominal_value <= k_d.nominal_value:
            continue
        k_dj = k_d * k_dn / (k_dn - k_d)
        value[i], error[i] = k_dj.nominal_value, k_dj.std_dev
    return JointStiffness(w, a, value, error)


# ---- eq 21 and 22 -------------------------------------------------------------------------


def exponential_law(amplitude: ArrayLike, energy: ArrayLike, *, what: str = "eq 21") -> LinearFit:
    """Return eq 21, E = c1 exp(c2 A), fitted on ln E = ln c1 + c2 A (A m, E J)."""
    a = np.asarray(amplitude, dtype=np.float64)
    e = np.asarray(energy, dtype=np.float64)
    if np.any(e <= 0):
        raise FitError(f"{what}: energies must be > 0 to fit on ln E")
    return linear_fit(
        np.column_stack((np.ones_like(a), a)),
        np.log(e),
        ("ln_c1", "c2"),
        ("ln J", "1/m"),
        what=what,
    )


def _energy_data(
    what: str, *columns: ArrayLike
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """(w, c, A, E) as arrays; the energies must be > 0 to fit on ln E."""
    w, c, a, e = (np.asarray(column, dtype=np.float64) for column in columns)
    if np.any(e <= 0):
        raise FitError(f"{what}: energies must be > 0 to fit on ln E")
    return w, c, a, e


def dissipation_law(
    omega: ArrayLike, clearance: ArrayLike, amplitude: ArrayLike, energy: ArrayLike
) -> LinearFit:
    """Return eq 22, ln E = (d0 + d1 w + d2 c) + (e0 + e1 w + e2 c) A, for all tests."""
    w, c, a, e = _energy_data("eq 22", omega, clearance, amplitude, energy)
    design = np.column_stack((np.ones_like(w), w, c, a, w * a, c * a))
    return linear_fit(
        design,
        np.log(e),
        ("d0", "d1", "d2", "e0", "e1", "e2"),
        ("ln J", "s/rad", "1/m", "1/m", "s/(rad m)", "1/m^2"),
        what="eq 22",
    )


def power_law(
    omega: ArrayLike, clearance: ArrayLike, amplitude: ArrayLike, energy: ArrayLike
) -> LinearFit:
    """The alternative to eq 22: ln E = g0 + g1 ln w + g2 ln A + g3 c."""
    w, c, a, e = _energy_data("power law", omega, clearance, amplitude, energy)
    if np.any(a <= 0):
        raise FitError("power law: amplitudes must be > 0 to fit on ln A")
    design = np.column_stack((np.ones_like(w), np.log(w), np.log(a), c))
    return linear_fit(
        design, np.log(e), ("g0", "g1", "g2", "g3"), ("ln J", "1", "1", "1/m"), what="power law"
    )


def evaluate_dissipation_law(
    law: LinearFit, omega: ArrayLike, clearance: ArrayLike, amplitude: ArrayLike
) -> FloatArray:
    """E from eq 22's coefficients at (w, c, A), J."""
    w = np.asarray(omega, dtype=np.float64)
    c = np.asarray(clearance, dtype=np.float64)
    a = np.asarray(amplitude, dtype=np.float64)
    d0, d1, d2, e0, e1, e2 = law.values
    return np.asarray(np.exp(d0 + d1 * w + d2 * c + (e0 + e1 * w + e2 * c) * a), dtype=np.float64)
