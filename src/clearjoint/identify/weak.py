"""The clearance joint's parameters from the cycle average by a weak (integral) form.

MODEL.md section 3: in each stage s of a branch (rising, falling) the record obeys

    m x'' + a_s + k_s x + c x' + F_f sgn(x') = F(t)

(k_s: the slope the structure shows in stage s, tension / free play / compression).
Multiplying by a test function phi(t) that vanishes with its first derivative at both
ends of the stage's time span and integrating by parts moves every derivative onto phi:

    m int(phi'' x) + a_s int(phi) + k_s int(phi x) - c int(phi' x) + F_f sgn int(phi) = int(phi F)

so no derivative of the measured displacement is ever taken (the displacement enters
only through integrals, which average its noise), and the test functions stop at the
contact instants instead of smearing across them. Several test functions per stage
(a bump t^2 (1 - t)^2 times Legendre polynomials) give an over-determined linear system
in (a_s, k_s, c, F_f[, m]), solved by least squares. With a measured acceleration,
int(phi a) replaces int(phi'' x). When the record has no mass (force control), m is
one more unknown.

Everything but the friction term is linear in the data, so the same equations, built
once, solve every jackknife replicate (the average without one group of cycles) in one
batched solve. The friction term's weights int(phi sgn x') are not: they follow the sign
of the velocity, which the noise flips near each reversal. Each replicate therefore takes
them from its own velocity (:meth:`WeakSystem.friction_of`), so the jackknife's spread
carries the sign's noise too; with the average's sign shared by every replicate it did
not, and the friction's standard error came out 1.9-2.6 times too small over noise draws
(docs/identify.md, "The number of cycles").
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from numpy.polynomial import Polynomial

FloatArray = NDArray[np.float64]

#: Width (samples) of the sliding test functions, their stride, and the orders at each place
#: (a run shorter than WIDTH gets one place as wide as itself).
WIDTH = 12
STRIDE = 2
ORDERS = 2
#: Fewest samples a stage needs to carry test functions.
MIN_STAGE_SAMPLES = 8


@functools.cache
def _bases(order: int) -> list[tuple[Polynomial, Polynomial, Polynomial]]:
    """phi_q(tau) = tau^2 (1 - tau)^2 P_q(2 tau - 1) and its two derivatives, q < order.

    Built on first use: records that never reach the weak form (the BRFD damper loops)
    do not import numpy.polynomial.
    """
    from numpy.polynomial import Legendre, Polynomial

    bump = Polynomial([0.0, 0.0, 1.0, -2.0, 1.0])
    out = []
    for q in range(order):
        legendre = Legendre.basis(q).convert(kind=Polynomial)(Polynomial([-1.0, 2.0]))
        phi = bump * legendre
        out.append((phi, phi.deriv(), phi.deriv(2)))
    return out


@dataclass(frozen=True)
class WeakSystem:
    """The weights of every equation over the samples it covers.

    ``columns`` (E, K): the samples of the cycle each equation covers (K = WIDTH + 1,
    padded with zero weights); ``phi, dphi, ddphi`` (E, K): the weights of int(phi .),
    int(phi' .), int(phi'' .) on them;
    ``stage`` (E,) the stage of each equation (0 tension, 1 free play, 2 compression);
    ``friction`` (E,) int(phi sgn x'), from the cycle average's velocity sign.
    """

    columns: NDArray[np.int64]
    phi: FloatArray
    dphi: FloatArray
    ddphi: FloatArray
    stage: NDArray[np.int64]
    friction: FloatArray

    def integrals(self, data: FloatArray, weights: FloatArray) -> FloatArray:
        """int(weights . data) of every equation for every row of ``data`` (R, M): (R, E)."""
        out: FloatArray = np.sum(data[:, self.columns] * weights[None, :, :], axis=2)
        return out

    def friction_of(self, velocity: FloatArray) -> FloatArray:
        """int(phi sgn v) of every equation for every row of ``velocity`` (R, M): (R, E)."""
        return self.integrals(np.sign(np.atleast_2d(velocity)), self.phi)


def _simpson(intervals: int, step: float) -> FloatArray:
    """Composite Simpson weights over ``intervals`` + 1 samples (3/8 rule on the last
    three intervals when their count is odd): the ringing after an impact has only about
    ten samples per period, where trapezoids would cost percents."""
    n = intervals
    w = np.zeros(n + 1)
    even = n if n % 2 == 0 else n - 3
    if even >= 2:
        w[: even + 1 : 2] += 2.0 / 3.0
        w[1:even:2] += 4.0 / 3.0
        w[0] -= 1.0 / 3.0
        w[even] -= 1.0 / 3.0
    if n % 2 == 1:
        w[even : even + 4] += np.array([3.0, 9.0, 9.0, 3.0]) / 8.0
    return w * step


@functools.lru_cache(maxsize=64)
def _shapes(width: int, step: float) -> FloatArray:
    """(ORDERS, 3, width + 1): Simpson weight times phi, phi' and phi'' of each order."""
    tau = np.arange(width + 1) / width
    length = width * step
    weight = _simpson(width, step)
    return np.array(
        [
            [weight * phi(tau), weight * dphi(tau) / length, weight * ddphi(tau) / length**2]
            for phi, dphi, ddphi in _bases(ORDERS)
        ]
    )


def stage_runs(
    x: FloatArray, edges: tuple[float, float], margin: float
) -> list[tuple[int, int, int]]:
    """Runs of the periodic cycle ``x`` (M,) that stay in one stage, as (first, last, stage).

    Stage 0 below ``lower - margin`` (tension), 1 between ``lower + margin`` and
    ``upper - margin`` (free play), 2 above ``upper + margin`` (compression); samples
    within ``margin`` of an edge belong to no run, so every run ends before a contact
    instant. A run that wraps round the end of the cycle is kept whole.
    """
    lower, upper = edges
    label = np.full(x.size, -1)
    label[x < lower - margin] = 0
    label[(x > lower + margin) & (x < upper - margin)] = 1
    label[x > upper + margin] = 2
    change = np.nonzero(label != np.roll(label, 1))[0]
    if change.size == 0:
        return [(0, x.size - 1, int(label[0]))] if label[0] >= 0 else []
    runs = []
    for k, first in enumerate(change):
        nxt = change[(k + 1) % change.size]
        last = (nxt - 1) if nxt > first else (nxt - 1 + x.size)
        if label[first] >= 0:
            runs.append((int(first), int(last), int(label[first])))
    return runs


def weak_system(
    x_mean: FloatArray,
    velocity: FloatArray,
    step: float,
    runs: list[tuple[int, int, int]],
) -> WeakSystem | None:
    """Build the test-function weights of every run (first, last, stage) of the cycle.

    ``x_mean`` and ``velocity`` (M,) are the cycle average and its velocity (only its
    sign is used, for the friction term). Runs shorter than ``MIN_STAGE_SAMPLES`` carry
    no test function; returns None when a stage has none at all.
    """
    m = x_mean.size
    k = WIDTH + 1
    columns: list[NDArray[np.int64]] = []
    shapes_all: list[FloatArray] = []
    stages: list[int] = []
    for first, last, s in runs:
        if last - first + 1 < MIN_STAGE_SAMPLES:
            continue
        width = min(WIDTH, last - first)
        shapes = np.zeros((ORDERS, 3, k))
        shapes[:, :, : width + 1] = _shapes(width, step)
        for start in range(first, last - width + 1, STRIDE):
            cols = np.zeros(k, dtype=np.int64)
            cols[: width + 1] = np.arange(start, start + width + 1) % m
            for order in range(ORDERS):
                columns.append(cols)
                shapes_all.append(shapes[order])
                stages.append(s)
    if set(stages) != {0, 1, 2}:
        return None
    block = np.array(shapes_all)
    cols_arr = np.array(columns)
    sign = np.sign(velocity)
    return WeakSystem(
        cols_arr,
        block[:, 0],
        block[:, 1],
        block[:, 2],
        np.array(stages, dtype=np.int64),
        np.sum(sign[cols_arr] * block[:, 0], axis=1),
    )


@dataclass(frozen=True)
class WeakFit:
    """Coefficients per replicate: lines (R, 3, 2) as (intercept, slope) of tension,
    free play and compression; drag c, friction F_f and mass m (R,); rms equation
    residual (R,), N; the equation residuals of replicate 0 (E,), N, which
    :func:`clearjoint.identify.loopcheck.weak_residual` reads against its noise floor."""

    lines: FloatArray
    drag: FloatArray
    friction: FloatArray
    mass: FloatArray
    residual: FloatArray
    equations: FloatArray


def weak_fit(
    system: WeakSystem,
    x: FloatArray,
    force: FloatArray,
    *,
    mass: float | None,
    acceleration: FloatArray | None = None,
    velocity: FloatArray | None = None,
) -> WeakFit:
    """Solve the weak-form equations for every replicate (row) of ``x`` and ``force`` (R, M).

    ``mass`` None makes m an unknown; ``acceleration`` (R, M), when measured, gives the
    inertia integrals instead of int(phi'' x); ``velocity`` (R, M), each replicate's own,
    gives its friction term's sign (without it every replicate takes the system's, the
    sign of the velocity it was built with).
    """
    x2 = np.atleast_2d(x)
    f2 = np.atleast_2d(force)
    phi = system.phi
    i0 = phi.sum(axis=1)  # (E,)
    scale = np.abs(phi).sum(axis=1)
    i1 = system.integrals(x2, phi)  # (R, E)
    ic = -system.integrals(x2, system.dphi)
    inertia = (
        system.integrals(np.atleast_2d(acceleration), phi)
        if acceleration is not None
        else system.integrals(x2, system.ddphi)
    )
    rhs = system.integrals(f2, phi)
    r, e = i1.shape
    p = 6 + 2 + (1 if mass is None else 0)
    design = np.zeros((r, e, p))
    rows = np.arange(e)
    design[:, rows, 2 * system.stage] = i0
    design[:, rows, 2 * system.stage + 1] = i1
    design[:, :, 6] = ic
    design[:, :, 7] = system.friction if velocity is None else system.friction_of(velocity)
    if mass is None:
        design[:, :, 8] = inertia
    else:
        rhs = rhs - mass * inertia
    design /= scale[None, :, None]
    rhs = rhs / scale[None, :]
    transposed = design.transpose(0, 2, 1)
    gram = transposed @ design
    coef = np.linalg.solve(gram, transposed @ rhs[..., None])[..., 0]
    residual = rhs - (design @ coef[..., None])[..., 0]
    rms = np.sqrt(np.mean(residual**2, axis=1))
    lines = coef[:, :6].reshape(r, 3, 2)
    m_hat = coef[:, 8] if mass is None else np.full(r, float(mass))
    return WeakFit(lines, coef[:, 6], coef[:, 7], m_hat, rms, residual[0])
