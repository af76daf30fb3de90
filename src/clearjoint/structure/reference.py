"""Reference path for structures: solve_ivp with event location on every gap edge.

Slow but independent of the pattern flows and certified marching of ``motion``: the
equation of motion of MODEL.md 5.2 is integrated numerically (DOP853) with each
joint's force f_j(b_j^T u) taken from its law directly; solve_ivp locates every gap
edge as a terminal event, where restitution is applied and the integration restarts
(so no step straddles a kink). Used by the tests and ``benchmarks/bench_structure.py``.
The joints' law is written out here on purpose, not taken from
:mod:`clearjoint.laws.clearance`: this is the independent route the tests check against.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.integrate import solve_ivp

from clearjoint.structure.model import Structure
from clearjoint.structure.motion import _initial, _vector

FloatArray = NDArray[np.float64]


def reference_response(
    structure: Structure,
    force: ArrayLike,
    omega: float,
    times: ArrayLike,
    *,
    initial: Any = None,
    rtol: float = 1e-12,
    atol: float = 1e-15,
    max_step: float = math.inf,
) -> tuple[FloatArray, FloatArray, int]:
    """Return (u, v, events) at ``times`` (s, sorted, from 0) by solve_ivp with edge events.

    ``u`` and ``v`` are (n, N); ``events`` counts the gap edges crossed. solve_ivp sees an
    event only as a sign change between its steps, so two crossings within one step (a
    brief, grazing contact) go unseen; ``max_step`` (s) narrows that window.
    """
    s = structure
    n = s.n_dof
    f = _vector("force", force, s)
    u0, v0 = _initial(s, initial)
    m = s.mass_diagonal()
    c = s.damping_matrix()
    b = s.joint_directions
    laws = s.joint_laws
    plain = [i for i, mem in enumerate(s.members) if mem.joint is None]
    bm = s.member_directions[plain]
    k_lin = (bm.T * s._k_member[plain]) @ bm
    m_eff = 1.0 / np.einsum("jn,jn->j", b, b / m)
    t_out = np.asarray(times, dtype=np.float64)
    t_end = float(t_out[-1])

    k0 = np.array([law.gap_stiffness for law in laws])
    kc = np.array([law.compression_stiffness for law in laws])
    kt = np.array([law.tension_stiffness for law in laws])
    gc = np.array([law.compression_gap for law in laws])
    gt = np.array([law.tension_gap for law in laws])

    def rhs(t: float, z: FloatArray) -> FloatArray:
        u, v = z[:n], z[n:]
        delta = b @ u
        joint_force = (
            k0 * delta + kc * np.maximum(delta - gc, 0.0) + kt * np.minimum(delta + gt, 0.0)
        )
        acc = (f * math.sin(omega * t) - c @ v - k_lin @ u - b.T @ joint_force) / m
        return np.concatenate((v, acc))

    edges = [(j, side) for j in range(len(laws)) for side in (1, -1)]

    def crossing(which: int, direction: float) -> Any:
        j, side = edges[which]
        edge = gc[j] if side == 1 else -gt[j]

        def event(t: float, z: FloatArray) -> float:
            return float(b[j] @ z[:n]) - float(edge)

        event.terminal = True  # type: ignore[attr-defined]
        event.direction = direction  # type: ignore[attr-defined]
        return event

    z = np.concatenate((u0, v0))
    # which side of each edge the motion is on: +1 above (next crossing is downward)
    above = [
        (1.0 if float(b[j] @ u0) - (gc[j] if side == 1 else -gt[j]) >= 0.0 else -1.0)
        for j, side in edges
    ]
    t = 0.0
    u_out = np.zeros((t_out.size, n))
    v_out = np.zeros((t_out.size, n))
    count = 0
    while t < t_end:
        active = [crossing(i, -above[i]) for i in range(len(edges))]
        sol = solve_ivp(
            rhs,
            (t, t_end),
            z,
            method="DOP853",
            rtol=rtol,
            atol=atol,
            events=active,
            dense_output=True,
            max_step=max_step,
        )
        t_stop = float(sol.t[-1])
        inside = (t_out >= t) & (t_out <= t_stop)
        if inside.any():
            zs = sol.sol(t_out[inside])
            u_out[inside] = zs[:n].T
            v_out[inside] = zs[n:].T
        z = sol.y[:, -1].copy()
        if sol.status != 1:
            break
        which = next(k for k, te in enumerate(sol.t_events) if te.size)
        j, side = edges[which]
        above[which] = -above[which]
        count += 1
        rate = float(b[j] @ z[n:])
        entering = rate * side > 0.0
        e = laws[j].restitution
        if entering and e < 1.0:
            z[n:] -= (1.0 - e) * rate * m_eff[j] * b[j] / m
        t = t_stop
    return u_out, v_out, count
