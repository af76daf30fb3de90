"""Frequency-response curves by harmonic balance with pseudo-arclength continuation (MODEL.md 5.3).

The HB residual (:mod:`clearjoint.harmonic.aft`) is followed in w (or in the force
amplitude) by the same continuation as the exact shooting of
:mod:`clearjoint.periodic`, and returned as the same
:class:`~clearjoint.results.FrequencyResponse`, with the harmonic coefficients
kept. Stability (``stability``): for one DOF with constant damping from Hill's infinite
determinant (one determinant per point); for a Joint with friction from Hill's quadratic
eigenproblem with the centroid sorting (:mod:`clearjoint.harmonic.hill`); for a Structure
by default from the exact monodromy of the HB orbit's piecewise-linear linearisation
(:mod:`clearjoint.harmonic.monodromy`), integrated when its joints carry friction
(:func:`~clearjoint.harmonic.monodromy.integrated_monodromy`), since Hill's truncated
eigenproblem disagrees with it on stiff contact (docs/harmonic.md, "Stability");
``stability="hill"`` asks for Hill's method anyway. Events are located as in
:mod:`clearjoint.periodic`: folds where the parameter component of the tangent
changes sign, period doublings where prod(1 + mu) changes sign (a multiplier
through -1), Neimark-Sacker crossings where the largest modulus among the complex
multipliers crosses 1, grazings where a joint's extreme relative displacement crosses a
gap edge.
"""

from __future__ import annotations

import dataclasses
import logging
import math
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from clearjoint import checks as _checks
from clearjoint.continuation import ContinuationSettings, continue_branch, parameter_range
from clearjoint.errors import ClearjointError, ParameterError
from clearjoint.harmonic import aft, check, hill, monodromy, solve
from clearjoint.harmonic.solve import (
    TOLERANCE,
    SparseResidual,
    linear_guess,
    newton,
)
from clearjoint.harmonic.system import (
    HarmonicError,
    LinearSystem,
    build,
    check_size,
    force_vector,
    friction_speed,
    scale_length,
)
from clearjoint.joint import Losses, takes_losses
from clearjoint.progress import silenced
from clearjoint.results import FrequencyResponse, ResponseEvent

FloatArray = NDArray[np.float64]

#: Progress of slow steps (the start's force continuation), at INFO; ``clearjoint frf``
#: prints it on stderr.
LOGGER = logging.getLogger("clearjoint.harmonic")

#: The start's force continuation takes at most this many unknown-points (points times
#: unknowns), between ``START_POINTS`` (400 and 2000) points. The example mast at 20 N and
#: H = 15 (1240 unknowns, 387 points, no orbit to reach) gives up after about 60 s on 2
#: cores (docs/harmonic.md). The floor of 400 is for the large masts, whose homotopy needs
#: more points as they grow (the 40-bay mast at H = 7, 2400 unknowns: 102 points; the
#: budget alone gave it 200 and the 80-bay mast 100, too few: issue 25).
START_BUDGET = 480_000
START_POINTS = (400, 2000)

#: On the sparse path, Newton from a linear response is given up when its residual has
#: not halved in this many iterations (solve.newton's ``stall``): on the 20- and 40-bay
#: masts at 0.8 x the first open mode both guesses stall at 1e-6 to 1e-4 within 5
#: iterations and used to run all 80, 7 s of the 40-bay start's 29 s.
START_STALL = 10

#: The start's force continuation follows its path to this scaled residual, not to the
#: curve's ``TOLERANCE``: only its end is kept, and Newton at the full force polishes that
#: to ``TOLERANCE`` (:func:`_newton_at`). Each path point then takes one or two corrector
#: iterations instead of four, the steps grow, and the 40-bay mast's homotopy takes 32
#: points instead of 102 (issue 25: its start from 7.7 s to 2.2 s, by
#: ``benchmarks/bench_scale.py --bays 40:30``). If the polish fails, or the path does not
#: reach the full force (its larger steps can lose a path the tight one follows), or it
#: turns back in the force anywhere (a fold, where its larger steps may cross to another
#: branch: on examples/chain.toml's chain at 10 N and 50 Hz it ended on an orbit 32 %
#: from the tight path's), the path is followed again at ``TOLERANCE``, as before. Only on
#: the sparse route (more than ``solve.SPARSE_ABOVE`` unknowns), where the start's cost
#: is the homotopy's: a small structure's path is cheap, and folds often (examples/chain.toml's
#: chain and the 3-bay mast: in 33 of the 35 starts where the loose path reached the force),
#: so it follows the tight path alone, as before.
START_TOLERANCE = 1e-7


class NoPeriodicResponse(HarmonicError):
    """No HB solution was found at the start of a curve (the message says how far the
    force continuation got and what to try).

    Attributes
    ----------
    omega : float
        The start frequency, rad/s.
    reached : float
        The fraction of the force the start's force continuation reached (0 if it was
        not tried).
    """

    def __init__(self, message: str, omega: float, reached: float) -> None:
        super().__init__(message)
        self.omega = omega
        self.reached = reached


@takes_losses
def frequency_response(
    system: Any,
    force: float | ArrayLike,
    omega_start: float,
    omega_stop: float | None,
    *,
    harmonics: int = 7,
    samples: int | None = None,
    losses: Losses | None = None,
    parameter: Literal["omega", "force"] = "omega",
    force_stop: float | None = None,
    max_points: int = 2000,
    max_step: float = 0.02,
    friction_regularization: float | None = None,
    check_points: int = 5,
    stability: Literal["hill", "monodromy"] | None = None,
) -> FrequencyResponse:
    """Return the frequency-response curve by harmonic balance and continuation (MODEL.md 5.3).

    The periodic response to F sin(w t), truncated to ``harmonics`` harmonics plus
    the mean, followed by pseudo-arclength continuation from ``omega_start`` to
    ``omega_stop`` through folds, stable and unstable alike (Hill's method). With
    ``parameter="force"`` it continues in the force amplitude from ``force`` to
    ``force_stop`` at the fixed ``omega_start``.

    Parameters
    ----------
    system : Joint or Structure
    force : float or (N,) array_like
        F0 > 0 in N for a Joint; the amplitude per DOF (N,) in N for a Structure
        (with ``parameter="force"`` the curve scales this pattern, and
        ``force_amplitude`` is its largest entry).
    omega_start, omega_stop : float
        rad/s, either order.
    harmonics : int
        H >= 1.
    samples : int, optional
        N_t time samples per period for AFT, >= 2 (2H + 1); default 32 (2H + 1)
        rounded up to a power of two (fewer samples leave the sampled law's kinks
        visible as small zigzags of the curve near a fold).
    losses : Losses, optional
        A Joint's losses (a Structure or VibrationSystem carries its own): the damping
        ratio zeta of its linear part, c_v = 2 zeta sqrt(m k_c), and Coulomb friction over
        its whole path (region "everywhere"), regularised as mu_s P tanh(v / v_eps); its
        error against the exact stick-slip orbits of :mod:`clearjoint.periodic` is in
        docs/harmonic.md. Friction over the free-play stroke only is refused, and so is
        restitution below 1 (impacts need :func:`clearjoint.periodic.frequency_response`).
        A Structure carries its joints' own friction (rigid members only) the same way,
        on each joint's relative speed: against exact stick-slip orbits the amplitude is
        off by about 1e-3 while the joints slide and by about 12 % where they stick;
        points where a joint sticks get an ``"untrusted"`` event (docs/harmonic.md).
        The pin and its contact friction coefficient are not used: the exact solvers
        evaluate that friction along a cycle without feedback on the motion (MODEL.md
        sec. 2), so it does not change the orbit.
    parameter : {"omega", "force"}
    force_stop : float, optional
        End of the force range, N (largest entry for a Structure).
    max_points : int
        Largest number of points on the curve.
    max_step : float
        Largest arclength step in scaled coordinates (smaller: more points).
    friction_regularization : float, optional
        v_eps in m/s; default 1e-3 * omega_start * c (c the joint's clearance; for a
        Structure the largest clearance of its joints with friction).
    check_points : int
        Structures only: this many points, spread evenly along the curve, are run
        through one period of the exact motion
        (:func:`clearjoint.harmonic.check.check_orbits`); each whose orbit misses by
        more than the tolerance gets an ``"untrusted"`` event (its stability verdict
        is not to be trusted), and the whole check is in ``settings["orbit_check"]``.
        Every point harmonic balance calls stable is then confirmed or refuted by the
        exact motion (:func:`clearjoint.harmonic.check.confirm_stable`): ``stable`` is
        True only where confirmed, harmonic balance's own verdict is kept in
        ``settings["harmonic_stable"]``, the check in ``settings["stability_check"]``,
        and each run of refuted points gets an ``"untrusted"`` event saying what the
        exact motion does. 0 skips both checks (``stable`` is then harmonic balance's
        verdict alone); they are skipped when a joint has friction, which the exact
        structure motion does not carry.
    stability : {"hill", "monodromy"}, optional
        How the Floquet multipliers are found. ``"hill"``: Hill's method (the
        infinite determinant for one DOF without friction, else the quadratic
        eigenproblem with centroid sorting, :func:`clearjoint.harmonic.hill.spectrum`;
        a point where it finds fewer than 2N resolved exponents gets NaN multipliers
        and an ``"untrusted"`` event; for a Structure each point is also checked
        against the exact monodromy of its orbit, and one whose verdict differs gets
        an ``"untrusted"`` event; ``settings["hill_defect"]`` holds each point's
        shift defect). ``"monodromy"``: the exact monodromy of the HB orbit's
        linearisation (:mod:`clearjoint.harmonic.monodromy`). Default: ``"hill"`` for
        a Joint, ``"monodromy"`` for a Structure (on a 2-bay mast with stiff contact
        Hill's method at H = 7 and 15 gives the other verdict at several points;
        docs/harmonic.md, "Stability").

    Returns
    -------
    FrequencyResponse
        ``method == "harmonic"``; ``coefficients`` holds the harmonic coefficients,
        (n, 2H + 1) for a Joint and (n, 2H + 1, N) for a Structure, rows a_0, a_1,
        b_1, ..., a_H, b_H in m. For a Structure ``x_max``, ``x_min``,
        ``amplitude`` are (n, N), ``multipliers`` (n, 2N) and ``initial_state``
        (n, 2N): u(0) then u'(0).

    Raises
    ------
    HarmonicError
        Bad harmonics or samples, friction or restitution, no solution at the start.
    ParameterError
        A range of zero width, a value not finite and positive, a force of the wrong shape.
    """
    if parameter not in ("omega", "force"):
        raise ParameterError(f"parameter must be 'omega' or 'force', got {parameter!r}")
    h, n_t = aft.check_harmonics(harmonics, samples)
    w0 = _checks.positive("omega_start", omega_start, unit="rad/s")
    model = build(system, losses, friction_speed(system, w0, friction_regularization))
    pattern = force_vector(model, force)
    peak = float(np.max(np.abs(pattern)))
    start, stop = parameter_range(parameter, peak, w0, omega_stop, force_stop)
    unit_force = pattern / peak
    if isinstance(max_points, bool) or not isinstance(max_points, int) or max_points < 2:
        raise ParameterError(f"max_points must be an integer >= 2, got {max_points!r}")
    if isinstance(check_points, bool) or not isinstance(check_points, int) or check_points < 0:
        raise ParameterError(f"check_points must be an integer >= 0, got {check_points!r}")
    if stability not in (None, "hill", "monodromy"):
        raise ParameterError(
            f"stability must be 'hill' or 'monodromy' (or None for the default), got {stability!r}"
        )
    check_size(model.n_dof, h, lambda k: aft.check_harmonics(k, samples)[1])
    basis = aft.Basis.make(h, n_t)
    k_ref = model.reference_stiffness

    def at(lam: float) -> tuple[float, FloatArray]:
        if parameter == "omega":
            return lam, pattern
        return w0, lam * unit_force

    q0 = _start(model, basis, w0, pattern, k_ref)
    x_scale = max(0.5 * scale_length(model), float(np.max(np.abs(q0))))

    # a structure's stability comes from the monodromy, not from the evaluation: do not
    # keep one per point (each holds a dense Jacobian: 46 MB at 40 bays, H = 7)
    keep = model.is_joint
    # a large structure: its Jacobian assembled sparse, and the corrector's bordered solves
    # and the tangent by sparse LU (continuation hands them to the residual's own corrector
    # when chord_parameter is set)
    sparse = not model.is_joint and q0.size > solve.SPARSE_ABOVE
    sparse_jacobian = solve.SparseJacobian(model, basis) if sparse else None

    def residual(u: FloatArray, lam: float) -> tuple[FloatArray, Any, FloatArray, Any]:
        if not lam > 0.0:
            raise HarmonicError(f"the parameter left the positive range ({lam!r})")
        w, f = at(lam)
        ev = aft.evaluate(model, basis, u, w, f, jacobian=sparse_jacobian is None)
        if parameter == "omega":
            d_lam = ev.d_omega
        else:
            d_lam = np.zeros_like(ev.residual)
            d_lam.reshape(2 * h + 1, -1)[2] = -unit_force
        if sparse_jacobian is not None:
            jac = sparse_jacobian(ev, w, model.damping) * (1.0 / k_ref)
            return ev.residual / k_ref, jac, d_lam / k_ref, None
        return ev.residual / k_ref, ev.jacobian / k_ref, d_lam / k_ref, ev if keep else None

    # one DOF in w: the whole corrector compiled (one call per correction)
    compiled = (
        parameter == "omega"
        and model.n_dof == 1
        and model.friction_force is None
        and basis.assemble is not None
    )
    chosen: Any = residual
    if sparse:
        chosen = SparseResidual(residual)
    elif compiled:
        chosen = aft.OneDofResidual(residual, model, basis, float(pattern[0]), k_ref)
    branch = continue_branch(
        chosen,
        q0,
        start,
        stop,
        u_scale=np.full(q0.size, x_scale),
        lam_scale=abs(stop - start),
        settings=ContinuationSettings(
            step=min(0.002, max_step),
            min_step=1e-7,
            max_step=max_step,
            max_points=max_points,
            tolerance=TOLERANCE,
            chord_parameter=sparse or compiled,
        ),
    )
    settings = {
        "system": system,
        "harmonics": h,
        "samples": n_t,
        "losses": losses,
        "force_pattern": unit_force,
        "stability": stability or ("hill" if model.is_joint else "monodromy"),
    }
    names = getattr(system, "dof_names", None)
    if names is not None and not model.is_joint:
        # the curve carries them (FrequencyResponse.dof_names); kept in settings for
        # the readers of the older place
        settings["dof_names"] = list(names)
    response = _response(
        model,
        basis,
        branch.u,
        branch.lam,
        branch.data,
        parameter,
        w0,
        pattern,
        unit_force,
        branch.reason,
        settings,
    )
    if not model.is_joint and model.friction_force is not None:
        # no exact structure motion carries friction: no orbit check; flag sticking instead
        return dataclasses.replace(
            response, events=response.events + _sticking_events(model, basis, response)
        )
    if model.is_joint or check_points == 0:
        return response
    found = check.check_orbits(response, check.spread(response.omega.size, check_points))
    settings["orbit_check"] = found
    # a structure's point is stable only where the exact motion confirms it (issue 24)
    confirmed = check.confirm_stable(response)
    settings["stability_check"] = confirmed
    settings["harmonic_stable"] = response.stable.copy()
    stable = np.zeros_like(response.stable)
    stable[confirmed.index[confirmed.confirmed]] = True
    return dataclasses.replace(
        response,
        stable=stable,
        events=response.events
        + check.untrusted_events(response, found)
        + check.unconfirmed_events(response, confirmed),
    )


#: With friction, the start is also sought from these multiples of v_eps down to 1 (a
#: smoother friction first, then Newton from each solution at the next sharper one).
REGULARIZATION_LADDER = (1000.0, 300.0, 100.0, 30.0, 10.0, 3.0, 1.0)


def _start(
    model: LinearSystem, basis: aft.Basis, omega: float, force: FloatArray, k_ref: float
) -> FloatArray:
    """Solve HB at the start (:func:`_start_plain`); with friction, if that fails, from a
    smoother regularisation down to the asked one (``REGULARIZATION_LADDER``)."""
    try:
        return _start_plain(model, basis, omega, force, k_ref)
    except HarmonicError:
        if model.friction_force is None:
            raise
    v_eps = model.friction_speed
    first, *rest = REGULARIZATION_LADDER
    try:
        q = _start_plain(
            dataclasses.replace(model, friction_speed=first * v_eps), basis, omega, force, k_ref
        )
    except HarmonicError:
        q = None
    for factor in rest:
        if q is None:
            break
        smoother = dataclasses.replace(model, friction_speed=factor * v_eps)

        def function(
            u: FloatArray, system: LinearSystem = smoother
        ) -> tuple[FloatArray, FloatArray]:
            ev = aft.evaluate(system, basis, u, omega, force)
            return ev.residual / k_ref, ev.jacobian / k_ref

        found = newton(function, q, max(0.5 * scale_length(model), float(np.max(np.abs(q)))))
        q = None if found is None else found[0]
    if q is not None:
        return q
    raise HarmonicError(
        f"harmonic balance found no periodic response at omega_start = {omega!r} rad/s with "
        f"the friction regularised at v_eps = {v_eps:.3g} m/s (nor from a smoother one); "
        "start the curve at another frequency or pass a larger friction_regularization"
    )


def linear_start(
    model: LinearSystem,
    basis: aft.Basis,
    omega: float,
    force: FloatArray,
    k_ref: float,
    *,
    sparse: Any = None,
    max_iterations: int = 80,
    tolerate: tuple[type[Exception], ...] = (),
) -> FloatArray | None:
    """Harmonic balance's orbit by Newton from the open, then the closed, linear response.

    The first part of :func:`frequency_response`'s start (its force homotopy is the
    second). ``sparse``: a ``SparseJacobian`` for a large structure. An exception of a
    type in ``tolerate`` counts as no solution from that guess (the next is tried).

    Returns
    -------
    (2H + 1) N ndarray or None
        The coefficients a_0, a_1, b_1, ..., a_H, b_H (per DOF), m; None if neither
        converged.
    """
    for stiffness in (model.open_stiffness(), model.closed_stiffness()):
        guess = linear_guess(model, basis, omega, force, stiffness)
        try:
            found = _newton_at(
                model, basis, omega, force, k_ref, sparse, guess, max_iterations=max_iterations
            )
        except tolerate:
            found = None
        if found is not None:
            return found
    return None


def _newton_at(
    model: LinearSystem,
    basis: aft.Basis,
    omega: float,
    force: FloatArray,
    k_ref: float,
    sparse: Any,
    guess: FloatArray,
    *,
    max_iterations: int = 80,
) -> FloatArray | None:
    """Newton on harmonic balance at (omega, force) from ``guess`` to ``TOLERANCE``, or
    None. ``sparse``: a ``SparseJacobian`` for a large structure; there the halved steps
    need no Jacobian and a Newton that stalls (``START_STALL``) is given up."""
    scale = 0.5 * scale_length(model)

    def function(q: FloatArray) -> tuple[FloatArray, Any]:
        ev = aft.evaluate(model, basis, q, omega, force, jacobian=sparse is None)
        jac = ev.jacobian if sparse is None else sparse(ev, omega, model.damping)
        return ev.residual / k_ref, jac / k_ref

    def residual(q: FloatArray) -> FloatArray:
        # a halved trial step needs no Jacobian (the same R as ``function``'s)
        ev = aft.evaluate(model, basis, q, omega, force, jacobian=False)
        return np.asarray(ev.residual / k_ref, dtype=np.float64)

    found = newton(
        function,
        guess,
        max(scale, float(np.max(np.abs(guess)))),
        max_iterations=max_iterations,
        residual=None if sparse is None else residual,
        stall=None if sparse is None else START_STALL,
    )
    return None if found is None else found[0]


def _start_plain(
    model: LinearSystem, basis: aft.Basis, omega: float, force: FloatArray, k_ref: float
) -> FloatArray:
    """Solve HB at the start: Newton from the open and the closed linear responses, else a
    continuation in the force from a level where the open linear response fits the gaps."""
    scale = 0.5 * scale_length(model)
    # a large structure: the Jacobian assembled sparse for Newton and the homotopy below
    n_u = (2 * basis.harmonics + 1) * model.n_dof
    sparse = (
        None if model.is_joint or n_u <= solve.SPARSE_ABOVE else solve.SparseJacobian(model, basis)
    )

    hz = omega / (2.0 * math.pi)
    found = linear_start(model, basis, omega, force, k_ref, sparse=sparse)
    if found is not None:
        return found
    reached = 0.0
    # Homotopy: from a force small enough for the open (all joints in free-play) linear
    # response to stay inside every gap, follow the solution up to the full force.
    open_guess = linear_guess(model, basis, omega, force, model.open_stiffness())
    coef = open_guess.reshape(2 * basis.harmonics + 1, model.n_dof)
    reach = np.hypot(coef[1], coef[2]) @ np.abs(model.directions.T)
    room = np.minimum(model.g_c, model.g_t)
    if reach.size and np.all(np.isfinite(reach)) and np.max(reach) > 0.0 and np.all(room > 0):
        fraction = min(0.5 * float(np.min(room / np.maximum(reach, 1e-300))), 0.5)
        peak = float(np.max(np.abs(force)))
        points = int(np.clip(START_BUDGET // open_guess.size, *START_POINTS))
        LOGGER.info(
            "start at %.6g Hz: Newton from the linear responses found no orbit; following "
            "the force up from %.3g N to %.3g N (at most %d points)",
            hz,
            fraction * peak,
            peak,
            points,
        )
        calls = [0, fraction]

        def residual(u: FloatArray, lam: float) -> tuple[FloatArray, Any, FloatArray, None]:
            calls[0] += 1
            calls[1] = max(calls[1], lam)
            if calls[0] % 25 == 0:
                LOGGER.info(
                    "start at %.6g Hz: force continuation at %.3g N of %.3g N (%d evaluations)",
                    hz,
                    lam * peak,
                    peak,
                    calls[0],
                )
            ev = aft.evaluate(model, basis, u, omega, lam * force, jacobian=sparse is None)
            d_lam = np.zeros_like(ev.residual)
            d_lam.reshape(2 * basis.harmonics + 1, -1)[2] = -force
            jac = ev.jacobian if sparse is None else sparse(ev, omega, model.damping)
            return ev.residual / k_ref, jac / k_ref, d_lam / k_ref, None

        # on the sparse route, the path to START_TOLERANCE first, its end polished at the
        # full force; where it falls short, turns back or does not polish, the path again
        # to the curve's TOLERANCE, as before (START_TOLERANCE's note)
        paths = (START_TOLERANCE, TOLERANCE) if sparse is not None else (TOLERANCE,)
        u_scale = np.full(open_guess.size, max(scale, float(np.max(np.abs(open_guess)))))
        for tolerance in dict.fromkeys(paths):
            calls[:] = [0, fraction]  # the error below reports the last path's reach
            try:
                with silenced():  # it counts the force, not the curve's progress
                    branch = continue_branch(
                        residual if sparse is None else SparseResidual(residual),
                        fraction * open_guess,
                        fraction,
                        1.0,
                        u_scale=u_scale,
                        lam_scale=1.0,
                        settings=ContinuationSettings(
                            step=0.01,
                            min_step=1e-7,
                            max_step=0.1,
                            max_points=points,
                            tolerance=tolerance,
                            chord_parameter=sparse is not None,  # sparse corrector and tangent
                        ),
                    )
            except ClearjointError:
                branch = None
            if tolerance == TOLERANCE:
                if branch is not None and branch.reason == "reached":
                    return np.asarray(branch.u[-1], dtype=np.float64)
                break
            if branch is None or branch.reason != "reached":
                LOGGER.info(
                    "start at %.6g Hz: the force continuation to %.0e did not reach the full "
                    "force (%s); following it again at the tolerance",
                    hz,
                    tolerance,
                    "no start" if branch is None else branch.reason,
                )
                continue
            if np.any(np.diff(branch.lam) < 0.0):
                LOGGER.info(
                    "start at %.6g Hz: the force continuation to %.0e turned back in the "
                    "force; following it again at the tolerance",
                    hz,
                    tolerance,
                )
                continue  # a fold: where the larger steps may cross to another branch
            end = np.asarray(branch.u[-1], dtype=np.float64)
            polished = _newton_at(model, basis, omega, force, k_ref, sparse, end)
            if polished is not None:
                return polished
            LOGGER.info(
                "start at %.6g Hz: the force continuation's end did not polish to the "
                "tolerance; following it again at that tolerance",
                hz,
            )
        reached = float(calls[1]) if branch is None else float(np.max(branch.lam))
        raise NoPeriodicResponse(
            f"harmonic balance found no periodic response at omega_start = {omega!r} rad/s "
            f"({hz:.6g} Hz): Newton from the linear responses failed and the force "
            f"continuation reached only {reached * peak:.3g} N of {peak:.3g} N"
            + ("" if branch is None else f" ({branch.reason} after {len(branch.lam)} points)")
            + "; at this force there may be no periodic orbit (the joints may rattle): start "
            "at a lower force or another frequency, or use the exact time response",
            omega,
            reached,
        )
    raise NoPeriodicResponse(
        f"harmonic balance found no periodic response at omega_start = {omega!r} rad/s; "
        "start the curve at another frequency",
        omega,
        reached,
    )


def _response(
    model: LinearSystem,
    basis: aft.Basis,
    u: FloatArray,
    lam: FloatArray,
    evaluations: list[aft.Evaluation],
    parameter: str,
    w0: float,
    pattern: FloatArray,
    unit_force: FloatArray,
    reason: str,
    settings: dict[str, Any],
) -> FrequencyResponse:
    n_pts = lam.size
    n, n_c = model.n_dof, 2 * basis.harmonics + 1
    by_hill = settings["stability"] == "hill"
    omega = lam.copy() if parameter == "omega" else np.full(n_pts, w0)
    peak = float(np.max(np.abs(pattern)))
    force = lam.copy() if parameter == "force" else np.full(n_pts, peak)
    coef = u.reshape(n_pts, n_c, n)
    # extremes per DOF and per joint (the relative displacements, for grazing)
    cols = coef.transpose(1, 0, 2).reshape(n_c, n_pts * n)
    x_max, x_min = (v.reshape(n_pts, n) for v in basis.extremes(cols))
    b = model.directions
    rel = np.einsum("pcn,jn->cpj", coef, b).reshape(n_c, -1)
    d_max, d_min = (v.reshape(n_pts, b.shape[0]) for v in basis.extremes(rel))
    multipliers = np.empty((n_pts, 2 * n), dtype=np.complex128)
    determinant = by_hill and n == 1 and model.friction_force is None
    jacobians = np.empty((n_pts, n_c, n_c)) if determinant else None
    defect = np.zeros(n_pts)
    unresolved: list[int] = []
    disagree: list[tuple[int, float, float]] = []
    block: FloatArray | None = None  # the leading invariant subspace at the last point
    full: list[int] = []
    for i in range(n_pts):
        if not by_hill:  # the exact monodromy of the orbit's linearisation
            found_block = _verdicts(model, basis, coef[i], float(omega[i]), block)
            multipliers[i] = found_block.multipliers
            block = found_block.block
            if found_block.full:
                full.append(i)
            continue
        ev = evaluations[i] if i < len(evaluations) else None
        if not isinstance(ev, aft.Evaluation):  # a point the continuation did not evaluate
            f = pattern if parameter == "omega" else force[i] * unit_force
            ev = aft.evaluate(model, basis, u[i], float(omega[i]), f)
        if jacobians is not None:  # one DOF, constant damping: Hill's determinant
            jacobians[i] = ev.jacobian
            continue
        try:
            found = hill.spectrum(model, basis, ev.jacobian, float(omega[i]), ev.velocity_tangent)
        except HarmonicError:  # fewer than 2N resolved exponents: no verdict
            multipliers[i] = np.nan
            defect[i] = np.inf
            unresolved.append(i)
            continue
        multipliers[i] = found.multipliers
        defect[i] = found.defect
        if not model.is_joint:  # cross-check against the exact monodromy of the same orbit
            exact = float(np.max(np.abs(monodromy.multipliers(model, basis, coef[i], omega[i]))))
            mine = float(np.max(np.abs(found.multipliers)))
            if (mine < 1.0) != (exact < 1.0):
                disagree.append((i, mine, exact))
    if jacobians is not None:
        multipliers[:] = aft.hill_determinant_multipliers(model, basis, jacobians, omega)
    if full:  # the leading block did not converge there: the whole monodromy was used
        settings["monodromy_full"] = full
        LOGGER.warning(
            "the leading Floquet multipliers did not converge at %d point(s) (first: %d); "
            "the whole monodromy was decomposed there instead (slower, same verdict)",
            len(full),
            full[0],
        )
    if by_hill:
        settings["hill_defect"] = defect
    stable = np.max(np.abs(multipliers), axis=1) < 1.0
    amplitude = 0.5 * (x_max - x_min)
    x0 = coef[:, 0, :] + coef[:, 1::2, :].sum(axis=1)
    v0 = omega[:, None] * np.einsum("c,pcn->pn", _velocity_row(basis), coef)
    initial = np.concatenate((x0, v0), axis=1)
    events = curve_events(
        model, lam, multipliers, d_max, d_min, omega, force, np.max(amplitude, axis=1)
    )
    events += [
        check.untrusted(
            omega,
            force,
            amplitude,
            i,
            f"Hill's eigenproblem at H = {basis.harmonics} resolves fewer than the 2N = {2 * n} "
            "exponents: no stability verdict here; raise harmonics or use stability='monodromy'",
        )
        for i in unresolved
    ]
    events += [
        check.untrusted(
            omega,
            force,
            amplitude,
            i,
            f"Hill's largest multiplier {mine:.4g} and the exact monodromy's {exact:.4g} of the "
            "same orbit give other verdicts (the perturbation needs more harmonics than "
            "the orbit); use stability='monodromy'",
        )
        for i, mine, exact in disagree
    ]
    if model.is_joint:
        x_max, x_min, amplitude, coef_out = x_max[:, 0], x_min[:, 0], amplitude[:, 0], coef[:, :, 0]
    else:
        coef_out = coef
    return FrequencyResponse(
        omega=omega,
        force_amplitude=force,
        x_max=x_max,
        x_min=x_min,
        amplitude=amplitude,
        stable=stable,
        multipliers=multipliers,
        initial_state=initial,
        events=events,
        parameter=parameter,
        stop_reason=reason,
        settings=settings,
        coefficients=coef_out.copy(),
        method="harmonic",
        dof_names=None if model.is_joint else _dof_names(settings, n),
    )


def _verdicts(
    model: LinearSystem,
    basis: aft.Basis,
    coefficients: FloatArray,
    omega: float,
    start: FloatArray | None = None,
) -> monodromy.LeadingBlock:
    """One point's multipliers for the stability verdict: the exact monodromy's leading
    ones (:func:`clearjoint.harmonic.monodromy.leading_block`: its product applied to a few
    columns, never formed, on a large structure, started from the last point's block
    ``start``; all 2N on a small one)."""
    return monodromy.leading_block(model, basis, coefficients, omega, start)


def _dof_names(settings: dict[str, Any], n_dof: int) -> tuple[str, ...] | None:
    """Return the solved structure's DOF names (``settings["dof_names"]``), None if it has none."""
    names = settings.get("dof_names")
    return tuple(str(name) for name in names) if names is not None and len(names) == n_dof else None


def _sticking_events(
    model: LinearSystem, basis: aft.Basis, response: FrequencyResponse
) -> list[ResponseEvent]:
    """One ``"untrusted"`` event per point where a rubbing joint's speed reverses more
    than twice per period (it sticks: :func:`monodromy.speed_reversals`)."""
    assert model.friction_force is not None
    coefficients = response.coefficients
    assert coefficients is not None
    rubbing = model.friction_force > 0.0
    out = []
    for i in range(response.omega.size):
        turns = monodromy.speed_reversals(model, basis, coefficients[i])
        stuck = np.flatnonzero(rubbing & (turns > 2.0))
        if stuck.size:
            out.append(
                check.untrusted(
                    response.omega,
                    response.force_amplitude,
                    response.amplitude,
                    i,
                    f"joint {int(stuck[0])}'s relative speed reverses {int(turns[stuck[0]])} "
                    "times per period: it sticks, where the regularised friction's "
                    "linearisation (and this stability verdict) is not to be trusted; "
                    "study that joint alone with clearjoint.periodic (exact stick-slip)",
                )
            )
    return out


def _velocity_row(basis: aft.Basis) -> FloatArray:
    """Row r with u'(0) / w = r . coefficients: sum over h of h b_h."""
    row = np.zeros(2 * basis.harmonics + 1)
    row[2::2] = np.arange(1, basis.harmonics + 1)
    return row


#: Reversals of the parameter smaller than this fraction of it are not folds.
FOLD_TOLERANCE = 5e-4


def _turning_points(lam: FloatArray, tolerance: float) -> list[int]:
    """Indices where ``lam`` reaches an extreme and then goes back by more than ``tolerance``."""
    points: list[int] = []
    direction = 0.0
    extreme = 0
    for i in range(1, lam.size):
        step = float(lam[i] - lam[extreme])
        if direction == 0.0:
            if abs(step) > tolerance:
                direction, extreme = math.copysign(1.0, step), i
        elif direction * step > 0.0:
            extreme = i
        elif -direction * step > tolerance:
            points.append(extreme)
            direction, extreme = -direction, i
    return points


#: A multiplier counts as one of a complex pair when abs(Im mu) exceeds this fraction of abs(mu).
COMPLEX_PAIR = 1e-3


def _top_complex(multipliers: NDArray[np.complex128]) -> complex | None:
    """The complex multiplier of largest modulus in the upper half-plane, or None."""
    mag = np.abs(multipliers)
    upper = (np.abs(multipliers.imag) > COMPLEX_PAIR * mag) & (multipliers.imag > 0.0)
    if not np.any(upper):
        return None
    found = multipliers[upper]
    return complex(found[int(np.argmax(np.abs(found)))])


def _same_pair(before: NDArray[np.complex128], after: NDArray[np.complex128]) -> bool:
    """Whether the largest complex pair at ``after`` continues the one at ``before``: each is
    the other's nearest among its neighbour point's multipliers in the closed upper
    half-plane (a pair that met the real axis in between has a real multiplier nearer;
    the largest pair taken over by another has that other nearer). Multipliers returned
    as 0 (outside a leading block) or far inside the circle take no part, whatever their
    number at either point."""
    a, b = _top_complex(before), _top_complex(after)
    if a is None or b is None:
        return False

    def nearest(multipliers: NDArray[np.complex128], z: complex) -> complex:
        upper = multipliers[multipliers.imag >= 0.0]
        return complex(upper[int(np.argmin(np.abs(upper - z)))])

    return nearest(after, a) == b and nearest(before, b) == a


def _complex_pair_test(multipliers: NDArray[np.complex128]) -> FloatArray:
    """Largest abs(mu) - 1 over each point's complex multipliers (NaN where it has none):
    its sign change between two points whose largest pairs are one pair (:func:`_same_pair`)
    is a Neimark-Sacker crossing (a complex pair through the unit circle)."""
    mag = np.abs(multipliers)
    pair = np.abs(multipliers.imag) > COMPLEX_PAIR * mag
    top = np.max(np.where(pair, mag, -np.inf), axis=1)
    return np.where(np.isfinite(top), top - 1.0, np.nan)


def curve_events(
    model: LinearSystem,
    lam: FloatArray,
    multipliers: NDArray[np.complex128],
    d_max: FloatArray,
    d_min: FloatArray,
    omega: FloatArray,
    force: FloatArray,
    amplitude: FloatArray,
) -> list[ResponseEvent]:
    """Folds, period doublings, Neimark-Sacker crossings and grazings between successive points.

    For any curve of periodic orbits (harmonic balance, or a structure's exact shooting)
    with Floquet multipliers and the joints' extreme shortenings ``d_max``, ``d_min``
    (n, n_j) per point; ``model`` gives the joints' directions and gap edges
    (``directions``, ``g_c``, ``g_t``, ``is_joint``).

    Period doublings, Neimark-Sacker crossings (:func:`_complex_pair_test`) and
    grazings are located linearly between the points where their test function
    changes sign. Folds are the points where the parameter
    turns back by more than ``FOLD_TOLERANCE`` of its largest value: the sampled
    law makes the HB branch zigzag by about 1e-4 of the parameter where it is
    nearly flat at a fold (each sample crossing a gap edge is a tiny kink), and
    those reversals, below the truncation error, are not folds.
    """
    found: list[tuple[int, ResponseEvent]] = [
        (i, ResponseEvent("fold", float(omega[i]), float(force[i]), float(amplitude[i])))
        for i in _turning_points(lam, FOLD_TOLERANCE * float(np.max(np.abs(lam))))
    ]
    tests: list[tuple[str, FloatArray, str]] = [
        (
            "period_doubling",
            np.prod(1.0 + multipliers, axis=1).real,
            "a multiplier passes -1: a period-2 branch is born here (not followed)",
        ),
        (
            "neimark_sacker",
            _complex_pair_test(multipliers),
            "a complex pair of multipliers crosses the unit circle: a quasi-periodic "
            "motion (torus) is born here (not followed)",
        ),
    ]
    for j in range(model.directions.shape[0]):
        name = "" if model.is_joint else f" of joint {j}"
        tests.append(("grazing", d_max[:, j] - model.g_c[j], f"touches the compression edge{name}"))
        tests.append(("grazing", -model.g_t[j] - d_min[:, j], f"touches the tension edge{name}"))
    for kind, g, note in tests:
        for i in np.nonzero(np.sign(g[:-1]) * np.sign(g[1:]) < 0)[0]:
            if kind == "neimark_sacker" and not _same_pair(multipliers[i], multipliers[i + 1]):
                continue  # not one pair through the circle (_same_pair)
            frac = float(g[i] / (g[i] - g[i + 1]))

            def lerp(a: FloatArray, i: int = int(i), frac: float = frac) -> float:
                return float(a[i] + frac * (a[i + 1] - a[i]))

            found.append(
                (int(i), ResponseEvent(kind, lerp(omega), lerp(force), lerp(amplitude), note))
            )
    found.sort(key=lambda item: item[0])
    merged: list[tuple[int, ResponseEvent]] = []
    for index, event in found:
        last = merged[-1] if merged else None
        if last and event.kind == "grazing" and last[1].kind == "grazing" and last[0] == index:
            both = ResponseEvent(
                "grazing",
                event.omega,
                event.force_amplitude,
                event.amplitude,
                f"{last[1].note}; {event.note}",
            )
            merged[-1] = (index, both)
            continue
        merged.append((index, event))
    return [e for _, e in merged]


def start_coefficients(
    model: LinearSystem, basis: aft.Basis, omega: float, force: FloatArray
) -> FloatArray:
    """Harmonic balance's orbit at one frequency, found as :func:`frequency_response` finds its
    start: Newton from the open and the closed linear responses, else a continuation in the
    force (with friction, from smoother regularisations too).

    Returns
    -------
    (2H + 1) N ndarray
        The coefficients a_0, a_1, b_1, ..., a_H, b_H (per DOF), m.

    Raises
    ------
    HarmonicError
        No orbit found (``NoPeriodicResponse``).
    """
    return _start(model, basis, omega, force, model.reference_stiffness)
