"""The paper's fitted laws, with standard errors, R^2 and residuals (MODEL.md section 3).

* eq 19: stiffness linear in frequency and amplitude, k = a1 w + a2 A + a3, for each
  structure and side; Fig. 9's normalised coefficients a1 mean(w) / mean(k) and
  a2 mean(A) / mean(k);
* eq 20: the joint's own stiffness from the jointed (k_d) and non-jointed (k_dn)
  structures in series, k_dj = k_d k_dn / (k_dn - k_d), uncertainty carried through
  (``uncertainties``, with the coefficients' correlations);
* eq 21: E = c1 exp(c2 A) per joint and frequency, fitted on ln E;
* eq 22: one law for all tests, ln E = (d0 + d1 w + d2 c) + (e0 + e1 w + e2 c) A,
  compared by AIC with a power-law alternative, ln E = g0 + g1 ln w + g2 ln A + g3 c;
* a quadratic check, y = q0 + q1 u + q2 u^2 + q3 v, for "rises and saturates" and
  "first falls" (the sign of the curvature and of the slope at one end).

Each law has its design matrix (``*_design``) and its evaluator (``evaluate_*``), so a
law is fitted and evaluated through the same columns. :func:`slope` gives a linear
combination of a law's coefficients (a derivative at a point) with its standard error.

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


def stiffness_design(omega: ArrayLike, amplitude: ArrayLike) -> FloatArray:
    """Return eq 19's design matrix, (n, 3) columns w, A, 1."""
    w = np.asarray(omega, dtype=np.float64)
    a = np.asarray(amplitude, dtype=np.float64)
    w, a = np.broadcast_arrays(w, a)
    return np.column_stack((w, a, np.ones_like(w)))


def stiffness_law(
    omega: ArrayLike, amplitude: ArrayLike, stiffness: ArrayLike, *, what: str = "eq 19"
) -> LinearFit:
    """Return eq 19, k = a1 w + a2 A + a3, fitted by least squares (w rad/s, A m, k N/m)."""
    return linear_fit(
        stiffness_design(omega, amplitude),
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


def evaluate_stiffness_law(law: LinearFit, omega: ArrayLike, amplitude: ArrayLike) -> FloatArray:
    """Return eq 19's k at (w, A), N/m, shaped like the broadcast of ``omega`` and ``amplitude``."""
    return np.asarray(stiffness_design(omega, amplitude) @ law.values, dtype=np.float64)


#: The former name of :func:`evaluate_stiffness_law`.
predict = evaluate_stiffness_law


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


def exponential_design(amplitude: ArrayLike) -> FloatArray:
    """Return eq 21's design matrix for ln E, (n, 2) columns 1, A."""
    a = np.atleast_1d(np.asarray(amplitude, dtype=np.float64))
    return np.column_stack((np.ones_like(a), a))


def exponential_law(amplitude: ArrayLike, energy: ArrayLike, *, what: str = "eq 21") -> LinearFit:
    """Return eq 21, E = c1 exp(c2 A), fitted on ln E = ln c1 + c2 A (A m, E J)."""
    e = np.asarray(energy, dtype=np.float64)
    if np.any(e <= 0):
        raise FitError(f"{what}: energies must be > 0 to fit on ln E")
    return linear_fit(
        exponential_design(amplitude),
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


def evaluate_exponential_law(law: LinearFit, amplitude: ArrayLike) -> FloatArray:
    """Return eq 21's E = c1 exp(c2 A) at A, J, shape (n,)."""
    return np.asarray(np.exp(exponential_design(amplitude) @ law.values), dtype=np.float64)


def _columns(*values: ArrayLike) -> list[FloatArray]:
    arrays = np.broadcast_arrays(*(np.atleast_1d(np.asarray(v, dtype=np.float64)) for v in values))
    return [np.asarray(a, dtype=np.float64) for a in arrays]


def dissipation_design(omega: ArrayLike, clearance: ArrayLike, amplitude: ArrayLike) -> FloatArray:
    """Return eq 22's design matrix for ln E, (n, 6) columns 1, w, c, A, w A, c A."""
    w, c, a = _columns(omega, clearance, amplitude)
    return np.column_stack((np.ones_like(w), w, c, a, w * a, c * a))


def dissipation_law(
    omega: ArrayLike,
    clearance: ArrayLike,
    amplitude: ArrayLike,
    energy: ArrayLike,
    *,
    what: str = "eq 22",
) -> LinearFit:
    """Return eq 22, ln E = (d0 + d1 w + d2 c) + (e0 + e1 w + e2 c) A, for all tests.

    ``amplitude`` is whichever amplitude the caller chose (MODEL.md section 3: the
    penetration Abar = X - c/2, or the total amplitude X a displacement sensor reads).
    """
    w, c, a, e = _energy_data(what, omega, clearance, amplitude, energy)
    return linear_fit(
        dissipation_design(w, c, a),
        np.log(e),
        ("d0", "d1", "d2", "e0", "e1", "e2"),
        ("ln J", "s/rad", "1/m", "1/m", "s/(rad m)", "1/m^2"),
        what=what,
    )


def evaluate_dissipation_law(
    law: LinearFit, omega: ArrayLike, clearance: ArrayLike, amplitude: ArrayLike
) -> FloatArray:
    """Return E from eq 22's coefficients at (w, c, A), J, shape (n,)."""
    design = dissipation_design(omega, clearance, amplitude)
    return np.asarray(np.exp(design @ law.values), dtype=np.float64)


def power_design(omega: ArrayLike, clearance: ArrayLike, amplitude: ArrayLike) -> FloatArray:
    """Return the power law's design matrix for ln E, (n, 4) columns 1, ln w, ln A, c."""
    w, c, a = _columns(omega, clearance, amplitude)
    return np.column_stack((np.ones_like(w), np.log(w), np.log(a), c))


def power_law(
    omega: ArrayLike, clearance: ArrayLike, amplitude: ArrayLike, energy: ArrayLike
) -> LinearFit:
    """The alternative to eq 22: ln E = g0 + g1 ln w + g2 ln A + g3 c."""
    w, c, a, e = _energy_data("power law", omega, clearance, amplitude, energy)
    if np.any(a <= 0):
        raise FitError("power law: amplitudes must be > 0 to fit on ln A")
    return linear_fit(
        power_design(w, c, a),
        np.log(e),
        ("g0", "g1", "g2", "g3"),
        ("ln J", "1", "1", "1/m"),
        what="power law",
    )


def evaluate_power_law(
    law: LinearFit, omega: ArrayLike, clearance: ArrayLike, amplitude: ArrayLike
) -> FloatArray:
    """Return E from the power law at (w, c, A), J, shape (n,)."""
    return np.asarray(np.exp(power_design(omega, clearance, amplitude) @ law.values))


# ---- trends: a slope with its standard error, and a curvature check ------------------------


def slope(law: LinearFit, weights: ArrayLike) -> tuple[float, float]:
    """Return (g . b, its standard error sqrt(g C g)) for a weight vector g over the coefficients.

    A derivative of a law linear in its coefficients is such a combination: for eq 22,
    d ln E / dc at (w, A) has g = (0, 0, 1, 0, 0, A).
    """
    g = np.asarray(weights, dtype=np.float64)
    if g.shape != law.values.shape:
        raise FitError(f"slope: {g.size} weights for a law of {law.values.size} coefficients")
    return float(g @ law.values), float(np.sqrt(max(float(g @ law.covariance @ g), 0.0)))


def quadratic_design(main: ArrayLike, other: ArrayLike) -> FloatArray:
    """Return the quadratic check's design matrix, (n, 4) columns 1, u, u^2, v."""
    u, v = _columns(main, other)
    return np.column_stack((np.ones_like(u), u, u * u, v))


def quadratic_law(
    main: ArrayLike, other: ArrayLike, y: ArrayLike, *, what: str = "quadratic check"
) -> LinearFit:
    """Return y = q0 + q1 u + q2 u^2 + q3 v fitted by least squares (u the variable studied).

    q2 < 0 with q1 + 2 q2 u > 0 over the data says "rises and saturates" (the rate of
    increase falls); q1 + 2 q2 u_min < 0 says "first falls". Units are the caller's.
    """
    return linear_fit(
        quadratic_design(main, other), y, ("q0", "q1", "q2", "q3"), ("", "", "", ""), what=what
    )


def evaluate_quadratic_law(law: LinearFit, main: ArrayLike, other: ArrayLike) -> FloatArray:
    """Return the quadratic check's y at (u, v), shape (n,)."""
    return np.asarray(quadratic_design(main, other) @ law.values, dtype=np.float64)
