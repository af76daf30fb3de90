"""Floquet exponents by Hill's method with eigenvector (centroid) sorting (MODEL.md 5.3).

Linearised about an HB orbit, a perturbation e^(lambda t) s(t), s periodic in
H harmonics, solves Hill's quadratic eigenproblem

    (Delta_0 + lambda Delta_1 + lambda^2 Delta_2) s = 0,

Delta_0 the HB Jacobian, Delta_1 = I x C + 2 w D x M (plus the sampled friction
tangent), Delta_2 = I x M. Its 2N (2H + 1) eigenvalues hold each of the 2N Floquet
exponents once per shift lambda + i k w (a "family"); the shifted member's
eigenvector is the same perturbation written as e^(-i k w t) s(t), so in complex
exponentials s = sum_k c_k e^(i k w t) its weight moves by k harmonics. Which 2N to
keep is the sorting problem (Lazarus & Thomas, C. R. Mecanique 338, 2010):

- ``"imaginary"``: the 2N with the smallest abs(Im lambda). It fails when the
  structure's higher modes lie above H w / 2 (their resolved member is not the one
  closest to the real axis).
- ``"centroid"``: the member of each family whose eigenvector's weight centroid
  kbar = sum_k k abs(c_k)^2 / sum_k abs(c_k)^2 is closest to 0, the weighted mean of
  Guillot, Vergez & Cochelin (J. Comput. Phys. 416, 2020, eq. 26; squared weights
  here) and the "symmetric eigenvector" of Bentvelsen & Lazarus (Nonlinear Dyn.
  2018). The centroid alone is not enough: the truncation also makes spurious
  families (members that exist only on one side of the spectrum, their neighbours
  shifted by +-i w missing) whose centred member competes with the resolved ones
  (0.159 instead of 0.792 on a 3-link chain at H = 7, 400 rad/s). So each member
  with abs(kbar) <= 3/4 gets a shift defect

      d = (min_j abs(lambda_j - (lambda + i w)) + min_j abs(lambda_j - (lambda - i w))) / w,

  zero for a family Hill's truncated problem resolves (the spectrum is invariant
  under the shift near its centre), and the 2N with the smallest d are kept, one
  per family (two candidates that differ by i k w within 0.01 w and whose centroids
  differ by -k, as the members kbar = -+1/2 of a negative real multiplier do, count
  once). ``defect`` is the largest d kept: a resolution measure of the verdict.

The eigenproblem is solved densely (eigenvectors included): size 2N (2H + 1), cost
growing as its cube; both sortings together took 0.1-0.2 s at size 240, 2-7 s at
1008 and 9-30 s at 2032 on 2 shared cores (``benchmarks/bench_hill.py --agreement``);
a 10-bay mast (40 DOF) at H = 7 is 1200. A stiff-contact structure also needs many
more harmonics in the perturbation than in the orbit (:func:`orbit_spectrum`), so
for structures the exact monodromy of the HB orbit
(:mod:`clearjoint.harmonic.monodromy`) is the default route.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
import scipy.linalg
from numpy.typing import NDArray

from clearjoint.harmonic.aft import (
    Basis,
    check_harmonics,
    evaluate,
    hill_matrix,
)
from clearjoint.harmonic.system import HarmonicError, LinearSystem

__all__ = [
    "CANDIDATE_CENTROID",
    "SAME_FAMILY",
    "HillSpectrum",
    "centroids",
    "orbit_spectrum",
    "select",
    "spectrum",
]

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]

#: Members with abs(centroid) up to this are candidates (1/2 in an untruncated problem).
CANDIDATE_CENTROID = 0.75
#: Two candidates closer than this (in units of w) after a shift by i k w, whose centroids
#: also differ by about -k (within 1/4), are one family.
SAME_FAMILY = 0.01

Sorting = Literal["centroid", "imaginary"]


@dataclass(frozen=True)
class HillSpectrum:
    """The 2N Floquet exponents Hill's method keeps, and how well they are resolved.

    Attributes
    ----------
    exponents : (2N,) complex ndarray
        lambda, 1/s, in the order of ``multipliers``.
    multipliers : (2N,) complex ndarray
        exp(lambda T), T = 2 pi / w, largest modulus first.
    centroid : (2N,) ndarray
        Each kept eigenvector's weight centroid kbar (harmonics).
    defect : float
        The largest shift defect d of the kept exponents (see the module docstring);
        0 for the ``"imaginary"`` sorting, which does not measure it.
    """

    exponents: ComplexArray = field(repr=False)
    multipliers: ComplexArray = field(repr=False)
    centroid: FloatArray = field(repr=False)
    defect: float

    def __post_init__(self) -> None:
        if not (self.exponents.shape == self.multipliers.shape == self.centroid.shape):
            raise HarmonicError("HillSpectrum arrays must share one shape (2N,)")

    def __repr__(self) -> str:
        top = float(np.max(np.abs(self.multipliers))) if self.multipliers.size else 0.0
        return (
            f"HillSpectrum({self.exponents.size} exponents, largest |mu| = {top:.4g}, "
            f"defect = {self.defect:.3g})"
        )


def centroids(basis: Basis, vectors: ComplexArray, n_dof: int) -> FloatArray:
    """Return each eigenvector's weight centroid over the complex harmonics k = -H..H.

    Parameters
    ----------
    basis : Basis
    vectors : (N (2H + 1), m) complex ndarray
        Eigenvectors s in the real basis, coefficient-major (rows a_0, a_1, b_1, ...
        each N long).
    n_dof : int
        N.

    Returns
    -------
    (m,) ndarray
        kbar = sum_k k abs(c_k)^2 / sum_k abs(c_k)^2, with c_(+-h) = (a_h -+ i b_h) / 2
        summed over the DOFs (u = sum_k c_k e^(i k w t)).
    """
    h = basis.harmonics
    v = vectors.reshape(2 * h + 1, n_dof, -1)
    a, b = v[1::2], v[2::2]  # (H, N, m)
    up = np.sum(np.abs(0.5 * (a - 1j * b)) ** 2, axis=1)  # k = +h
    down = np.sum(np.abs(0.5 * (a + 1j * b)) ** 2, axis=1)  # k = -h
    k = np.arange(1, h + 1, dtype=np.float64)[:, None]
    power = np.sum(np.abs(v[0]) ** 2, axis=0) + np.sum(up + down, axis=0)
    moment = np.sum(k * (up - down), axis=0)
    return np.asarray(moment / np.maximum(power, 1e-300), dtype=np.float64)


def spectrum(
    system: LinearSystem,
    basis: Basis,
    jacobian: FloatArray,
    omega: float,
    velocity_tangent: FloatArray | None = None,
    *,
    sorting: Sorting = "centroid",
) -> HillSpectrum:
    """Return the 2N Floquet exponents of an HB orbit by Hill's method (MODEL.md 5.3).

    Parameters
    ----------
    system : LinearSystem
        N DOFs, diagonal mass.
    basis : Basis
    jacobian : (N (2H + 1), N (2H + 1)) ndarray
        The HB Jacobian dR/dQ at the orbit, N/m, coefficient-major.
    omega : float
        w, rad/s.
    velocity_tangent : (N_t, n_j) ndarray, optional
        Each joint's sampled friction tangent dF/dv, N s/m (regularised friction).
    sorting : {"centroid", "imaginary"}
        How the 2N exponents are picked (module docstring).

    Returns
    -------
    HillSpectrum

    Raises
    ------
    HarmonicError
        An unknown ``sorting``, or fewer than 2N candidates (the eigenproblem does
        not resolve the orbit at this H).
    """
    if sorting not in ("centroid", "imaginary"):
        raise HarmonicError(f"sorting must be 'centroid' or 'imaginary', got {sorting!r}")
    n = system.n_dof
    size = (2 * basis.harmonics + 1) * n
    a = hill_matrix(system, basis, jacobian, omega, velocity_tangent)
    period = 2.0 * math.pi / omega
    if sorting == "imaginary":
        lam = scipy.linalg.eigvals(a, check_finite=False)
        keep = np.argsort(np.abs(lam.imag), kind="stable")[: 2 * n]
        return _result(lam[keep], np.full(keep.size, np.nan), 0.0, period)
    lam, vec = scipy.linalg.eig(a, check_finite=False)
    kbar = centroids(basis, vec[:size], n)
    chosen, defect = select(lam, kbar, omega, 2 * n)
    return _result(lam[chosen], kbar[chosen], defect, period)


def orbit_spectrum(
    system: LinearSystem,
    coefficients: FloatArray,
    omega: float,
    *,
    harmonics: int | None = None,
    sorting: Sorting = "centroid",
) -> HillSpectrum:
    """Return Hill's spectrum of an HB orbit, the perturbation carried by ``harmonics``.

    The orbit's H harmonics are padded with zeros to ``harmonics`` >= H and the
    Jacobian of the padded orbit is taken (the same orbit; only the perturbation
    gets more harmonics). Hill's truncation error is then measured apart from the
    orbit's: on a structure whose contact modes lie far above H w the perturbation
    needs many more harmonics than the orbit (docs/harmonic.md, "Stability").

    Parameters
    ----------
    system : LinearSystem
    coefficients : (2H + 1, N) ndarray
        The HB orbit, m.
    omega : float
        w, rad/s.
    harmonics : int, optional
        H' >= H harmonics of the perturbation; default H.
    sorting : {"centroid", "imaginary"}

    Returns
    -------
    HillSpectrum

    Raises
    ------
    HarmonicError
        H' < H, or as :func:`spectrum`.
    """
    q = np.asarray(coefficients, dtype=np.float64)
    h = (q.shape[0] - 1) // 2
    hp, n_t = check_harmonics(h if harmonics is None else harmonics, None)
    if hp < h:
        raise HarmonicError(f"harmonics must be >= the orbit's H = {h}, got {harmonics!r}")
    padded = np.zeros((2 * hp + 1, system.n_dof))
    padded[: 2 * h + 1] = q
    basis = Basis.make(hp, n_t)
    ev = evaluate(system, basis, padded.ravel(), omega, np.zeros(system.n_dof))
    return spectrum(system, basis, ev.jacobian, omega, ev.velocity_tangent, sorting=sorting)


def select(
    lam: ComplexArray, kbar: FloatArray, omega: float, count: int
) -> tuple[NDArray[np.int64], float]:
    """Pick ``count`` exponents, one per family, by centroid and shift defect.

    Parameters
    ----------
    lam : (m,) complex ndarray
        All of Hill's eigenvalues, 1/s.
    kbar : (m,) ndarray
        Their eigenvectors' centroids (:func:`centroids`).
    omega : float
        w, rad/s.
    count : int
        2N.

    Returns
    -------
    (count,) ndarray of int, float
        The indices kept and the largest shift defect among them.

    Raises
    ------
    HarmonicError
        Fewer than ``count`` candidates with abs(kbar) <= ``CANDIDATE_CENTROID``.
    """
    cand = np.flatnonzero(np.abs(kbar) <= CANDIDATE_CENTROID)
    if cand.size < count:
        raise HarmonicError(
            f"Hill's method found {cand.size} centred exponents, fewer than the 2N = {count} "
            "needed: raise harmonics, or use stability='monodromy'"
        )
    z = lam / omega  # in units of w
    c = z[cand]
    up = np.min(np.abs(z[None, :] - (c[:, None] + 1j)), axis=1)
    down = np.min(np.abs(z[None, :] - (c[:, None] - 1j)), axis=1)
    defect = up + down
    kc = kbar[cand]
    order = np.lexsort((np.abs(kbar[cand]), defect))
    kept: list[int] = []
    for i in order.tolist():
        if len(kept) == count:
            break
        if any(_same_family(c[i], c[j], kc[i], kc[j]) for j in kept):
            continue
        kept.append(i)
    for i in order.tolist():  # near-collisions merged above: fill in order
        if len(kept) == count:
            break
        if i not in kept:
            kept.append(i)
    idx = np.asarray(kept, dtype=np.int64)
    return cand[idx], float(np.max(defect[idx]))


def _same_family(z1: complex, z2: complex, k1: float, k2: float) -> bool:
    """True if z1 - z2 (units of w) is i k, k a nonzero integer, within ``SAME_FAMILY``,
    and the centroids k1 - k2 = -k within 1/4 (the shift moves the weight by k)."""
    d = z1 - z2
    k = round(d.imag)
    close = abs(complex(d.real, d.imag - k)) < SAME_FAMILY
    return k != 0 and close and abs(k1 - k2 + k) < 0.25


def _result(lam: ComplexArray, kbar: FloatArray, defect: float, period: float) -> HillSpectrum:
    mu = np.exp(lam * period)
    order = np.argsort(-np.abs(mu), kind="stable")
    return HillSpectrum(
        exponents=np.asarray(lam[order], dtype=np.complex128),
        multipliers=np.asarray(mu[order], dtype=np.complex128),
        centroid=np.asarray(kbar[order], dtype=np.float64),
        defect=defect,
    )
