"""Energy dissipated per cycle by the joint: closed forms, exact cycles, and their gap.

MODEL.md section 2 (paper eqs 10-18). Each mechanism has two routes:

* the closed form on the *free-vibration cycle* at penetration A (fast, the
  paper's estimate): the orbit of ``stiffness.free_orbit``, whose stages are
  sinusoids (or straight lines when k0 = 0), so every integral is exact;
* the integral over the *exact steady cycle* of the forced joint from
  ``clearjoint.simulate`` (the reference), gathered by :func:`compare`.

Mechanisms, per cycle:

* sliding friction (eq 10): exact Coulomb mu_s P x (distance slid), or the paper's
  equivalent viscous form c_P * integral of x'^2 dt with c_P = 4 mu_s P / (pi w X),
  w = w_n(A) on the free cycle;
* contact friction on the pin (eq 12-15): 16 mu_c beta_H k_s^1.5 A_s^2.5 / (15 pi R_p)
  per excursion;
* impact (eq 16): beta m v_s^2 per entry into contact, beta = (1 - e^2) / 2;
* viscous loss of the linear part: c_v * integral of x'^2 dt (when modelled);
* total (eq 17) and the work of the excitation (eq 18).
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from clearjoint import checks as _checks
from clearjoint.contact import hertz_coefficient, hertz_contact
from clearjoint.errors import ParameterError
from clearjoint.joint import Friction, Joint, Losses, Pin, takes_losses
from clearjoint.plotting import dataset_on_amplitude, frame_on_amplitude
from clearjoint.simulate import SteadyState, steady_state
from clearjoint.stiffness import FreeOrbit, free_orbit, viscous_coefficient
from clearjoint.system import VibrationSystem, as_joint

if TYPE_CHECKING:
    import pandas as pd
    import xarray as xr
    from matplotlib.axes import Axes

FloatArray = NDArray[np.float64]

#: Keys of :func:`energies` (and of ``clearjoint dissipation --json``).
ENERGY_KEYS = (
    "sliding_friction_j",
    "sliding_friction_paper_j",
    "contact_friction_j",
    "impact_j",
    "viscous_j",
    "total_j",
    "loss_factor",
    "equivalent_damping_ratio",
    "hertz_half_width_m",
)


# ---- integrals over the free-vibration cycle ------------------------------------------------


def _friction_path(joint: Joint, orbit: FreeOrbit, region: str) -> FloatArray:
    """Distance slid per cycle: the whole path, or only the part inside the gap."""
    if region == "everywhere":
        return 2.0 * (orbit.x_max - orbit.x_min)
    top = np.minimum(orbit.x_max, joint.compression_gap)
    bottom = np.maximum(orbit.x_min, -joint.tension_gap)
    return 2.0 * (top - bottom)


def sliding_friction(
    joint: Joint,
    amplitude: ArrayLike,
    friction: Friction,
    *,
    form: Literal["exact", "paper"] = "exact",
) -> FloatArray:
    """Return the sliding-friction energy per free cycle at penetration A, J (MODEL.md eq 10).

    ``form="exact"``: Coulomb, mu_s P times the distance slid: 4 mu_s P X over the
    whole path (the default, ``friction.region == "everywhere"``), 2 mu_s P c over
    the free-play stroke only. ``form="paper"``: the equivalent viscous form
    c_P * integral of x'^2 dt over the stages where friction acts, with
    c_P = 4 mu_s P / (pi w_n(A) X). The two agree only for sinusoidal motion.
    """
    if not isinstance(friction, Friction):
        raise ParameterError(f"friction must be a clearjoint.Friction, got {friction!r}")
    return _sliding(joint, free_orbit(joint, amplitude), friction, form)


def _sliding(joint: Joint, orbit: FreeOrbit, friction: Friction, form: str) -> FloatArray:
    if form == "exact":
        return friction.force * _friction_path(joint, orbit, friction.region)
    if form != "paper":
        raise ParameterError(f"form must be 'exact' or 'paper', got {form!r}")
    action = orbit.free_play_action
    if friction.region == "everywhere":
        action = action + orbit.contact_action
    omega_n = 2.0 * math.pi / orbit.period
    x_amp = orbit.displacement_amplitude
    with np.errstate(divide="ignore", invalid="ignore"):
        c_p = 4.0 * friction.force / (math.pi * omega_n * x_amp)
        return np.where(np.isfinite(c_p), c_p * action, 0.0)


def contact_friction(
    joint: Joint, amplitude: ArrayLike, pin: Pin, coefficient: float
) -> FloatArray:
    """Return the pin's contact-friction energy per free cycle at penetration A, J (eq 15).

    Two excursions a cycle, each 0 -> A_s -> 0 under F_n = k_s (x - g_s):
    16 mu_c beta_H k_s^1.5 A_s^2.5 / (15 pi R_p) per side.
    """
    mu = _checks.non_negative("contact_friction_coefficient", coefficient)
    return _contact(joint, free_orbit(joint, amplitude), pin, mu)


def _contact(joint: Joint, orbit: FreeOrbit, pin: Pin, mu: float) -> FloatArray:
    factor = 16.0 * mu * hertz_coefficient(pin) / (15.0 * math.pi * pin.radius)
    k_c, k_t = joint.compression_stiffness, joint.tension_stiffness
    compression: FloatArray = orbit.compression_penetration**2.5
    tension: FloatArray = orbit.tension_penetration**2.5
    return factor * (k_c * math.sqrt(k_c) * compression + k_t * math.sqrt(k_t) * tension)


def _restitution(restitution: float) -> float:
    e = _checks.real_scalar("restitution", restitution)
    if not 0.0 <= e <= 1.0:
        raise ParameterError(f"restitution must satisfy 0 <= e <= 1, got {e!r}")
    return e


def impact(joint: Joint, amplitude: ArrayLike, restitution: float) -> FloatArray:
    """Return the impact energy per free cycle at penetration A, J (MODEL.md eq 16).

    beta m (v_c^2 + v_t^2), beta = (1 - e^2) / 2, with v_s the speed at which the
    free orbit reaches each gap edge (v_s = A_s w_s when k0 = 0).
    """
    return _impact(joint, free_orbit(joint, amplitude), _restitution(restitution))


def _impact(joint: Joint, orbit: FreeOrbit, e: float) -> FloatArray:
    beta = 0.5 * (1.0 - e * e)
    return beta * joint.mass * (orbit.compression_speed**2 + orbit.tension_speed**2)


def viscous(joint: Joint, amplitude: ArrayLike, damping_ratio: float) -> FloatArray:
    """Return the viscous loss c_v * integral of x'^2 dt per free cycle at penetration A, J."""
    c_v = viscous_coefficient(joint, damping_ratio)
    return _viscous(free_orbit(joint, amplitude), c_v)


def _viscous(orbit: FreeOrbit, c_v: float) -> FloatArray:
    return c_v * (orbit.contact_action + orbit.free_play_action)


@takes_losses
def total(
    joint: Joint | VibrationSystem,
    amplitude: ArrayLike,
    *,
    form: Literal["exact", "paper"] = "exact",
    losses: Losses | None = None,
) -> FloatArray:
    """Return E_Z = E_P + E_C + E_I (+ viscous) per free cycle at penetration A, J (eq 17).

    The mechanisms are those of ``losses`` (:class:`~clearjoint.Losses`, default none),
    or of the one-DOF VibrationSystem given as ``joint``.
    """
    joint, losses = as_joint(joint, losses)
    result = impact(joint, amplitude, losses.restitution)
    if losses.friction is not None:
        result = result + sliding_friction(joint, amplitude, losses.friction, form=form)
    if losses.pin is not None:
        mu_c = losses.contact_friction_coefficient
        result = result + contact_friction(joint, amplitude, losses.pin, mu_c)
    if losses.damping_ratio:
        result = result + viscous(joint, amplitude, losses.damping_ratio)
    return result


def excitation_work(
    time: ArrayLike, velocity: ArrayLike, force_amplitude: float, omega: float
) -> float:
    """Return E_F, the work of F0 sin(w t) over a sampled periodic motion, J (MODEL.md eq 18).

    ``time`` (N,) s, uniformly sampled over a whole number of forcing periods
    without repeating the end point; ``velocity`` (N,) m/s. The rectangle rule is
    spectrally accurate for smooth periodic integrands. For the exact steady
    cycle, ``SteadyState.energy.input`` gives the same integral to round-off.
    """
    t = np.asarray(time, dtype=np.float64)
    v = np.asarray(velocity, dtype=np.float64)
    if t.ndim != 1 or t.shape != v.shape or t.size < 8:
        raise ParameterError("time and velocity must be 1-D arrays of the same length (>= 8)")
    f0 = _checks.positive("force_amplitude", force_amplitude, unit="N")
    w = _checks.positive("omega", omega, unit="rad/s")
    dt = np.diff(t)
    if not np.all(np.isfinite(t)) or np.any(dt <= 0.0):
        raise ParameterError("time must be finite and strictly increasing")
    if np.ptp(dt) > 1e-6 * dt.mean():
        raise ParameterError("time must be uniformly sampled")
    return float(np.sum(f0 * np.sin(w * t) * v) * dt.mean())


def loss_factor(joint: Joint, amplitude: ArrayLike, energy: ArrayLike) -> FloatArray:
    """Return eta = E / (2 pi U_max), U_max = V(x_max) of the free cycle at penetration A."""
    return _loss_factor(joint, free_orbit(joint, amplitude), energy)


def _loss_factor(joint: Joint, orbit: FreeOrbit, energy: ArrayLike) -> FloatArray:
    u_max = joint.potential_energy(orbit.x_max)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(u_max > 0.0, np.asarray(energy) / (2.0 * math.pi * u_max), np.nan)


@takes_losses
def energies(
    joint: Joint | VibrationSystem,
    amplitude: ArrayLike,
    *,
    losses: Losses | None = None,
) -> Energies:
    """Return every energy per free cycle at penetration A, keyed as ``ENERGY_KEYS`` (SI).

    ``total_j`` uses the exact sliding-friction form; ``sliding_friction_paper_j``
    is the paper's equivalent-viscous form beside it. ``hertz_half_width_m`` is the
    half-width at the largest contact force of the cycle (0 without a pin). The
    mechanisms as for :func:`total`.
    """
    joint, losses = as_joint(joint, losses)
    friction, pin, mu_c = losses.friction, losses.pin, losses.contact_friction_coefficient
    e, damping_ratio = losses.restitution, losses.damping_ratio
    c_v = viscous_coefficient(joint, damping_ratio)
    orbit = free_orbit(joint, amplitude)  # once, for every mechanism
    zero = np.zeros_like(orbit.period)
    slide = _sliding(joint, orbit, friction, "exact") if friction else zero
    slide_paper = _sliding(joint, orbit, friction, "paper") if friction else zero
    contact = _contact(joint, orbit, pin, mu_c) if pin is not None else zero
    hits = _impact(joint, orbit, e)
    loss = _viscous(orbit, c_v) if damping_ratio else zero
    everything = slide + contact + hits + loss
    eta = _loss_factor(joint, orbit, everything)
    if pin is not None:
        peak = np.maximum(
            joint.compression_stiffness * orbit.compression_penetration,
            joint.tension_stiffness * orbit.tension_penetration,
        )
        width = hertz_contact(pin, peak).half_width
    else:
        width = zero
    return Energies(
        amplitude=np.asarray(amplitude, dtype=np.float64) + zero,
        sliding_friction_j=slide,
        sliding_friction_paper_j=slide_paper,
        contact_friction_j=contact,
        impact_j=hits,
        viscous_j=loss,
        total_j=everything,
        loss_factor=eta,
        equivalent_damping_ratio=0.5 * eta,
        hertz_half_width_m=width,
    )


#: Units of the keys of :data:`ENERGY_KEYS`, for tables and netCDF attributes.
ENERGY_UNITS = {
    key: ("J" if key.endswith("_j") else "m" if key.endswith("_m") else "1") for key in ENERGY_KEYS
}

#: The mechanisms :meth:`Energies.plot` draws, with their legend labels.
_PLOTTED = {
    "sliding_friction_j": "sliding friction E_P",
    "contact_friction_j": "contact friction E_C",
    "impact_j": "impact E_I",
    "viscous_j": "viscous",
    "total_j": "total E_Z",
}


@dataclass(frozen=True, eq=False)
class Energies(Mapping[str, FloatArray]):
    """Every energy per free cycle at penetration A: what :func:`energies` returns (SI).

    A read-only mapping keyed as :data:`ENERGY_KEYS` (``values["total_j"]``), whose
    entries are also attributes (``values.total_j``); every array is shaped like
    ``amplitude``.

    Attributes
    ----------
    amplitude : ndarray
        Penetration A beyond the compression gap edge, m.
    sliding_friction_j, sliding_friction_paper_j : ndarray
        Sliding friction per cycle, exact and in the paper's viscous form, J (eq 10).
    contact_friction_j, impact_j, viscous_j : ndarray
        Contact friction on the pin (eq 15), impact (eq 16) and viscous loss per cycle, J.
    total_j : ndarray
        Their total E_Z, J (eq 17, with the exact sliding friction).
    loss_factor, equivalent_damping_ratio : ndarray
        eta = E_Z / (2 pi U_max) and eta / 2.
    hertz_half_width_m : ndarray
        Hertz half-width at the cycle's largest contact force, m (0 without a pin).
    """

    amplitude: FloatArray
    sliding_friction_j: FloatArray
    sliding_friction_paper_j: FloatArray
    contact_friction_j: FloatArray
    impact_j: FloatArray
    viscous_j: FloatArray
    total_j: FloatArray
    loss_factor: FloatArray
    equivalent_damping_ratio: FloatArray
    hertz_half_width_m: FloatArray

    def __getitem__(self, key: str) -> FloatArray:
        if key not in ENERGY_UNITS:
            raise KeyError(key)
        value: FloatArray = getattr(self, key)
        return value

    def __iter__(self) -> Iterator[str]:
        return iter(ENERGY_KEYS)

    def __len__(self) -> int:
        return len(ENERGY_KEYS)

    def __repr__(self) -> str:
        a = np.atleast_1d(self.amplitude)
        e = np.atleast_1d(self.total_j)
        eta = np.atleast_1d(self.loss_factor)

        def span(values: FloatArray, scale: float) -> str:
            low, high = float(np.nanmin(values)) * scale, float(np.nanmax(values)) * scale
            return f"{low:.4g}" if low == high else f"{low:.4g} to {high:.4g}"

        return (
            f"Energies({a.size} amplitude{'s' if a.size != 1 else ''}, "
            f"A = {span(a, 1e6)} um: total {span(e, 1e3)} mJ per cycle, "
            f"loss factor {span(eta, 1.0) if np.any(np.isfinite(eta)) else 'nan'})"
        )

    def to_xarray(self) -> xr.Dataset:
        """Return the energies as an ``xarray.Dataset`` on ``amplitude``, units in attrs.

        Returns
        -------
        xarray.Dataset
            Coordinate ``amplitude`` (N,) in m; one variable (N,) per key of
            :data:`ENERGY_KEYS`, each with ``attrs["units"]`` (J, m or 1).

        Raises
        ------
        ParameterError
            The energies were computed on a grid of more than one dimension.
        """
        return dataset_on_amplitude(
            self.amplitude,
            {key: (self[key], unit) for key, unit in ENERGY_UNITS.items()},
            {"title": "clearjoint energies per free cycle"},
        )

    def to_pandas(self) -> pd.DataFrame:
        """Return the energies as a ``pandas.DataFrame``: index ``amplitude_m``, one column a key.

        Returns
        -------
        pandas.DataFrame
            (N, 9): the keys of :data:`ENERGY_KEYS` as columns (their names carry the unit).
        """
        return frame_on_amplitude(self.amplitude, {key: self[key] for key in ENERGY_KEYS})

    def plot(self, ax: Axes | None = None) -> Axes:
        """Draw each mechanism's energy per cycle (mJ) against A (um), log-log; return the Axes.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Where to draw; a new figure's Axes when None.

        Returns
        -------
        matplotlib.axes.Axes
            One line per mechanism that dissipates anything, labelled as in the
            legend (``"total E_Z"`` last, thicker).
        """
        from clearjoint.plotting import axes_or_new, one_dimensional

        axes: Axes = axes_or_new(ax)
        a = one_dimensional("amplitude", self.amplitude)
        styles = ["--", "-.", ":", (0, (5, 1, 1, 1))]
        few = a.size < 20
        for i, (key, label) in enumerate(_PLOTTED.items()):
            energy = np.broadcast_to(self[key], a.shape)
            if key != "total_j" and not np.any(energy > 0.0):
                continue
            axes.plot(
                a * 1e6,
                energy * 1e3,
                linestyle="-" if key == "total_j" else styles[i % len(styles)],
                lw=2.2 if key == "total_j" else 1.3,
                color="black",
                marker="o" if few else None,
                label=label,
            )
        if np.all(a > 0.0):
            axes.set_xscale("log")
        if np.all(np.broadcast_to(self.total_j, a.shape) > 0.0):
            axes.set_yscale("log")
        axes.set_xlabel("amplitude beyond the gap edge A (µm)")
        axes.set_ylabel("energy per cycle (mJ)")
        axes.legend(frameon=False, fontsize="small")
        return axes


# ---- closed form against the exact steady cycle --------------------------------------------


@dataclass(frozen=True)
class Comparison:
    """The same energies by two routes, with their relative gap (closed / exact - 1).

    ``closed`` is on the free cycle at the exact cycle's compression penetration;
    ``exact`` integrates over the forced steady cycle; ``cycle`` is that cycle.
    Energy keys are those of :data:`ENERGY_KEYS` ending in ``_j``.
    """

    penetration: float
    closed: dict[str, float]
    exact: dict[str, float]
    gap: dict[str, float]
    cycle: SteadyState

    def __repr__(self) -> str:
        worst = max(self.gap, key=lambda key: abs(self.gap[key]), default="total_j")
        return (
            f"Comparison(A = {self.penetration * 1e6:.4g} um: total closed "
            f"{self.closed.get('total_j', math.nan) * 1e3:.4g} mJ, exact "
            f"{self.exact.get('total_j', math.nan) * 1e3:.4g} mJ, gap "
            f"{self.gap.get('total_j', math.nan):+.3g}; largest gap {worst} "
            f"{self.gap.get(worst, math.nan):+.3g})"
        )

    def to_xarray(self) -> xr.Dataset:
        """Return both routes' energies and their gap as an ``xarray.Dataset``, units in attrs.

        Returns
        -------
        xarray.Dataset
            On ``energy`` (the keys of :attr:`exact`): ``closed`` and ``exact`` (J) and
            ``gap`` (closed / exact - 1); 0-d ``penetration`` (m). The cycle itself is
            ``cycle.to_xarray()``.
        """
        import xarray as xr

        keys = list(self.exact)
        return xr.Dataset(
            {
                "closed": ("energy", [self.closed[k] for k in keys], {"units": "J"}),
                "exact": ("energy", [self.exact[k] for k in keys], {"units": "J"}),
                "gap": ("energy", [self.gap[k] for k in keys], {"units": "1"}),
                "penetration": ((), self.penetration, {"units": "m"}),
            },
            coords={"energy": ("energy", keys)},
            attrs={"title": "clearjoint energies per cycle: closed form against the exact cycle"},
        )

    def to_pandas(self) -> pd.DataFrame:
        """Return both routes' energies as a ``pandas.DataFrame``, one row per energy.

        Returns
        -------
        pandas.DataFrame
            Index ``energy`` (the keys of :attr:`exact`); columns ``closed_j``,
            ``exact_j`` and ``gap`` (closed / exact - 1).
        """
        import pandas as pd

        keys = list(self.exact)
        return pd.DataFrame(
            {
                "closed_j": [self.closed[k] for k in keys],
                "exact_j": [self.exact[k] for k in keys],
                "gap": [self.gap[k] for k in keys],
            },
            index=pd.Index(keys, name="energy"),
        )

    def plot(self, ax: Axes | None = None) -> Axes:
        """Draw each energy by both routes side by side as bars (mJ); return the Axes.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Where to draw; a new figure's Axes when None.

        Returns
        -------
        matplotlib.axes.Axes
            Two bar containers, "closed form" then "exact cycle", one bar per energy.
        """
        from clearjoint.plotting import axes_or_new

        axes: Axes = axes_or_new(ax)
        keys = list(self.exact)
        at = np.arange(len(keys), dtype=np.float64)
        axes.bar(
            at - 0.2, [self.closed[k] * 1e3 for k in keys], 0.4, color="0.4", label="closed form"
        )
        axes.bar(
            at + 0.2, [self.exact[k] * 1e3 for k in keys], 0.4, color="0.8", label="exact cycle"
        )
        axes.set_xticks(at, [k.removesuffix("_j") for k in keys], rotation=30, ha="right")
        axes.set_ylabel("energy per cycle (mJ)")
        axes.set_title(f"A = {self.penetration * 1e6:.4g} µm", fontsize="small")
        axes.legend(frameon=False, fontsize="small")
        return axes


def _exact_energies(
    cycle: SteadyState,
    joint: Joint,
    friction: Friction | None,
    omega: float,
) -> dict[str, float]:
    ledger = cycle.energy
    paper = 0.0
    if friction is not None and friction.force > 0.0:
        # c_P with the forcing frequency and the cycle's own X, over the stages where it acts
        v2 = cycle.velocity**2
        if friction.region == "free-play":
            inside = (cycle.displacement < joint.compression_gap) & (
                cycle.displacement > -joint.tension_gap
            )
            v2 = np.where(inside, v2, 0.0)
        action = float(np.mean(v2)) * cycle.period
        paper = 4.0 * friction.force / (math.pi * omega * cycle.amplitude) * action
    return {
        "sliding_friction_j": ledger.sliding_friction,
        "sliding_friction_paper_j": paper,
        "contact_friction_j": ledger.contact_friction,
        "impact_j": ledger.impact,
        "viscous_j": ledger.viscous,
        "total_j": ledger.sliding_friction
        + ledger.contact_friction
        + ledger.impact
        + ledger.viscous,
    }


@takes_losses
def compare(
    joint: Joint | VibrationSystem,
    force_amplitude: float,
    omega: float,
    *,
    initial: ArrayLike | None = None,
    samples_per_period: int = 1024,
    max_periods: int = 20_000,
    losses: Losses | None = None,
) -> Comparison:
    """Return each energy by the closed form and over the exact steady cycle, with their gap.

    The forced steady cycle at F0 sin(omega t) (omega in rad/s) is simulated
    exactly; the closed forms are evaluated on the free cycle at that cycle's
    compression penetration A = x_max - g_c. The losses as for :func:`total`.
    """
    joint, losses = as_joint(joint, losses)
    cycle = steady_state(
        joint,
        force_amplitude,
        omega,
        losses=losses,
        initial=initial,
        samples_per_period=samples_per_period,
        max_periods=max_periods,
    )
    a = cycle.compression_penetration
    closed_all = energies(joint, a, losses=losses)
    exact = _exact_energies(cycle, joint, losses.friction, omega)
    closed = {key: float(closed_all[key]) for key in exact}
    gap = {
        key: (closed[key] / exact[key] - 1.0)
        if exact[key] != 0.0
        else (0.0 if closed[key] == 0.0 else math.inf)
        for key in exact
    }
    return Comparison(penetration=a, closed=closed, exact=exact, gap=gap, cycle=cycle)


@dataclass(frozen=True)
class AgreementMap:
    """Where the closed forms agree with the exact cycle, over forcing frequency and force.

    ``omega`` (F,) rad/s and ``force`` (N,) N span the grid; ``penetration`` (F, N)
    is the exact cycle's A = x_max - g_c in m; ``gap[key]`` (F, N) is closed / exact - 1
    for each energy key of :class:`Comparison`. NaN where no periodic orbit was found.
    """

    omega: FloatArray
    force: FloatArray
    penetration: FloatArray
    gap: dict[str, FloatArray]

    def __repr__(self) -> str:
        f = self.omega / (2 * math.pi)
        found = int(np.sum(np.isfinite(self.penetration)))
        total = self.gap.get("total_j")
        worst = (
            f", largest |gap| of the total {float(np.nanmax(np.abs(total))):.3g}"
            if total is not None and np.any(np.isfinite(total))
            else ""
        )
        return (
            f"AgreementMap({self.omega.size} x {self.force.size} grid, "
            f"{f.min():.4g}-{f.max():.4g} Hz, F0 {self.force.min():.4g}-{self.force.max():.4g} N, "
            f"{found} points with an orbit{worst})"
        )

    def to_xarray(self) -> xr.Dataset:
        """Return the map as an ``xarray.Dataset`` on (``omega``, ``force``), units in attrs.

        Returns
        -------
        xarray.Dataset
            Coordinates ``omega`` (F,) rad/s (with ``frequency`` in Hz) and ``force`` (N,) N;
            ``penetration`` (F, N) in m and ``gap_<key>`` (F, N) for each energy key
            (closed / exact - 1, unit 1); NaN where no orbit was found.
        """
        import xarray as xr

        dims = ("omega", "force")
        return xr.Dataset(
            {
                "penetration": (dims, self.penetration, {"units": "m"}),
                **{f"gap_{key}": (dims, value, {"units": "1"}) for key, value in self.gap.items()},
            },
            coords={
                "omega": ("omega", self.omega, {"units": "rad/s"}),
                "frequency": ("omega", self.omega / (2 * math.pi), {"units": "Hz"}),
                "force": ("force", self.force, {"units": "N"}),
            },
            attrs={"title": "clearjoint agreement of the closed forms with the exact cycle"},
        )

    def to_pandas(self) -> pd.DataFrame:
        """Return the map as a ``pandas.DataFrame``, one row per (omega, force) point.

        Returns
        -------
        pandas.DataFrame
            ``to_xarray().to_dataframe()``: index (``omega`` rad/s, ``force`` N); columns
            ``frequency`` (Hz), ``penetration`` (m) and ``gap_<key>`` of each energy.
        """
        return self.to_xarray().to_dataframe()

    def plot(self, ax: Axes | None = None) -> Axes:
        """Draw the total energy's gap over frequency (Hz) and force (N); return the Axes.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Where to draw; a new figure's Axes when None.

        Returns
        -------
        matplotlib.axes.Axes
            One QuadMesh: closed / exact - 1 of ``total_j`` (the penetration in um when
            no gap was computed), blank where no orbit was found, with a colour bar.
        """
        from clearjoint.plotting import axes_or_new

        axes: Axes = axes_or_new(ax)
        total = self.gap.get("total_j")
        values, label = (
            (total, "gap of the total, closed / exact - 1")
            if total is not None
            else (self.penetration * 1e6, "penetration A (µm)")
        )
        mesh = axes.pcolormesh(
            self.omega / (2 * math.pi), self.force, values.T, shading="nearest", cmap="RdBu_r"
        )
        axes.figure.colorbar(mesh, ax=axes, label=label)
        axes.set_xlabel("frequency (Hz)")
        axes.set_ylabel("force amplitude F0 (N)")
        return axes


def _agreement_row(
    args: tuple[Joint, float, FloatArray, Losses, int],
) -> tuple[FloatArray, dict[str, FloatArray]]:
    """One frequency of :func:`agreement_map`: the forces stepped upward from rest."""
    from clearjoint.simulate import SimulationError

    joint, omega, f, losses, max_periods = args
    penetration = np.full(f.size, np.nan)
    gaps: dict[str, FloatArray] = {}
    initial: tuple[float, float, int, int] | None = None
    for n, force in enumerate(f):
        try:
            result = compare(
                joint,
                float(force),
                omega,
                losses=losses,
                initial=initial,
                samples_per_period=128,
                max_periods=max_periods,
            )
        except SimulationError:
            continue
        initial = result.cycle.initial_state
        penetration[n] = result.penetration
        for key, value in result.gap.items():
            gaps.setdefault(key, np.full(f.size, np.nan))[n] = value
    return penetration, gaps


@takes_losses
def agreement_map(
    joint: Joint | VibrationSystem,
    omegas: ArrayLike,
    forces: ArrayLike,
    *,
    max_periods: int = 2000,
    executor: Any = None,
    losses: Losses | None = None,
) -> AgreementMap:
    """Return the closed-form-to-exact gap of every energy over a grid of (omega, F0).

    At each frequency the forces are stepped upward, each step starting from the
    last steady state (as a test rig would), so every point is an exact steady
    cycle compared with the closed forms at its own penetration (:func:`compare`).
    Frequencies run one after the other here, or side by side on ``executor`` (a
    concurrent.futures Executor or a dask.distributed Client: clearjoint.parallel),
    with the same result. The losses as for :func:`total`.
    """
    joint, losses = as_joint(joint, losses)
    from clearjoint.parallel import run_ordered

    w = np.atleast_1d(np.asarray(omegas, dtype=np.float64))
    f = np.sort(np.atleast_1d(np.asarray(forces, dtype=np.float64)))
    rows = run_ordered(
        _agreement_row,
        [(joint, float(omega), f, losses, max_periods) for omega in w],
        executor,
    )
    penetration = np.full((w.size, f.size), np.nan)
    gaps: dict[str, FloatArray] = {}
    for i, (row_penetration, row_gaps) in enumerate(rows):
        penetration[i] = row_penetration
        for key, value in row_gaps.items():
            gaps.setdefault(key, np.full((w.size, f.size), np.nan))[i] = value
    return AgreementMap(omega=w, force=f, penetration=penetration, gap=gaps)
