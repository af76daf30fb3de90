"""A structure's frequency-response curve of exact periodic orbits, by shooting (MODEL.md 5.1).

Pseudo-arclength continuation (``clearjoint.continuation``) of R(z, w) = P(z; w) - z, the
exact one-period map of ``clearjoint.structure.orbit``: dR/dz = Phi - I is exact (the
monodromy), dR/dw is the central difference of P over w (1 +- 1e-7), asked once per step
(a chord in that one column: the corrector's convergence is judged on the exact residual,
so the chord costs iterations, never accuracy). Every point carries its Floquet
multipliers; the events are found between successive points as for harmonic balance
(folds where w turns back, period doublings where a multiplier passes -1, Neimark-Sacker
crossings where a complex pair leaves the unit circle, grazings where a joint's extreme
shortening passes a gap edge), and a change of the number of gap-edge events a period
tells the continuation that it crossed onto another smooth piece of the branch.
"""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from clearjoint import checks as _checks
from clearjoint.continuation import ContinuationSettings, continue_branch
from clearjoint.errors import ParameterError
from clearjoint.results import FrequencyResponse
from clearjoint.simulate.core import SimulationError
from clearjoint.structure.motion import _run, _system, _vector
from clearjoint.structure.orbit import periodic_orbit
from clearjoint.structure.poincare import (
    FloatArray,
    ShootingMap,
    sorted_multipliers,
    turning_extremes,
)
from clearjoint.structure.tangent import PatternFlows

#: Relative step of the central difference of P over w.
D_OMEGA = 1e-7
#: Samples a period along the curve (extremes refined by the local cubic: about 1e-4 of X
#: where a turning point lies near a gap edge; periodic_orbit samples 512 for 1e-9).
CURVE_SAMPLES = 64
#: Periods of the short transient that restarts Newton across a kink.
RESTART_PERIODS = 20


def frequency_response(
    structure: Any,
    force: ArrayLike,
    omega_start: float,
    omega_stop: float,
    *,
    initial: Any = None,
    max_points: int = 500,
    max_step: float = 0.02,
) -> FrequencyResponse:
    """Return the curve of exact period-1 orbits of a structure from omega_start to omega_stop.

    MODEL.md 5.1 on the structure of 5.2 (module docstring): stable and unstable orbits
    alike, through folds, with folds, period doublings, Neimark-Sacker crossings and
    grazings as ``events``.

    Parameters
    ----------
    structure : Structure or VibrationSystem
        Lumped mass; joints without friction; a restitution in (0, 1] (impacts' saltation
        matrices enter the monodromy).
    force : (N,) array_like
        Force amplitude per DOF, N.
    omega_start, omega_stop : float
        rad/s, > 0, different (either order).
    initial : (u0, v0), optional
        A state near the orbit at omega_start (default: see
        :func:`clearjoint.structure.periodic_orbit`).
    max_points : int
        Points on the curve at most, >= 2.
    max_step : float
        Largest arclength step (scaled: the range is 1).

    Returns
    -------
    FrequencyResponse
        ``method == "shooting"``; x_max, x_min, amplitude (n, N); multipliers (n, 2N);
        initial_state (n, 2N): u(0) then u'(0).

    Raises
    ------
    ParameterError
        A frequency not finite and positive, a range of zero width, bad max_points.
    OrbitError
        No periodic orbit at omega_start.
    """
    system = _system(structure)
    f = _vector("force", force, system)
    w0 = _checks.positive("omega_start", omega_start, unit="rad/s")
    w1 = _checks.positive("omega_stop", omega_stop, unit="rad/s")
    if w0 == w1:
        raise ParameterError(f"omega_start and omega_stop are equal ({w0!r} rad/s): no range")
    if isinstance(max_points, bool) or not isinstance(max_points, int) or max_points < 2:
        raise ParameterError(f"max_points must be an integer >= 2, got {max_points!r}")
    if not (isinstance(max_step, int | float) and 0.0 < max_step <= 1.0):
        raise ParameterError(f"max_step must be in (0, 1], got {max_step!r}")
    flows = PatternFlows(system, impacts=bool(np.any(system.restitution() < 1.0)))
    first = periodic_orbit(system, f, w0, initial=initial)
    n = system.n_dof
    b = system.directions
    rows = np.vstack((np.eye(n), b))
    maps: dict[float, ShootingMap] = {}

    def shooting_map(w: float) -> ShootingMap:
        found = maps.get(w)
        if found is None:
            if len(maps) > 8:
                maps.clear()
            found = maps[w] = ShootingMap(system, f, w, 1, flows)
        return found

    def residual(
        z: FloatArray, lam: float, with_lam: bool = True
    ) -> tuple[FloatArray, FloatArray, FloatArray | None, Any]:
        if not lam > 0.0:
            raise SimulationError(f"the frequency left the positive range ({lam!r} rad/s)")
        shoot = shooting_map(lam)
        end, phi, motion = shoot(z, CURVE_SAMPLES)
        d_lam = None
        if with_lam:
            up = shooting_map(lam * (1.0 + D_OMEGA)).run(z)
            down = shooting_map(lam * (1.0 - D_OMEGA)).run(z)
            d_lam = (np.concatenate(up.final_state) - np.concatenate(down.final_state)) / (
                2.0 * D_OMEGA * lam
            )
        # the DOFs' extremes and the joints' shortenings' in one pass over the samples
        top, bottom = turning_extremes(motion, system, f, rows)
        x_max, d_max, x_min, d_min = top[:n], top[n:], bottom[:n], bottom[n:]
        data = SimpleNamespace(
            events=motion.events,
            x_max=x_max,
            x_min=x_min,
            d_max=d_max,
            d_min=d_min,
            multipliers=sorted_multipliers(phi),
        )
        return end - z, phi - np.eye(2 * n), d_lam, data

    def restart(z: FloatArray, lam: float) -> FloatArray | None:
        shoot = shooting_map(lam)
        try:
            motion = _run(shoot.flow, z[:n], z[n:], RESTART_PERIODS * shoot.period, np.zeros(1))
        except SimulationError:
            return None
        return np.concatenate(motion.final_state)

    def differs(last: Any, new: Any) -> bool:
        return bool(last.events != new.events)

    z0 = np.concatenate(first.initial_state)
    x_scale = max(float(np.max(first.amplitude)), 1e-9)
    v_scale = x_scale * max(w0, w1)
    branch = continue_branch(
        residual,  # type: ignore[arg-type]  # chord_parameter: called with a third argument
        z0,
        w0,
        w1,
        u_scale=np.concatenate((np.full(n, x_scale), np.full(n, v_scale))),
        lam_scale=abs(w1 - w0),
        settings=ContinuationSettings(
            step=min(0.005, max_step),
            min_step=1e-7,
            max_step=max_step,
            max_points=max_points,
            tolerance=1e-10,
            chord_parameter=True,
        ),
        restart=restart,
        differs=differs,
    )
    data = branch.data
    omega = np.asarray(branch.lam, dtype=np.float64)
    x_max = np.array([d.x_max for d in data])
    x_min = np.array([d.x_min for d in data])
    amplitude = 0.5 * (x_max - x_min)
    multipliers = np.array([d.multipliers for d in data])
    stable = np.all(np.abs(multipliers) < 1.0, axis=1)
    peak = float(np.max(np.abs(f)))
    force_amplitude = np.full(omega.size, peak)
    law = system.law_arrays()
    model = SimpleNamespace(directions=b, g_c=law.g_c, g_t=law.g_t, is_joint=False)
    from clearjoint.harmonic.response import curve_events

    events = curve_events(
        model,  # type: ignore[arg-type]
        omega,
        multipliers,
        np.array([d.d_max for d in data]),
        np.array([d.d_min for d in data]),
        omega,
        force_amplitude,
        np.max(amplitude, axis=1),
    )
    return FrequencyResponse(
        omega=omega,
        force_amplitude=force_amplitude,
        x_max=x_max,
        x_min=x_min,
        amplitude=amplitude,
        stable=np.asarray(stable, dtype=bool),
        multipliers=multipliers,
        initial_state=np.asarray(branch.u, dtype=np.float64),
        events=events,
        parameter="omega",
        stop_reason=branch.reason,
        settings={"system": system, "force": f, "events_per_period": [d.events for d in data]},
        method="shooting",
        dof_names=system.dof_names,
    )
