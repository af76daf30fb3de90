"""Exact periodic orbits of a structure, seeded and closed by shooting (MODEL.md 5.1, 5.2).

:func:`periodic_orbit` closes an orbit by Newton on the exact p-period map with its exact
Jacobian (``clearjoint.structure.poincare``). Newton starts, by default, from the
harmonic-balance orbit at that frequency (H = 7, ``clearjoint.harmonic``: Newton on its
residual from the open and the closed linear responses), else from ``initial``, else from
the end of a transient from rest, and last from harmonic balance's whole start (its force
homotopy). An orbit that does not close is an error, never a result.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from clearjoint import checks as _checks
from clearjoint.errors import ParameterError
from clearjoint.structure.motion import _initial, _run, _system, _vector
from clearjoint.structure.poincare import (
    FloatArray,
    OrbitError,
    ShootingMap,
    StructureOrbit,
    newton_orbit,
    orbit_at,
)
from clearjoint.system import VibrationSystem

__all__ = ["OrbitError", "StructureOrbit", "harmonic_seed", "periodic_orbit"]

#: Periods of the transient from rest that seeds Newton when nothing else does.
TRANSIENT_PERIODS = 200
#: Harmonics of the harmonic-balance seed.
SEED_HARMONICS = 7


def _state_of(coefficients: Any, h: int, n: int, omega: float) -> FloatArray:
    """(u(0), u'(0)) of the HB coefficients a_0, a_1, b_1, ..., a_H, b_H ((2H + 1) N,)."""
    coef = np.asarray(coefficients, dtype=np.float64).reshape(2 * h + 1, n)
    u0 = coef[0] + coef[1::2].sum(axis=0)
    v0 = omega * (np.arange(1, h + 1)[:, None] * coef[2::2]).sum(axis=0)
    return np.concatenate((u0, v0))


def harmonic_seed(
    system: VibrationSystem, force: FloatArray, omega: float, *, homotopy: bool = False
) -> FloatArray | None:
    """The state (u, v) at phase 0 of a harmonic-balance orbit at ``omega`` (H = 7), or None.

    Newton on the HB residual from the open and the closed linear responses (the cheap
    part of ``clearjoint.harmonic``'s start); with ``homotopy`` its whole start, the
    force homotopy included (seconds on a small chain).
    """
    from clearjoint.harmonic import aft
    from clearjoint.harmonic.response import linear_start, start_coefficients
    from clearjoint.harmonic.system import HarmonicError, build

    try:
        model = build(system, None)
        h, n_t = aft.check_harmonics(SEED_HARMONICS, None)
        basis = aft.Basis.make(h, n_t)
    except (HarmonicError, ParameterError):
        return None
    failures = (HarmonicError, np.linalg.LinAlgError, ValueError)
    q: FloatArray | None
    try:
        if homotopy:
            q = start_coefficients(model, basis, omega, force)
        else:
            k_ref = model.reference_stiffness
            q = linear_start(
                model, basis, omega, force, k_ref, max_iterations=30, tolerate=failures
            )
    except failures:
        return None
    return None if q is None else _state_of(q, h, system.n_dof, omega)


def _seeds(
    shoot: ShootingMap, initial: Any, use_harmonic: bool
) -> list[tuple[str, FloatArray | None]]:
    """The seeds to try, in order, as (name, z or None to be computed lazily)."""
    if initial is not None:
        u0, v0 = _initial(shoot.system, initial)
        return [("initial", np.concatenate((u0, v0)))]
    out: list[tuple[str, FloatArray | None]] = []
    if use_harmonic and shoot.p == 1:
        out.append(("harmonic balance", None))
    out.append(("transient", None))
    if use_harmonic and shoot.p == 1:
        out.append(("harmonic balance, from a force homotopy", None))
    return out


def _transient(shoot: ShootingMap, z: FloatArray | None = None) -> FloatArray:
    """The state at phase 0 after ``TRANSIENT_PERIODS`` periods from z (rest by default)."""
    start = np.zeros(2 * shoot.n) if z is None else z
    times = np.zeros(1)
    motion = _run(
        shoot.flow, start[: shoot.n], start[shoot.n :], TRANSIENT_PERIODS * shoot.period, times
    )
    return np.concatenate(motion.final_state)


def _floor(shoot: ShootingMap) -> float:
    """A size below which an orbit counts as zero: the gaps times w (m/s)."""
    gaps = np.concatenate((shoot.flow.g_c, shoot.flow.g_t))
    gaps = gaps[np.isfinite(gaps) & (gaps > 0)]
    return float(shoot.omega * (np.min(gaps) if gaps.size else 1e-6)) * 1e-3


def _check_period_multiple(period_multiple: int) -> int:
    if (
        isinstance(period_multiple, bool)
        or not isinstance(period_multiple, int | np.integer)
        or period_multiple < 1
    ):
        raise ParameterError(f"period_multiple must be an integer >= 1, got {period_multiple!r}")
    return int(period_multiple)


def periodic_orbit(
    structure: Any,
    force: ArrayLike,
    omega: float,
    *,
    period_multiple: int = 1,
    initial: Any = None,
) -> StructureOrbit:
    """Return the exact periodic orbit of ``structure`` under F sin(omega t), with its stability.

    MODEL.md 5.1 on the structure of 5.2: Newton on the exact p-period map with its exact
    Jacobian (module docstring).

    Parameters
    ----------
    structure : Structure or VibrationSystem
        Lumped (diagonal) mass; joints without friction. A restitution below 1 (but above
        0) is carried: each impact's saltation matrix enters the monodromy.
    force : (N,) array_like
        Force amplitude per DOF, N.
    omega : float
        rad/s, > 0.
    period_multiple : int
        p >= 1: seek an orbit that closes after p forcing periods.
    initial : (u0, v0), optional
        Newton's start (each (N,), m and m/s). Default: the harmonic-balance orbit at
        omega (p = 1), then the end of a transient from rest.

    Returns
    -------
    StructureOrbit

    Raises
    ------
    StructureError
        A force or initial vector of the wrong length, friction, a restitution of 0.
    ParameterError
        omega not finite and positive, period_multiple not an integer >= 1.
    OrbitError
        Newton converged from none of the seeds.
    """
    system = _system(structure)
    f = _vector("force", force, system)
    w = _checks.positive("omega", omega, unit="rad/s")
    p = _check_period_multiple(period_multiple)
    shoot = ShootingMap(system, f, w, p)
    floor = _floor(shoot)
    tried: list[str] = []
    for name, z0 in _seeds(shoot, initial, use_harmonic=True):
        if z0 is None:
            if name == "transient":
                z0 = _transient(shoot)
            else:
                z0 = harmonic_seed(system, f, w, homotopy=name != "harmonic balance")
            if z0 is None:
                tried.append(f"{name} (no solution)")
                continue
        found = newton_orbit(shoot, z0, floor)
        if found is not None:
            z, phi, closure, iterations = found
            return orbit_at(shoot, z, phi, closure, iterations, name)
        tried.append(name)
    raise OrbitError(
        f"no periodic orbit of period {p} converged at {w / (2 * math.pi):.6g} Hz from "
        f"{', '.join(tried)}; the motion there may not be periodic: run "
        "clearjoint.structure.stepped_sine to see what it does, or pass initial="
    )
