"""The clearance joint's law, written once: force, tangent, potential, contact state.

MODEL.md section 0 and 5.2. At the relative displacement delta across the joint
(positive in compression), with free-play stiffness k0, contact stiffnesses k_c and
k_t and gap edges g_c (compression contact from delta = g_c) and g_t (tension contact
from delta = -g_t):

    f(delta) = k0 delta                          for -g_t <= delta <= g_c   (OPEN)
    f(delta) = k0 delta + k_c (delta - g_c)      for delta > g_c            (COMPRESSION)
    f(delta) = k0 delta + k_t (delta + g_t)      for delta < -g_t           (TENSION)

In each state the law is linear, f = K delta - offset, with (K, offset) = (k0, 0),
(k0 + k_c, k_c g_c) and (k0 + k_t, -k_t g_t): the sign convention of the event-driven
kernel (``region_force``) and of the structure's contact patterns (K_s u - r_s). At a
gap edge itself (a kink of f) the state is OPEN and the tangent is k0, unless a rate
is given: then the edge counts as the side the rate points to (:func:`contact_state`).

The scalar functions are compiled with numba so that the event-driven kernels call
them in their inner loops; numba compiles a callee into its caller and LLVM inlines
these small bodies, so a kernel runs as fast as with the law written out in it. The
array forms are compiled loops over the same scalar functions, so a numpy caller
(:class:`~clearjoint.ClearanceJoint`, harmonic balance's
:meth:`~clearjoint.harmonic.system.LinearSystem.joint_forces`, the structure's
tables) gets the same numbers bit for bit. The additive form of :func:`force`
(k0 delta + k_c (delta - g_c)) and the state form K delta - offset agree to round-off,
not bit for bit: each solver keeps the one it had.

numba's disk cache of a kernel does not notice a change to a function it calls in
another file: after editing this module, clear the ``__pycache__`` folders (or set
``NUMBA_CACHE_DIR`` to a fresh folder) before trusting the kernels.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np
from numpy.typing import NDArray

from clearjoint.jit import njit  # numba.njit that survives a read-only install
from clearjoint.laws import Law

FloatArray = NDArray[np.float64]

#: Contact states of a joint (the event-driven kernel calls OPEN its FREE region).
OPEN, COMPRESSION, TENSION = 0, 1, -1


# ---- one relative displacement (compiled, for the kernels) -------------------------------


@njit(cache=True)
def force(delta: float, k0: float, k_c: float, k_t: float, g_c: float, g_t: float) -> float:
    """Return the force f(delta) in N at relative displacement delta in m (MODEL.md sec. 0).

    Parameters
    ----------
    delta : float
        Relative displacement across the joint, m, positive in compression.
    k0, k_c, k_t : float
        Free-play and contact stiffnesses (compression, tension), N/m.
    g_c, g_t : float
        Distances from delta = 0 to the compression and the tension gap edge, m.
    """
    f = k0 * delta
    if delta > g_c:
        f += k_c * (delta - g_c)
    if delta < -g_t:
        f += k_t * (delta + g_t)
    return f


@njit(cache=True)
def tangent(delta: float, k0: float, k_c: float, k_t: float, g_c: float, g_t: float) -> float:
    """Return the tangent stiffness df/d(delta) in N/m; k0 at a gap edge (MODEL.md sec. 0)."""
    k = k0
    if delta > g_c:
        k += k_c
    if delta < -g_t:
        k += k_t
    return k


@njit(cache=True)
def force_and_tangent(
    delta: float, k0: float, k_c: float, k_t: float, g_c: float, g_t: float
) -> tuple[float, float]:
    """Return (f, df/d(delta)) in N and N/m: :func:`force` and :func:`tangent` at once."""
    return force(delta, k0, k_c, k_t, g_c, g_t), tangent(delta, k0, k_c, k_t, g_c, g_t)


@njit(cache=True)
def potential(delta: float, k0: float, k_c: float, k_t: float, g_c: float, g_t: float) -> float:
    """Return the stored energy V(delta) in J, the integral of f from 0 (MODEL.md sec. 0)."""
    v = 0.5 * k0 * delta**2
    if delta > g_c:
        v += 0.5 * k_c * (delta - g_c) ** 2
    if delta < -g_t:
        v += 0.5 * k_t * (delta + g_t) ** 2
    return v


@njit(cache=True)
def contact_force(delta: float, k_c: float, k_t: float, g_c: float, g_t: float) -> float:
    """Return the normal force on the pin in N, >= 0: f less its free-play spring k0 delta.

    MODEL.md sec. 0 and eq 14: k_c (delta - g_c) in compression contact, k_t (-g_t - delta)
    in tension contact, 0 in free-play.
    """
    if delta > g_c:
        return k_c * (delta - g_c)
    if delta < -g_t:
        return k_t * (-g_t - delta)
    return 0.0


@njit(cache=True)
def contact_state(delta: float, rate: float, g_c: float, g_t: float) -> int:
    """Return the contact state OPEN, COMPRESSION or TENSION of delta moving at ``rate``.

    MODEL.md sec. 0. Beyond an edge the state is that contact; exactly at an edge it
    is the side the rate d(delta)/dt points to (OPEN when the rate is 0 or points back
    into the gap).
    """
    if delta > g_c or (delta == g_c and rate > 0.0):
        return COMPRESSION
    if delta < -g_t or (delta == -g_t and rate < 0.0):
        return TENSION
    return OPEN


@njit(cache=True)
def state_law(
    state: int, k0: float, k_c: float, k_t: float, g_c: float, g_t: float
) -> tuple[float, float]:
    """Return (K, offset) of the law in one contact state: f = K delta - offset there.

    MODEL.md sec. 0: (k0 + k_c, k_c g_c) in COMPRESSION, (k0 + k_t, -k_t g_t) in
    TENSION, (k0, 0) otherwise (OPEN).
    """
    if state == COMPRESSION:
        return k0 + k_c, k_c * g_c
    if state == TENSION:
        return k0 + k_t, -k_t * g_t
    return k0, 0.0


# ---- arrays of samples (compiled loops over the functions above) -------------------------


@njit(cache=True)
def forces_and_tangents(
    delta: FloatArray,
    k0: FloatArray,
    k_c: FloatArray,
    k_t: FloatArray,
    g_c: FloatArray,
    g_t: FloatArray,
) -> tuple[FloatArray, FloatArray]:
    """Return f_j and df_j/d(delta) (N, N/m) for samples ``delta`` (N_t, n_j) of n_j laws.

    MODEL.md sec. 0 and 5.2. ``delta`` (N_t, n_j) in m; each law's parameters
    ``k0``, ``k_c``, ``k_t`` (N/m) and ``g_c``, ``g_t`` (m) are (n_j,) arrays. Both
    results have the shape of ``delta``.
    """
    f = np.empty_like(delta)
    k = np.empty_like(delta)
    for n in range(delta.shape[0]):
        for j in range(delta.shape[1]):
            f[n, j], k[n, j] = force_and_tangent(delta[n, j], k0[j], k_c[j], k_t[j], g_c[j], g_t[j])
    return f, k


@njit(cache=True)
def potentials(
    delta: FloatArray,
    k0: FloatArray,
    k_c: FloatArray,
    k_t: FloatArray,
    g_c: FloatArray,
    g_t: FloatArray,
) -> FloatArray:
    """Return V_j(delta) in J for samples ``delta`` (N_t, n_j) of n_j laws (MODEL.md sec. 0).

    Parameters as :func:`forces_and_tangents`; the result has the shape of ``delta``.
    """
    v = np.empty_like(delta)
    for n in range(delta.shape[0]):
        for j in range(delta.shape[1]):
            v[n, j] = potential(delta[n, j], k0[j], k_c[j], k_t[j], g_c[j], g_t[j])
    return v


@njit(cache=True)
def contact_forces(
    delta: FloatArray, k_c: FloatArray, k_t: FloatArray, g_c: FloatArray, g_t: FloatArray
) -> FloatArray:
    """Return the pin's normal force (N, >= 0, :func:`contact_force`) for samples (N_t, n_j)."""
    out = np.empty_like(delta)
    for n in range(delta.shape[0]):
        for j in range(delta.shape[1]):
            out[n, j] = contact_force(delta[n, j], k_c[j], k_t[j], g_c[j], g_t[j])
    return out


@njit(cache=True)
def contact_states(
    delta: FloatArray, rate: FloatArray, g_c: FloatArray, g_t: FloatArray
) -> NDArray[np.int8]:
    """Return each joint's contact state (:func:`contact_state`), (n_j,) int8.

    ``delta`` and ``rate`` (n_j,): relative displacements (m) and their rates (m/s).
    """
    states = np.zeros(delta.size, dtype=np.int8)
    for j in range(delta.size):
        states[j] = contact_state(delta[j], rate[j], g_c[j], g_t[j])
    return states


@njit(cache=True)
def state_tables(
    k0: FloatArray, k_c: FloatArray, k_t: FloatArray, g_c: FloatArray, g_t: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Return each law's stiffness K and offset in every state, two (n_j, 3) arrays.

    Column ``state + 1``: TENSION, OPEN, COMPRESSION; f = K delta - offset in that state
    (:func:`state_law`).
    """
    stiffness = np.zeros((k0.size, 3))
    offset = np.zeros((k0.size, 3))
    for j in range(k0.size):
        for state in (TENSION, OPEN, COMPRESSION):
            stiffness[j, state + 1], offset[j, state + 1] = state_law(
                state, k0[j], k_c[j], k_t[j], g_c[j], g_t[j]
            )
    return stiffness, offset


def parameters(
    laws: Iterable[Law],
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
    """Return (k0, k_c, k_t, g_c, g_t) of the laws, five (n_j,) arrays in N/m and m.

    The arguments the array forms take after the samples.
    """
    laws = tuple(laws)
    return (
        np.array([law.gap_stiffness for law in laws], dtype=np.float64),
        np.array([law.compression_stiffness for law in laws], dtype=np.float64),
        np.array([law.tension_stiffness for law in laws], dtype=np.float64),
        np.array([law.compression_gap for law in laws], dtype=np.float64),
        np.array([law.tension_gap for law in laws], dtype=np.float64),
    )
