"""Nonlinear modes by the extended periodic motion concept (EPMC, MODEL.md 5.4).

Krack, Computers & Structures 154 (2015): the damped free motion is made periodic
by an artificial negative damping -xi M u'. With harmonic balance the unknowns are
the coefficients Q, w and xi, and two conditions close the system at a prescribed
modal amplitude a: the fundamental cosine coefficient of the mode's reference DOF
is a, its sine coefficient 0 (the phase). Then

    natural frequency w(a),
    energy dissipated per cycle E_diss = xi * integral of u'^T M u' dt over one period,
    damping ratio zeta(a) = E_diss / (4 pi E_max),
    EPMC's own ratio xi / (2 w).

zeta is the loss factor of MODEL.md section 2 halved, E_max the largest potential
energy over the orbit; EPMC's ratio equals it for sinusoidal motion only.

For one joint without losses xi = 0 and w(a) is the paper's 2 pi / T(A) of
section 1 (the dynamic stiffness is the backbone of the mode).

Coulomb friction in joints (over the whole path, MODEL.md section 2) enters the
residual regularised as mu_s P tanh(v / v_eps), with its slope in the Jacobian, as in
:func:`clearjoint.harmonic.frequency_response` (:func:`clearjoint.harmonic.aft.evaluate`
carries both); E_diss is then the friction's work, 2 mu_s P (x_max - x_min) per cycle
for one joint sliding back and forth.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from clearjoint.errors import ParameterError, ParameterTypeError
from clearjoint.harmonic import aft
from clearjoint.harmonic.solve import SPARSE_ABOVE, SparseJacobian, newton
from clearjoint.harmonic.system import (
    LinearSystem,
    build,
    check_size,
    friction_speed,
    scale_length,
)
from clearjoint.joint import Losses, takes_losses
from clearjoint.progress import report

if TYPE_CHECKING:
    import pandas as pd
    import xarray as xr
    from matplotlib.axes import Axes

FloatArray = NDArray[np.float64]

#: Solutions with w below this fraction of the closed-pattern frequency are not modes.
_LOWEST = 1e-3

#: Halvings of the step in log amplitude before an amplitude is given up: the last try
#: starts 2^-3 of the way from the neighbouring converged amplitude. More buys little
#: where it fails (near contact onset the mode has several solutions close together):
#: the example mast's first mode at 50 amplitudes (benchmarks/bench_harmonic.py sizes)
#: converged at 43, 45 and 44 of 50 with 0, 3 and 10 halvings, in 15, 61 and 105 s (2
#: cores, another job running; with 3 and nothing else running, 45 of 50 in 45 s).
MAX_HALVINGS = 3

#: If the closed-pattern guess fails at the largest amplitude, it is tried at up to 10^4
#: times it.
_ABOVE = 4

#: Newton iterations a sub-step may take (a full step between two amplitudes: 80).
_SUB_ITERATIONS = 20

#: Consecutive solutions whose fundamental shapes have a MAC below this are another mode.
_MAC = 0.5

_NEWTON = (
    "Newton did not converge from the neighbouring converged amplitude above (nor below, where "
    f"one converged) after {MAX_HALVINGS} halvings of the step in log amplitude (or converged "
    "to another mode)"
)

Path = list[tuple[float, FloatArray]]


@dataclass(frozen=True)
class NonlinearMode:
    """One nonlinear mode's properties against its amplitude (EPMC, MODEL.md 5.4).

    Attributes
    ----------
    amplitude : (n,) ndarray
        The modal amplitude a, m: the fundamental harmonic's amplitude on the
        mode's reference DOF (``reference_dof``), ascending.
    x_max, x_min : ndarray
        Extremes of the motion per DOF, m: (n,) for a Joint, (n, N) for a Structure.
    frequency : (n,) ndarray
        Natural frequency w(a), rad/s.
    damping_ratio : (n,) ndarray
        The energy-equivalent ratio zeta(a) = E_diss / (4 pi E_max): the loss factor
        of MODEL.md section 2 halved, with E_diss = ``energy_per_cycle`` and E_max the
        largest potential energy over the orbit (0.5 u^T K u plus every joint's
        V(delta)); for one joint E_max = V(x_max), as :mod:`clearjoint.dissipation`.
    energy_per_cycle : (n,) ndarray
        Energy the losses dissipate per cycle, xi * integral u'^T M u' dt, J.
    epmc_damping_ratio : (n,) ndarray
        EPMC's xi / (2 w): equal to ``damping_ratio`` for a sinusoid, up to twice
        smaller for a joint's near-triangular motion close to its gap (docs/harmonic.md).
    harmonic_shapes : ndarray
        The harmonic coefficients a_0, a_1, b_1, ..., a_H, b_H, m: (n, 2H + 1) for
        a Joint, (n, 2H + 1, N) for a Structure.
    converged : (n,) ndarray of bool
        False where no mode was found at that amplitude (e.g. a mass that stays in
        a gap without restoring force, which would give w -> 0: solutions below
        1e-3 of the closed-pattern frequency are refused); the other arrays hold
        NaN there.
    mode : int
        The mode number (1 = lowest of the closed pattern).
    harmonics : int
        H.
    reference_dof : str
        The DOF the amplitude is measured on.
    dof_names : tuple of str
        A Structure's DOF names (the ``dof`` coordinate of :meth:`to_xarray`); empty
        for a Joint.
    note : str
        Empty, or one line per thing the user should know: how many amplitudes found
        no mode and why (Newton did not converge from the neighbouring amplitude after
        :data:`MAX_HALVINGS` halvings of the step; w fell to 0; friction holds a
        rubbing joint at a turning point); how many were reached instead up from the
        open-pattern mode below contact onset, or up from a converged amplitude below
        (the branch from above did not reach them: it folds in amplitude there, the
        solutions are not unique); or that no joint reached a gap edge over the whole
        range (with where contact begins).
    """

    amplitude: FloatArray
    x_max: FloatArray = field(repr=False)
    x_min: FloatArray = field(repr=False)
    frequency: FloatArray = field(repr=False)
    damping_ratio: FloatArray = field(repr=False)
    energy_per_cycle: FloatArray = field(repr=False)
    harmonic_shapes: FloatArray = field(repr=False)
    converged: NDArray[np.bool_] = field(repr=False)
    epmc_damping_ratio: FloatArray = field(repr=False)
    mode: int = 1
    harmonics: int = 7
    reference_dof: str = "x"
    dof_names: tuple[str, ...] = ()
    note: str = ""

    def __repr__(self) -> str:
        ok = self.converged
        f = self.frequency[ok] / (2.0 * math.pi)
        z = self.damping_ratio[ok]
        span = f"{f.min():.4g}-{f.max():.4g} Hz, zeta {z.min():.3g}-{z.max():.3g}" if f.size else ""
        return (
            f"NonlinearMode(mode {self.mode}, H={self.harmonics}, {self.amplitude.size} amplitudes "
            f"{self.amplitude.min():.3g}-{self.amplitude.max():.3g} m on {self.reference_dof}, "
            f"{span}, {int(np.sum(~ok))} not converged)"
        )

    def plot(self, ax: Axes | None = None) -> Axes:
        """Plot frequency (Hz, solid) and both damping ratios (right axis) against amplitude.

        ``damping_ratio`` dashed, ``epmc_damping_ratio`` dotted.

        Returns
        -------
        matplotlib.axes.Axes
            The frequency axes (the damping ratio is on its twin).
        """
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(6.4, 4.0))
        a_um = self.amplitude * 1e6
        ax.plot(a_um, self.frequency / (2.0 * math.pi), "-", color="C0", label="frequency")
        ax.set_xlabel(f"modal amplitude on {self.reference_dof} (um)")
        ax.set_ylabel("natural frequency (Hz)", color="C0")
        if self.amplitude.size > 1 and self.amplitude.max() > 10.0 * self.amplitude.min():
            ax.set_xscale("log")
        if np.any(self.damping_ratio[self.converged] > 0.0):
            twin = ax.twinx()
            twin.plot(
                a_um, self.damping_ratio, "--", color="C3", label="damping ratio E/(4 pi E_max)"
            )
            twin.plot(a_um, self.epmc_damping_ratio, ":", color="C3", label="EPMC xi/(2 w)")
            twin.set_ylabel("damping ratio (dashed; EPMC xi/(2 w) dotted)", color="C3")
        ax.set_title(f"nonlinear mode {self.mode} (EPMC, H = {self.harmonics})")
        return ax

    def to_xarray(self) -> xr.Dataset:
        """The mode as an xarray Dataset over ``amplitude`` (and ``dof``), units in attrs."""
        import xarray as xr

        per = ("amplitude",) if self.x_max.ndim == 1 else ("amplitude", "dof")
        shape_dims = ("amplitude", "coefficient", "dof")[: self.harmonic_shapes.ndim]
        coords: dict[str, Any] = {"amplitude": ("amplitude", self.amplitude, {"units": "m"})}
        if self.x_max.ndim == 2 and len(self.dof_names) == self.x_max.shape[1]:
            coords["dof"] = ("dof", list(self.dof_names))
        return xr.Dataset(
            {
                "frequency": ("amplitude", self.frequency / (2.0 * math.pi), {"units": "Hz"}),
                "omega": ("amplitude", self.frequency, {"units": "rad/s"}),
                "damping_ratio": ("amplitude", self.damping_ratio, {"units": "1"}),
                "energy_per_cycle": ("amplitude", self.energy_per_cycle, {"units": "J"}),
                "epmc_damping_ratio": ("amplitude", self.epmc_damping_ratio, {"units": "1"}),
                "x_max": (per, self.x_max, {"units": "m"}),
                "x_min": (per, self.x_min, {"units": "m"}),
                "harmonic_shapes": (
                    shape_dims,
                    self.harmonic_shapes,
                    {"units": "m", "order": "a_0, a_1, b_1, ..., a_H, b_H of cos/sin(h w t)"},
                ),
                "converged": ("amplitude", self.converged.astype(np.int8), {"units": "1 yes"}),
            },
            coords=coords,
            attrs={
                "title": "clearjoint nonlinear mode (EPMC, harmonic balance)",
                "mode": self.mode,
                "harmonics": self.harmonics,
                "reference_dof": self.reference_dof,
                "note": self.note,
            },
        )

    def to_pandas(self) -> pd.DataFrame:
        """Return the mode as a ``pandas.DataFrame``, one row per modal amplitude.

        Returns
        -------
        pandas.DataFrame
            Index ``amplitude_m``; columns ``frequency_hz``, ``omega_rad_per_s``,
            ``damping_ratio``, ``energy_per_cycle_j``, ``epmc_damping_ratio``,
            ``converged``, and the extremes ``x_max_m``, ``x_min_m`` (a Structure's:
            one column per DOF, ``x_max_m[<dof name>]``). The harmonic shapes are in
            :meth:`to_xarray`.
        """
        import pandas as pd

        columns: dict[str, Any] = {
            "frequency_hz": self.frequency / (2.0 * math.pi),
            "omega_rad_per_s": self.frequency,
            "damping_ratio": self.damping_ratio,
            "energy_per_cycle_j": self.energy_per_cycle,
            "epmc_damping_ratio": self.epmc_damping_ratio,
            "converged": self.converged,
        }
        for key, values in (("x_max", self.x_max), ("x_min", self.x_min)):
            if values.ndim == 1:
                columns[f"{key}_m"] = values
                continue
            names = list(self.dof_names)
            if len(names) != values.shape[1]:
                names = [f"DOF {k}" for k in range(values.shape[1])]
            columns.update({f"{key}_m[{name}]": values[:, k] for k, name in enumerate(names)})
        return pd.DataFrame(columns, index=pd.Index(self.amplitude, name="amplitude_m"))


def _amplitudes(amplitudes: ArrayLike) -> FloatArray:
    try:
        a = np.atleast_1d(np.asarray(amplitudes, dtype=np.float64))
    except (TypeError, ValueError):
        raise ParameterTypeError(
            f"amplitudes must be an array of modal amplitudes in m, got {amplitudes!r}"
        ) from None
    if a.ndim != 1 or a.size == 0 or not np.all(np.isfinite(a)):
        raise ParameterError("amplitudes must be a non-empty 1-D array of finite values (m)")
    if np.any(a <= 0.0):
        raise ParameterError(
            f"amplitudes must be > 0 (m); the range starts at {float(a.min())!r}: "
            "start it above zero (e.g. 1 um)"
        )
    return np.sort(a)


def _model(
    system: Any,
    mode: int,
    losses: Losses | None,
    given: float | None,
) -> tuple[LinearSystem, int, float, FloatArray]:
    """(model, reference DOF, closed-pattern frequency, shape) of mode ``mode``.

    Coulomb friction (a Joint's, or a Structure's joints', over the whole path) is
    regularised as in :func:`clearjoint.harmonic.frequency_response`: mu_s P tanh(v / v_eps)
    with v_eps = ``given``, or by default 1e-3 * w * c with w the mode's closed-pattern
    frequency (frequency_response's w is its start frequency) and c the clearance.
    """
    import dataclasses

    # v_eps does not enter the linear modes: build once with a placeholder, then set it
    model = build(system, losses, 1.0)
    ref, omega_lin, shape = _reference(model, mode)
    if model.friction_force is not None or given is not None:
        speed = friction_speed(system, omega_lin, given)
        model = dataclasses.replace(model, friction_speed=speed)
    return model, ref, omega_lin, shape


def _reference(model: LinearSystem, mode: int) -> tuple[int, float, FloatArray]:
    """(reference DOF, closed-pattern frequency, shape) of linear mode ``mode``."""
    import scipy.linalg

    n = model.n_dof
    if isinstance(mode, bool) or not isinstance(mode, int | np.integer) or not 1 <= mode <= n:
        what = "a Joint has only mode 1" if model.is_joint else f"the structure has modes 1 to {n}"
        raise ParameterError(f"mode must be an integer from 1 to {n} ({what}), got {mode!r}")
    w2, shapes = scipy.linalg.eigh(model.closed_stiffness(), model.mass)
    shape = shapes[:, int(mode) - 1]
    ref = int(np.argmax(np.abs(shape)))
    return ref, math.sqrt(max(float(w2[int(mode) - 1]), 0.0)), shape / shape[ref]


@takes_losses
def nonlinear_modes(
    system: Any,
    mode: int = 1,
    amplitudes: ArrayLike | None = None,
    *,
    harmonics: int = 7,
    samples: int | None = None,
    losses: Losses | None = None,
    friction_regularization: float | None = None,
) -> NonlinearMode:
    """Return a nonlinear mode's frequency, damping and shape against amplitude (MODEL.md 5.4).

    EPMC with harmonic balance: at each modal amplitude a, solve for Q, w and the
    negative damping xi that makes the free motion periodic. Amplitudes are solved
    from the largest down, each from the ones before (a secant predictor in log a);
    where Newton fails the step is halved, up to :data:`MAX_HALVINGS` times. An amplitude
    the branch from above does not reach is then tried up from the open-pattern mode (below
    contact onset), up from the nearest converged amplitude below it, and down from the
    two nearest above without the predictor: near onset the branch folds in amplitude
    (docs/harmonic.md), so several solutions lie at one amplitude; each point is the one
    on the branch continued from above where that reaches it, else the one reached from
    such a neighbour, not every solution (``note`` says how many, from which side). An
    amplitude still failing is flagged in ``converged`` and explained in ``note``.

    Parameters
    ----------
    system : Joint or Structure
    mode : int
        Mode number, 1 to N, counted on the closed pattern (all joints in contact);
        it also picks the reference DOF, where that linear mode moves most.
    amplitudes : (n,) array_like, optional
        Modal amplitudes a > 0, m: the fundamental harmonic's amplitude on the
        reference DOF. Default: 40 values from c/2 to 20 c (c the largest clearance).
    harmonics : int
        H >= 1.
    samples : int, optional
        N_t, as for :func:`clearjoint.harmonic.frequency_response`.
    losses : Losses, optional
        A Joint's losses (a Structure or VibrationSystem carries its own): the damping
        ratio zeta of its linear part (c_v = 2 zeta sqrt(m k_c)) and Coulomb friction
        over its whole path (region "everywhere"), regularised as mu_s P tanh(v / v_eps)
        exactly as in :func:`clearjoint.harmonic.frequency_response`; a Structure's
        joints carry their own friction (rigid members only) the same way. Friction
        over the free-play stroke only is refused (HarmonicError), and so is
        restitution below 1 (impacts need :mod:`clearjoint.periodic`). Where a rubbing
        joint would stick at a turning point (the force that would hold it, for a Joint
        its restoring force, within mu_s P: :func:`holding_forces`), the amplitude
        fails with the reason in ``note``: EPMC's regularised orbit has no stick phase
        and creeps through there, driven by the negative damping. The pin and its
        contact friction coefficient are not used (no feedback on the motion, MODEL.md
        sec. 2).
    friction_regularization : float, optional
        v_eps, m/s. Default 1e-3 w c, with w the mode's closed-pattern frequency
        (frequency_response uses its start frequency) and c a Joint's clearance (for
        a Structure the largest clearance of its joints with friction).

    Returns
    -------
    NonlinearMode

    Raises
    ------
    ParameterError
        A mode the system does not have, an amplitude at or below zero.
    HarmonicError
        Bad harmonics or samples, arrays above ``system.MEMORY_BOUND`` (2 GiB),
        friction over the free-play stroke only, or restitution.
    """
    h, n_t = aft.check_harmonics(harmonics, samples)
    model, ref, omega_lin, shape = _model(system, mode, losses, friction_regularization)
    length = scale_length(model)
    amps = _amplitudes(
        np.geomspace(0.5 * length, 20.0 * length, 40) if amplitudes is None else amplitudes
    )
    check_size(model.n_dof, h, lambda k: aft.check_harmonics(k, samples)[1])
    basis = aft.Basis.make(h, n_t)
    n, n_c = model.n_dof, 2 * h + 1
    n_u = n_c * n
    # a large structure: the Jacobian assembled sparse and factored by a sparse LU
    # (its column ordering reused from one Newton step and amplitude to the next)
    sparse = SparseJacobian(model, basis) if not model.is_joint and n_u > SPARSE_ABOVE else None

    def solve_at(a: float, guess: FloatArray, iterations: int = 80) -> FloatArray | None:
        w_scale = max(omega_lin, 1e-300)

        def function(z: FloatArray) -> tuple[FloatArray, Any]:
            return epmc_residual(model, basis, z, a, w_scale, ref, sparse_jacobian=sparse)

        def residual(z: FloatArray) -> FloatArray:
            return epmc_residual(model, basis, z, a, w_scale, ref, jacobian=False)[0]

        found = newton(function, guess, 1.0, residual=residual, max_iterations=iterations)
        if found is None:
            return None
        z = found[0]
        if not np.all(np.isfinite(z)):
            return None
        if not z[n_u] > _LOWEST:
            # w -> 0 is no mode: a mass floating in a gap with no restoring force (k0 = 0)
            low.append(a)
            return None
        return z

    # the stiffest pattern's mode bounds w from above (1 % margin for HB's own error)
    import scipy.linalg

    b = model.directions
    stiffest = model.stiffness + (b.T * (model.k0 + np.maximum(model.k_c, model.k_t))) @ b
    w2_top = float(scipy.linalg.eigh(stiffest, model.mass, eigvals_only=True)[int(mode) - 1])
    w_top = 1.01 * math.sqrt(max(w2_top, 0.0)) / max(omega_lin, 1e-300)

    def same_mode(before: FloatArray, after: FloatArray) -> bool:
        """Not a jump to another mode: w under the bound, fundamental shapes alike (MAC)."""
        if not after[n_u] <= w_top:
            return False
        one, two = before[n : 3 * n], after[n : 3 * n]
        mac = float(one @ two) ** 2 / max(float(one @ one) * float(two @ two), 1e-300)
        return mac >= _MAC

    low: list[float] = []
    results, reasons = _march(
        solve_at, amps, _first_guess(model, basis, shape, omega_lin, n_u), same_mode
    )
    for a in low:
        for i in np.flatnonzero(amps == a).tolist():
            if i not in results:
                reasons[i] = "w fell below 1e-3 of the closed-pattern frequency (no mode)"
    reach, phi, w_open = _open_mode(model, int(mode), ref)
    upward: list[int] = []
    if reasons and math.isfinite(reach) and w_open > _LOWEST * omega_lin:
        # the open-pattern mode is exact below onset: follow the branch up from there
        open_guess = _first_guess(model, basis, phi, omega_lin, n_u)
        open_guess[n_u] = w_open / omega_lin
        for i in sorted(reasons):
            start = min(float(amps[i]), reach * (1.0 - 1e-9))
            z = solve_at(start, open_guess)
            path: Path = [] if z is None else [(start, z)]
            if path and _walk(solve_at, path, float(amps[i]), same_mode):
                results[i] = path[-1][1]
                del reasons[i]
                upward.append(i)
    from_below, from_above = _neighbours(solve_at, amps, results, reasons, same_mode)
    held = _held(model, basis, amps, results, omega_lin)
    for i, why in held.items():
        del results[i]
        reasons[i] = why
    upward = [i for i in upward if i not in held]
    from_below = [i for i in from_below if i not in held]
    from_above = [i for i in from_above if i not in held]
    note = _note(amps, reasons)
    if upward:
        at = amps[upward]
        note = (note + "; " if note else "") + (
            f"{at.size} of {amps.size} amplitudes ({at.min():.3g}..{at.max():.3g} m) followed up "
            f"from the open-pattern mode below contact onset ({reach:.3g} m): the branch from "
            "above did not reach them"
        )
    for where, which in (
        ("the nearest converged amplitude below", from_below),
        ("one of the two nearest converged amplitudes above, with no predictor", from_above),
    ):
        if which:
            at = amps[which]
            note = (note + "; " if note else "") + (
                f"{at.size} of {amps.size} amplitudes ({at.min():.3g}..{at.max():.3g} m) reached "
                f"from {where}, not by the march from above: near "
                "contact onset the branch folds in amplitude (several solutions at one "
                "amplitude), so the curve may jump between its pieces"
            )
    if not _any_contact(model, basis, amps, results):
        note = (note + "; " if note else "") + (
            f"no joint reaches a gap edge over {amps[0]:.3g}..{amps[-1]:.3g} m (linear "
            "open-pattern motion everywhere)"
            + (f": contact begins near {reach:.3g} m" if math.isfinite(reach) else "")
        )
    return _mode(model, basis, amps, results, int(mode), ref, omega_lin, note)


def epmc_residual(
    model: LinearSystem,
    basis: aft.Basis,
    z: FloatArray,
    amplitude: float,
    w_scale: float,
    ref: int,
    *,
    jacobian: bool = True,
    sparse_jacobian: SparseJacobian | None = None,
) -> tuple[FloatArray, Any]:
    """Return EPMC's scaled residual and its exact Jacobian at z (MODEL.md 5.4).

    The HB residual of the free motion with the negative damping -xi M u'
    (:func:`clearjoint.harmonic.aft.evaluate`, which carries the joints' laws and their
    regularised friction mu_s P tanh(v / v_eps) with its slope), divided by k_ref a, and
    the two conditions a_1 = a, b_1 = 0 on the reference DOF.

    Parameters
    ----------
    model : LinearSystem
    basis : aft.Basis
    z : (N (2H + 1) + 2,) ndarray
        The coefficients over a (row-major from (2H + 1, N)), then w and xi over
        ``w_scale``.
    amplitude : float
        The modal amplitude a, m.
    w_scale : float
        The scale of w and xi, rad/s (the closed-pattern frequency).
    ref : int
        The reference DOF.
    jacobian : bool
        False: the Jacobian is an empty (0, 0) array.
    sparse_jacobian : SparseJacobian, optional
        The structure's sparse assembly (:class:`clearjoint.harmonic.solve.SparseJacobian`):
        the Jacobian is then a scipy CSR matrix with the same entries, never dense (a
        large structure's Newton factors it by a sparse LU).

    Returns
    -------
    residual : (N (2H + 1) + 2,) ndarray
    jacobian : (N (2H + 1) + 2, N (2H + 1) + 2) ndarray or scipy CSR matrix
        d residual / d z.
    """
    n, n_c = model.n_dof, 2 * basis.harmonics + 1
    n_u = n_c * n
    k_ref, a = model.reference_stiffness, amplitude
    q, w, xi = z[:n_u] * a, z[n_u] * w_scale, z[n_u + 1] * w_scale
    ev = aft.evaluate(
        model,
        basis,
        q,
        w,
        np.zeros(n),
        negative_damping=xi,
        jacobian=jacobian and sparse_jacobian is None,
    )
    r = np.empty(n_u + 2)
    r[:n_u] = ev.residual / (k_ref * a)
    r[n_u] = z[n + ref] - 1.0  # a_1 on the reference DOF = a
    r[n_u + 1] = z[2 * n + ref]  # b_1 there = 0 (phase)
    if not jacobian:
        return r, np.empty((0, 0))
    d_xi = -w * ((basis.derivative @ q.reshape(n_c, n)) @ model.mass).ravel()
    if sparse_jacobian is not None:
        return r, _sparse_epmc_jacobian(
            sparse_jacobian(ev, w, model.damping - xi * model.mass) * (1.0 / k_ref),
            ev.d_omega * w_scale / (k_ref * a),
            d_xi * w_scale / (k_ref * a),
            n + ref,
            2 * n + ref,
        )
    jac = np.zeros((n_u + 2, n_u + 2))
    jac[:n_u, :n_u] = ev.jacobian / k_ref
    jac[:n_u, n_u] = ev.d_omega * w_scale / (k_ref * a)
    jac[:n_u, n_u + 1] = d_xi * w_scale / (k_ref * a)
    jac[n_u, n + ref] = 1.0
    jac[n_u + 1, 2 * n + ref] = 1.0
    return r, jac


def _sparse_epmc_jacobian(
    jac_u: Any, d_omega: FloatArray, d_xi: FloatArray, a_row: int, b_row: int
) -> Any:
    """[[dR/dq, dR/dw, dR/dxi], [e_a^T, 0, 0], [e_b^T, 0, 0]] as a CSR matrix (as the dense).

    Written straight into CSR arrays (each row of dR/dq, then its non-zero entries of the
    two columns): the same entries as scipy's ``hstack``/``vstack`` of the blocks (which
    drop the columns' zeros), without their COO round trip, a sixth of EPMC's time on the
    40-bay mast (issue 25).
    """
    import scipy.sparse

    jac = scipy.sparse.csr_matrix(jac_u)
    n_u = jac.shape[0]
    has_w, has_xi = d_omega != 0.0, d_xi != 0.0
    own = np.diff(jac.indptr)
    indptr = np.zeros(n_u + 3, dtype=np.int64)
    np.cumsum(own + has_w + has_xi, out=indptr[1 : n_u + 1])
    indptr[n_u + 1] = indptr[n_u] + 1
    indptr[n_u + 2] = indptr[n_u] + 2
    nnz = int(indptr[-1])
    indices = np.empty(nnz, dtype=np.int64)
    data = np.empty(nnz)
    rows = np.repeat(np.arange(n_u), own)
    at = indptr[rows] + (np.arange(jac.indptr[-1]) - jac.indptr[rows])
    indices[at], data[at] = jac.indices, jac.data
    ends = indptr[:n_u] + own
    w_rows = np.flatnonzero(has_w)
    indices[ends[w_rows]], data[ends[w_rows]] = n_u, d_omega[w_rows]
    xi_rows = np.flatnonzero(has_xi)
    xi_at = ends[xi_rows] + has_w[xi_rows]
    indices[xi_at], data[xi_at] = n_u + 1, d_xi[xi_rows]
    indices[nnz - 2 :], data[nnz - 2 :] = (a_row, b_row), 1.0
    return scipy.sparse.csr_matrix((data, indices, indptr), shape=(n_u + 2, n_u + 2))


def _march(
    solve_at: Callable[..., FloatArray | None],
    amps: FloatArray,
    guess: FloatArray,
    same_mode: Callable[[FloatArray, FloatArray], bool],
) -> tuple[dict[int, FloatArray], dict[int, str]]:
    """Solve the amplitudes from the largest down, sub-stepping where Newton fails.

    The closed-pattern mode is the first guess at the largest amplitude, or if Newton
    fails there at 10, 100, ... 10^4 times it, from where the branch is followed down.
    Each next amplitude starts from a secant predictor in log a on the last two
    converged solutions; when Newton fails the step is halved, up to
    :data:`MAX_HALVINGS` times, and after a success doubled again. A solution
    ``same_mode(previous, new)`` refuses (a jump to another mode) counts as a failure.
    Returns (solutions by index, reasons by index of the failed ones); a solution
    depends only on the amplitudes at and above it.
    """
    results: dict[int, FloatArray] = {}
    reasons: dict[int, str] = {}
    start = float(amps[-1])
    path: Path = []
    for k in range(_ABOVE + 1):
        z = solve_at(start * 10.0**k, guess)
        if z is not None:
            path.append((start * 10.0**k, z))
            break
    if not path:
        why = f"no mode from the closed-pattern mode at {start:.3g} m nor at up to 10^{_ABOVE} x it"
        return results, dict.fromkeys(range(amps.size), why)
    for i in range(amps.size - 1, -1, -1):
        if _walk(solve_at, path, float(amps[i]), same_mode):
            results[i] = path[-1][1]
        else:
            reasons[i] = _NEWTON
        report(amps.size - i, amps.size)  # for a progress bar
    return results, reasons


def _walk(
    solve_at: Callable[..., FloatArray | None],
    path: Path,
    target: float,
    same_mode: Callable[[FloatArray, FloatArray], bool],
) -> bool:
    """Step from ``path[-1]`` to amplitude ``target`` in log a; True if it converged there.

    ``path`` holds the last two converged (a, z), updated in place.
    """
    if target == path[-1][0]:
        return True
    full = math.log(target / path[-1][0])
    step, least = full, abs(full) / 2.0**MAX_HALVINGS
    while True:
        a_now, z_now = path[-1]
        left = math.log(target / a_now)
        last = abs(step) >= abs(left) * (1.0 - 1e-12)
        if last:
            step = left
        a = target if last else a_now * math.exp(step)
        guess = z_now
        if len(path) > 1:
            back = math.log(a_now / path[-2][0])
            if back != 0.0:
                guess = z_now + (z_now - path[-2][1]) * (step / back)
        z = solve_at(a, guess, 80 if step == full else _SUB_ITERATIONS)
        if z is None or not same_mode(z_now, z):
            if abs(step) * 0.5 < least * (1.0 - 1e-9):
                return False
            step *= 0.5
            continue
        path.append((a, z))
        del path[:-2]
        if last:
            return True
        step *= 2.0


#: Phases per period on which the holding forces and the turning points are sought.
_TURNS = 1024


def holding_forces(
    model: LinearSystem, basis: aft.Basis, coefficients: FloatArray, omega: float, tau: FloatArray
) -> FloatArray:
    """Return the friction force that would hold each joint still at phases ``tau``, N.

    Joint j stays put (b_j^T u'' = 0) if its friction supplies phi_j = b_j^T M^-1 r /
    (b_j^T M^-1 b_j), r = -K u - C u' - sum_k b_k f_k(delta_k) - sum_(k != j) b_k
    mu_s,k P_k tanh(v_k / v_eps) (MODEL.md sections 2 and 5.2; EPMC's artificial
    -xi M u' left out: it is no force of the free motion). At a turning point of a
    Joint (x' = 0) this is -f(x).

    Parameters
    ----------
    model : LinearSystem
    basis : aft.Basis
    coefficients : (2H + 1, N) ndarray
        The orbit, m.
    omega : float
        w, rad/s.
    tau : (n,) ndarray
        Phases w t, rad.

    Returns
    -------
    (n, n_j) ndarray
        phi_j at each phase, N.
    """
    b = model.directions
    u = basis.evaluate(coefficients, tau)
    du = omega * basis.evaluate(basis.derivative @ coefficients, tau)
    law, _ = model.joint_forces(u @ b.T)
    load = -(u @ model.stiffness.T) - du @ model.damping.T - law @ b
    rub = np.zeros_like(law)
    if model.friction_force is not None:
        rub, _ = model.friction_forces(du @ b.T)
        load = load - rub @ b
    inverse_mass = np.linalg.inv(model.mass)
    per = b @ inverse_mass  # (n_j, N): row j is b_j^T M^-1
    # adding joint j's own friction back: b_j^T M^-1 b_j rub_j
    own = np.einsum("jn,jn->j", per, b)
    return np.asarray((load @ per.T) / own + rub, dtype=np.float64)


def _turning_phases(
    model: LinearSystem, basis: aft.Basis, coefficients: FloatArray
) -> list[FloatArray]:
    """Phases where each joint's relative speed changes sign (grid of :data:`_TURNS`, then
    linear interpolation), rad."""
    tau = 2.0 * math.pi * np.arange(_TURNS) / _TURNS
    speed = basis.evaluate(basis.derivative @ coefficients, tau) @ model.directions.T
    out = []
    for v in speed.T:
        after = np.roll(v, -1)
        turns = np.flatnonzero((v > 0.0) != (after > 0.0))
        share = v[turns] / np.where(v[turns] != after[turns], v[turns] - after[turns], 1.0)
        out.append(tau[turns] + share * (2.0 * math.pi / _TURNS))
    return out


def _held(
    model: LinearSystem,
    basis: aft.Basis,
    amps: FloatArray,
    results: dict[int, FloatArray],
    omega_lin: float,
) -> dict[int, str]:
    """The converged amplitudes where friction holds the motion, with the reason.

    A rubbing joint sticks at a turning point where the force that would hold it
    (:func:`holding_forces`) is at most its mu_s P: the exact Coulomb motion stops there.
    For a Joint that stop is for good; in a Structure the joint stays stuck until the
    rest of the structure pulls it free. The regularised EPMC orbit has no stick phase:
    it creeps through, moved by the negative damping -xi M u', which is no force of the
    free motion (at 3 um on the tests' 2-DOF chain it finds 59 Hz and zeta 1.3 where the
    exact motion keeps the joint locked). So such an amplitude fails, with the reason,
    rather than give a number nothing checks.

    Returns
    -------
    dict
        Failed index -> reason.
    """
    if model.friction_force is None or not results:
        return {}
    rubbing = np.flatnonzero(model.friction_force > 0.0)
    limit = model.friction_force
    n_c, n = 2 * basis.harmonics + 1, model.n_dof
    failed: dict[int, str] = {}
    for i, z in results.items():
        coef = (z[: n_c * n] * amps[i]).reshape(n_c, n)
        w = z[n_c * n] * omega_lin
        phases = _turning_phases(model, basis, coef)
        for j in rubbing.tolist():
            held = np.abs(holding_forces(model, basis, coef, w, phases[j])[:, j])
            if not np.any(held <= limit[j]):
                continue
            if model.is_joint:
                failed[i] = (
                    "friction holds the joint: its restoring force at a turning point is below "
                    f"mu_s P = {float(limit[0]):.3g} N, so the free motion sticks (the orbit "
                    "found is moved by EPMC's negative damping and the regularisation's creep)"
                )
            else:
                failed[i] = (
                    "a rubbing joint sticks at a turning point (the force that would hold it "
                    "is below its mu_s P): EPMC with regularised friction has no stick phase "
                    "(its orbit creeps through, moved by the negative damping); follow the "
                    "forced response with clearjoint.harmonic.frequency_response instead"
                )
            break
    return failed


def _neighbours(
    solve_at: Callable[..., FloatArray | None],
    amps: FloatArray,
    results: dict[int, FloatArray],
    reasons: dict[int, str],
    same_mode: Callable[[FloatArray, FloatArray], bool],
) -> tuple[list[int], list[int]]:
    """Solve the failed amplitudes from their nearest converged neighbours.

    Near contact onset the branch followed down from above can fold back in amplitude
    (an internal resonance with a higher mode, or a gap edge crossed at a sample; see
    docs/harmonic.md), so that no step reaches the amplitudes under the fold from above,
    while the piece of the branch under it reaches them from below. In ascending order,
    each failed amplitude is walked to (:func:`_walk`) up from the nearest converged
    amplitude below it (secant predictor on the two converged below when both are
    there), so a recovered one serves the next; then, in descending order, Newton at
    the full step from the nearest converged one above with no predictor (the march's
    secant, taken along the piece above the fold, points past the solutions under it),
    or from the next nearest if that fails. Both passes repeat while they recover any,
    never trying the same pair of amplitudes twice. ``same_mode`` refuses jumps to
    another mode as in the march. ``results`` and ``reasons`` are updated in place.

    Returns
    -------
    (list of int, list of int)
        The indices reached from below, and from above.
    """
    up: list[int] = []
    down: list[int] = []
    tried: set[tuple[int, int]] = set()
    while True:
        before = len(results)
        for i in sorted(i for i in reasons if reasons[i] == _NEWTON):
            below = [j for j in results if j < i]
            if not below or (i, max(below)) in tried:
                continue
            j = max(below)
            tried.add((i, j))
            path: Path = [(float(amps[j]), results[j])]
            if j - 1 in results:
                path.insert(0, (float(amps[j - 1]), results[j - 1]))
            if _walk(solve_at, path, float(amps[i]), same_mode):
                results[i] = path[-1][1]
                del reasons[i]
                up.append(i)
        for i in sorted((i for i in reasons if reasons[i] == _NEWTON), reverse=True):
            for j in sorted(j for j in results if j > i)[:2]:
                if (i, j) in tried:
                    continue
                tried.add((i, j))
                z = solve_at(float(amps[i]), results[j])
                if z is not None and same_mode(results[j], z):
                    results[i] = z
                    del reasons[i]
                    down.append(i)
                    break
        if len(results) == before:
            return up, down


def _note(amps: FloatArray, reasons: dict[int, str]) -> str:
    """One line per distinct reason: how many amplitudes failed, over which range, and why."""
    lines = []
    for why in sorted(set(reasons.values())):
        at = amps[[i for i, r in reasons.items() if r == why]]
        lines.append(
            f"no mode at {at.size} of {amps.size} amplitudes ({at.min():.3g}..{at.max():.3g} m): "
            f"{why}"
        )
    return "; ".join(lines)


def _open_mode(model: LinearSystem, mode: int, ref: int) -> tuple[float, FloatArray, float]:
    """(contact onset a_c in m, shape phi with phi[ref] = 1, w in rad/s) of the open pattern.

    The linear mode ``mode`` of M and K + k0 (every joint in free-play), scaled to 1 on
    the reference DOF, gives each joint a relative displacement amplitude |b_j^T phi|;
    contact begins at a_c = min_j min(g_c, g_t) / |b_j^T phi|. Below a_c it is an exact
    nonlinear mode. a_c is NaN if undefined (no joint, or phi[ref] = 0).
    """
    import scipy.linalg

    w2, shapes = scipy.linalg.eigh(model.open_stiffness(), model.mass)
    phi = shapes[:, mode - 1]
    w = math.sqrt(max(float(w2[mode - 1]), 0.0))
    if model.directions.shape[0] == 0 or not abs(phi[ref]) > 1e-9 * float(np.max(np.abs(phi))):
        return math.nan, phi, w
    phi = phi / phi[ref]
    swing = np.abs(model.directions @ phi)
    edge = np.minimum(model.g_c, model.g_t)
    with np.errstate(divide="ignore"):
        at = np.where(swing > 0.0, edge / swing, np.inf)
    value = float(np.min(at))
    return (value if math.isfinite(value) else math.nan), phi, w


def _any_contact(
    model: LinearSystem, basis: aft.Basis, amps: FloatArray, results: dict[int, FloatArray]
) -> bool:
    """True if a converged orbit takes some joint to or past a gap edge (or nothing to check)."""
    if not results or model.directions.shape[0] == 0:
        return True
    n_c, n = 2 * basis.harmonics + 1, model.n_dof
    for i, z in results.items():
        delta = (z[: n_c * n] * amps[i]).reshape(n_c, n) @ model.directions.T
        top, bottom = basis.extremes(delta)
        if np.any(top >= model.g_c) or np.any(bottom <= -model.g_t):
            return True
    return False


def _first_guess(
    model: LinearSystem, basis: aft.Basis, shape: FloatArray, omega: float, n_u: int
) -> FloatArray:
    """The closed-pattern linear mode at unit amplitude: a_1 = shape, w = w_closed, xi = 0."""
    n = model.n_dof
    z = np.zeros(n_u + 2)
    z[n : 2 * n] = shape
    z[n_u] = 1.0
    return z


def _mode(
    model: LinearSystem,
    basis: aft.Basis,
    amps: FloatArray,
    results: dict[int, FloatArray],
    mode: int,
    ref: int,
    omega_lin: float,
    note: str = "",
) -> NonlinearMode:
    n, n_c = model.n_dof, 2 * basis.harmonics + 1
    n_u = n_c * n
    count = amps.size
    coef = np.full((count, n_c, n), np.nan)
    omega = np.full(count, np.nan)
    xi = np.full(count, np.nan)
    for i, z in results.items():
        coef[i] = (z[:n_u] * amps[i]).reshape(n_c, n)
        omega[i] = z[n_u] * omega_lin
        xi[i] = z[n_u + 1] * omega_lin
    converged = np.isfinite(omega)
    x_max = np.full((count, n), np.nan)
    x_min = np.full((count, n), np.nan)
    energy = np.full(count, np.nan)
    ok = np.flatnonzero(converged)
    if ok.size:
        cols = coef[ok].transpose(1, 0, 2).reshape(n_c, ok.size * n)
        top, bottom = basis.extremes(cols)
        x_max[ok] = top.reshape(ok.size, n)
        x_min[ok] = bottom.reshape(ok.size, n)
        # integral of u'^T M u' dt over T = 2 pi / w, from the velocity coefficients
        vel = omega[ok, None, None] * np.einsum("cd,pdn->pcn", basis.derivative, coef[ok])
        weights = np.full(n_c, 0.5)
        weights[0] = 1.0
        mean_square = np.einsum("c,pcn,nm,pcm->p", weights, vel, model.mass, vel)
        energy[ok] = xi[ok] * mean_square * (2.0 * math.pi / omega[ok])
    e_max = np.full(count, np.nan)
    for k in ok.tolist():
        e_max[k] = largest_potential_energy(model, basis, coef[k])
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(e_max > 0.0, energy / (4.0 * math.pi * e_max), np.nan)
    shapes = coef
    if model.is_joint:
        x_max, x_min, shapes = x_max[:, 0], x_min[:, 0], coef[:, :, 0]
    return NonlinearMode(
        amplitude=amps,
        x_max=x_max,
        x_min=x_min,
        frequency=omega,
        damping_ratio=ratio,
        energy_per_cycle=energy,
        harmonic_shapes=shapes,
        converged=converged,
        epmc_damping_ratio=xi / (2.0 * omega),
        mode=mode,
        harmonics=basis.harmonics,
        reference_dof=model.dof_names[ref],
        dof_names=() if model.is_joint else tuple(model.dof_names),
        note=note,
    )


def potential_energy(model: LinearSystem, u: FloatArray) -> FloatArray:
    """Return the potential energy 0.5 u^T K u + sum_j V_j(b_j^T u) of states ``u`` (n, N), J.

    V_j is the integral of joint j's piecewise-linear law (MODEL.md section 0) from 0:
    0.5 k0 d^2 + 0.5 k_c max(d - g_c, 0)^2 + 0.5 k_t min(d + g_t, 0)^2; for a Joint
    (K = 0, b = 1) this is ``Joint.potential_energy``. Returns shape (n,).
    """
    delta = u @ model.directions.T
    joints = 0.5 * (
        model.k0 * delta**2
        + model.k_c * np.maximum(delta - model.g_c, 0.0) ** 2
        + model.k_t * np.minimum(delta + model.g_t, 0.0) ** 2
    )
    linear = 0.5 * np.einsum("ti,ij,tj->t", u, model.stiffness, u)
    return np.asarray(linear + joints.sum(axis=1), dtype=np.float64)


def largest_potential_energy(
    model: LinearSystem, basis: aft.Basis, coefficients: FloatArray, fine: int = 1024
) -> float:
    """Return E_max, the largest potential energy over one HB orbit, J.

    Parameters
    ----------
    model : LinearSystem
    basis : aft.Basis
    coefficients : (2H + 1, N) ndarray
        The orbit's harmonic coefficients, m.
    fine : int
        Phases of the first grid; the best one is then refined by a bounded scalar
        search over its two neighbouring intervals (to 1e-12 rad).

    Returns
    -------
    float
        max over tau of :func:`potential_energy` (u(tau)).
    """
    from scipy.optimize import minimize_scalar

    tau = 2.0 * math.pi * np.arange(fine) / fine
    energy = potential_energy(model, basis.evaluate(coefficients, tau))
    best = int(np.argmax(energy))
    step = 2.0 * math.pi / fine

    def negative(t: float) -> float:
        return -float(potential_energy(model, basis.evaluate(coefficients, np.array([t])))[0])

    found = minimize_scalar(
        negative,
        bounds=(tau[best] - step, tau[best] + step),
        method="bounded",
        options={"xatol": 1e-12},
    )
    return max(float(energy[best]), -float(found.fun))
