"""Dynamic stiffness of a clearance joint from the period of its free vibration.

MODEL.md section 1. The free motion m x'' + f(x) = 0 (eq 1) is a chain of
sinusoids joined at the gap edges, so its period T is exact in closed form
(eqs 2-5; eq 6 is the k0 = 0 case). From it: the natural frequency
w_n = 2 pi / T, the dynamic stiffness k_d = m w_n^2 (eq 8) and the stiffness
coefficient c_d = k_d / k_inf (eq 9). The first-harmonic describing function
of the same f(x) gives a second equivalent stiffness, and eq 7 turns either
into the amplitude of the forced response (a fixed point, solved on all
branches).

Every function here is vectorised over the amplitude and parameterised, as
MODEL.md is, by the penetration A = A_c beyond the compression gap edge, with
the orbit's energy H = V(g_c + A).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from clearjoint import checks as _checks
from clearjoint.errors import ParameterError
from clearjoint.joint import Joint
from clearjoint.laws import Spring
from clearjoint.plotting import dataset_on_amplitude, frame_on_amplitude

if TYPE_CHECKING:
    import pandas as pd
    import xarray as xr
    from matplotlib.axes import Axes

FloatArray = NDArray[np.float64]

__all__ = [
    "FreeOrbit",
    "ResponseBranch",
    "StiffnessCurve",
    "describing_stiffness",
    "dynamic_stiffness",
    "equivalent_linear_response",
    "free_orbit",
    "natural_frequency",
    "period",
    "stiffness_coefficient",
    "stiffness_curve",
    "viscous_coefficient",
]


@dataclass(frozen=True)
class FreeOrbit:
    """The free-vibration orbit of a joint at compression penetration A (MODEL.md eq 1-5).

    Every field is an array broadcast like the amplitude given to :func:`free_orbit`.

    Attributes
    ----------
    compression_penetration, tension_penetration : ndarray
        A_c and A_t, how far the orbit goes beyond each gap edge, m (0 if that
        side is never touched).
    compression_speed, tension_speed : ndarray
        Speed at which the mass reaches each gap edge, m/s (0 if never reached).
    compression_touched, tension_touched : ndarray of bool
        Whether the orbit enters contact on each side.
    x_max, x_min : ndarray
        Turning points of the orbit, m.
    compression_time, tension_time : ndarray
        Time spent in contact on each side per cycle, s.
    free_play_time : ndarray
        Time spent inside the gap per cycle, s.
    period : ndarray
        The period T, s (inf when the mass never moves: k0 = 0 and A = 0 with c > 0).
    contact_action, free_play_action : ndarray
        The integral of x'^2 dt over one cycle, in contact and inside the gap, m^2/s
        (what viscous damping and the paper's equivalent friction damping dissipate).
    """

    compression_penetration: FloatArray
    tension_penetration: FloatArray
    compression_speed: FloatArray
    tension_speed: FloatArray
    compression_touched: NDArray[np.bool_]
    tension_touched: NDArray[np.bool_]
    x_max: FloatArray
    x_min: FloatArray
    compression_time: FloatArray
    tension_time: FloatArray
    free_play_time: FloatArray
    period: FloatArray
    contact_action: FloatArray
    free_play_action: FloatArray

    @property
    def displacement_amplitude(self) -> FloatArray:
        """X = (x_max - x_min) / 2, m."""
        return 0.5 * (self.x_max - self.x_min)

    def __repr__(self) -> str:
        a = np.atleast_1d(self.compression_penetration) * 1e6
        x = np.atleast_1d(self.displacement_amplitude) * 1e6
        t = np.atleast_1d(self.period) * 1e3

        def span(values: FloatArray) -> str:
            low, high = float(np.min(values)), float(np.max(values))
            return f"{low:.4g}" if low == high else f"{low:.4g}-{high:.4g}"

        return (
            f"FreeOrbit({a.size} amplitude{'s' if a.size != 1 else ''}, A_c = {span(a)} um: "
            f"X = {span(x)} um, T = {span(t)} ms)"
        )

    def _columns(self) -> dict[str, tuple[NDArray[Any], str]]:
        """Return each field but A_c with its unit: the variables of :meth:`to_xarray`."""
        return {
            "tension_penetration": (self.tension_penetration, "m"),
            "compression_speed": (self.compression_speed, "m/s"),
            "tension_speed": (self.tension_speed, "m/s"),
            "compression_touched": (self.compression_touched, "1 touched, 0 not"),
            "tension_touched": (self.tension_touched, "1 touched, 0 not"),
            "x_max": (self.x_max, "m"),
            "x_min": (self.x_min, "m"),
            "displacement_amplitude": (self.displacement_amplitude, "m"),
            "compression_time": (self.compression_time, "s"),
            "tension_time": (self.tension_time, "s"),
            "free_play_time": (self.free_play_time, "s"),
            "period": (self.period, "s"),
            "contact_action": (self.contact_action, "m^2/s"),
            "free_play_action": (self.free_play_action, "m^2/s"),
        }

    def to_xarray(self) -> xr.Dataset:
        """Return the orbits as an ``xarray.Dataset`` on ``amplitude`` (A_c), units in attrs.

        Returns
        -------
        xarray.Dataset
            Coordinate ``amplitude`` (N,): the compression penetration A_c in m; one
            variable (N,) per other field (and ``displacement_amplitude``), each with
            ``attrs["units"]``.

        Raises
        ------
        ParameterError
            The orbits were computed on a grid of more than one dimension.
        """
        return dataset_on_amplitude(
            self.compression_penetration,
            self._columns(),
            {"title": "clearjoint free-vibration orbits against penetration"},
        )

    def to_pandas(self) -> pd.DataFrame:
        """Return the orbits as a ``pandas.DataFrame``, one row per penetration A_c.

        Returns
        -------
        pandas.DataFrame
            ``to_xarray().to_dataframe()``: index ``amplitude`` (A_c, m), one column per
            field (units in :meth:`to_xarray`'s attrs).
        """
        return self.to_xarray().to_dataframe()

    def plot(self, ax: Axes | None = None) -> Axes:
        """Draw the period and the time in contact and in the gap (ms) against A_c; return the Axes.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Where to draw; a new figure's Axes when None.

        Returns
        -------
        matplotlib.axes.Axes
            Four lines: period T, compression, tension and free-play time per cycle.
        """
        from clearjoint.plotting import axes_or_new, one_dimensional

        axes: Axes = axes_or_new(ax)
        a = one_dimensional("amplitude", self.compression_penetration)
        marker = "o" if a.size < 20 else None
        for values, style, label in (
            (self.period, "-", "period T"),
            (self.compression_time, "--", "in compression"),
            (self.tension_time, "-.", "in tension"),
            (self.free_play_time, ":", "in free play"),
        ):
            axes.plot(
                a * 1e6,
                np.broadcast_to(values, a.shape) * 1e3,
                style,
                color="black",
                marker=marker,
                label=label,
            )
        axes.set_xlabel("compression penetration A_c (µm)")
        axes.set_ylabel("time per cycle (ms)")
        axes.legend(frameon=False, fontsize="small")
        return axes


def _contact_time(speed: FloatArray, y0: float, omega_s: float) -> FloatArray:
    """Time of one contact excursion entered at ``speed`` (MODEL.md sec. 1).

    Duration 2 atan2(v_s, y0 w_s) / w_s; when y0 = 0 (k0 = 0 or an edge at
    x = 0) the excursion is a half sine, pi / w_s, at any speed, including the
    limit of vanishing speed.
    """
    if y0 == 0.0:
        return np.full_like(speed, math.pi / omega_s)
    return 2.0 * np.arctan2(speed, y0 * omega_s) / omega_s


def _crossing_time(gap: float, speed: FloatArray, omega_0: float) -> FloatArray:
    """Time in free-play from x = 0 to a gap edge at distance ``gap`` reached at ``speed``.

    atan2(w0 g, v_g) / w0, which is g / v_g when k0 = 0 (constant speed) and
    pi / (2 w0) when the edge is never reached (``speed`` clamped to 0).
    """
    if gap == 0.0:
        return np.zeros_like(speed)
    if omega_0 > 0.0:
        return np.arctan2(omega_0 * gap, speed) / omega_0
    with np.errstate(divide="ignore"):
        return gap / speed


def _free_play_action(
    gap: float, speed: FloatArray, crossing: FloatArray, omega_0: float
) -> FloatArray:
    """Integral of x'^2 dt from x = 0 to an edge at ``gap`` reached at ``speed`` in ``crossing``.

    (g v_g + (v_g^2 + w0^2 g^2) t_g) / 2, which is g v_g at constant speed (k0 = 0).
    """
    if omega_0 > 0.0:
        return 0.5 * (gap * speed + (speed**2 + (omega_0 * gap) ** 2) * crossing)
    return gap * speed


def _edge_speeds_squared(joint: Spring, amplitude: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Squared speeds at the compression and tension edges for energy H = V(g_c + A).

    Written without cancellation: 2H/m - w0^2 g^2 factored by hand. The tension
    value is negative when the orbit does not reach that edge.
    """
    m, k0, k_c = joint.mass, joint.gap_stiffness, joint.compression_stiffness
    g_c, g_t = joint.compression_gap, joint.tension_gap
    contact = k_c * amplitude * amplitude
    v_c2 = (k0 * amplitude * (2.0 * g_c + amplitude) + contact) / m
    v_t2 = (k0 * (amplitude + (g_c - g_t)) * (amplitude + (g_c + g_t)) + contact) / m
    return v_c2, v_t2


def _omegas(joint: Spring) -> tuple[float, float, float]:
    m, k0 = joint.mass, joint.gap_stiffness
    return (
        math.sqrt(k0 / m),
        math.sqrt((k0 + joint.compression_stiffness) / m),
        math.sqrt((k0 + joint.tension_stiffness) / m),
    )


def _edge_offsets(joint: Spring) -> tuple[float, float]:
    """y0 = k0 g_s / (k0 + k_s): how far each gap edge lies outside its contact equilibrium."""
    k0 = joint.gap_stiffness
    y0_c = k0 * joint.compression_gap / (k0 + joint.compression_stiffness)
    y0_t = k0 * joint.tension_gap / (k0 + joint.tension_stiffness)
    return y0_c, y0_t


def _period(joint: Spring, amplitude: FloatArray) -> FloatArray:
    """The exact period for validated amplitudes (the fast path of :func:`period`)."""
    omega_0, omega_c, omega_t = _omegas(joint)
    y0_c, y0_t = _edge_offsets(joint)
    v_c2, v_t2 = _edge_speeds_squared(joint, amplitude)
    v_c = np.sqrt(v_c2)
    v_t = np.sqrt(np.maximum(v_t2, 0.0))
    return (
        _contact_time(v_c, y0_c, omega_c)
        + _contact_time(v_t, y0_t, omega_t)
        + 2.0 * _crossing_time(joint.compression_gap, v_c, omega_0)
        + 2.0 * _crossing_time(joint.tension_gap, v_t, omega_0)
    )


def _amplitude(amplitude: ArrayLike, name: str = "amplitude") -> FloatArray:
    return _checks.non_negative_array(name, amplitude, unit="m")


def free_orbit(joint: Joint, amplitude: ArrayLike) -> FreeOrbit:
    """Return the free-vibration orbit (turning points, edge speeds, stage times) at penetration A.

    MODEL.md eq 1-5, general case (k0 >= 0, k_c != k_t, off-centre gap).

    Parameters
    ----------
    joint : Joint
    amplitude : float or (N,) array_like
        Penetration A >= 0 beyond the compression gap edge, m.
    """
    a_c = _amplitude(amplitude)
    omega_0, omega_c, omega_t = _omegas(joint)
    y0_c, y0_t = _edge_offsets(joint)
    v_c2, v_t2 = _edge_speeds_squared(joint, a_c)
    v_c = np.sqrt(v_c2)
    touched_t = v_t2 > 0.0
    v_t = np.sqrt(np.maximum(v_t2, 0.0))
    # A_t = B - y0 with B = sqrt(y0^2 + (v/w)^2), written as (v/w)^2 / (B + y0).
    q_t = (v_t / omega_t) ** 2
    b_t = np.sqrt(y0_t**2 + q_t)
    with np.errstate(invalid="ignore"):
        a_t = np.where(q_t > 0.0, q_t / (b_t + y0_t), 0.0)
    x_max = joint.compression_gap + a_c
    if joint.gap_stiffness > 0.0:
        # Turning point inside the gap when the tension edge is not reached: V(x) = H.
        free_turn = np.sqrt(x_max**2 + joint.compression_stiffness * a_c**2 / joint.gap_stiffness)
    else:
        free_turn = np.full_like(a_c, joint.tension_gap)
    x_min = np.where(
        touched_t, -(joint.tension_gap + a_t), -np.minimum(free_turn, joint.tension_gap)
    )
    t_c = _contact_time(v_c, y0_c, omega_c)
    t_t = _contact_time(v_t, y0_t, omega_t)
    cross_c = _crossing_time(joint.compression_gap, v_c, omega_0)
    cross_t = _crossing_time(joint.tension_gap, v_t, omega_0)
    t_free = 2.0 * (cross_c + cross_t)
    # integral of x'^2 dt. Contact on side s (a sinusoid about its equilibrium, entered
    # y0 outside it at speed v_s): w_s B^2 theta_s - y0 v_s, theta_s = w_s t_s / 2.
    contact_action = (
        omega_c * (y0_c**2 + (v_c / omega_c) ** 2) * (0.5 * omega_c * t_c)
        - y0_c * v_c
        + omega_t * (y0_t**2 + q_t) * (0.5 * omega_t * t_t)
        - y0_t * v_t
    )
    # Free-play, one way from 0 to an edge g reached at v_g in time t_g:
    # (g v_g + (v_g^2 + w0^2 g^2) t_g) / 2; a side never reached gives its quarter swing.
    one_way = _free_play_action(joint.compression_gap, v_c, cross_c, omega_0)
    reach_t = _free_play_action(joint.tension_gap, v_t, cross_t, omega_0)
    quarter = 0.25 * math.pi * omega_0 * free_turn**2
    free_play_action = 2.0 * (one_way + np.where(touched_t, reach_t, quarter))
    return FreeOrbit(
        compression_penetration=a_c,
        tension_penetration=a_t,
        compression_speed=v_c,
        tension_speed=v_t,
        compression_touched=np.ones_like(a_c, dtype=bool),
        tension_touched=touched_t,
        x_max=x_max,
        x_min=x_min,
        compression_time=t_c,
        tension_time=t_t,
        free_play_time=t_free,
        period=t_c + t_t + t_free,
        contact_action=contact_action,
        free_play_action=free_play_action,
    )


def period(joint: Joint, amplitude: ArrayLike) -> FloatArray:
    """Return the exact period T of free vibration at penetration A, in s (MODEL.md eq 5).

    General case: k0 >= 0, k_c != k_t and an off-centre gap. With k0 = 0 and a
    symmetric joint it reduces to eq 4, T = 2 pi / w1 + 2 c / (A w1). T is
    infinite when k0 = 0, c > 0 and A = 0 (the mass never moves).

    Parameters
    ----------
    joint : Joint
    amplitude : float or array_like
        Penetration A >= 0 beyond the compression gap edge, m.

    Returns
    -------
    ndarray
        T in s, shaped like ``amplitude``.
    """
    return _period(joint, _amplitude(amplitude))


def natural_frequency(joint: Joint, amplitude: ArrayLike) -> FloatArray:
    """Return the amplitude-dependent natural frequency w_n = 2 pi / T, rad/s (MODEL.md eq 6)."""
    return (2.0 * math.pi) / period(joint, amplitude)


def dynamic_stiffness(joint: Joint, amplitude: ArrayLike) -> FloatArray:
    """Return the dynamic stiffness k_d = m w_n^2 at penetration A, N/m (MODEL.md eq 8).

    Examples
    --------
    >>> j = Joint(mass=2.0, clearance=0.106e-3, compression_stiffness=8e7)
    >>> float(dynamic_stiffness(j, 20e-6) / 8e7)  # eq 9: (pi A / (pi A + c))^2
    0.1385...
    """
    omega_n = (2.0 * math.pi) / _period(joint, _amplitude(amplitude))
    return joint.mass * omega_n * omega_n


def stiffness_coefficient(joint: Joint, amplitude: ArrayLike) -> FloatArray:
    """Return c_d = k_d / k_inf, the dynamic stiffness over its large-amplitude limit (eq 9).

    For a symmetric joint with k0 = 0 this is k_d / k_c = (pi A / (pi A + c))^2;
    it tends to 1 at large A and is 0 at A = 0 when k0 = 0.
    """
    return dynamic_stiffness(joint, amplitude) / joint.large_amplitude_stiffness


def _gap_fraction_term(gap: float, amplitude: FloatArray) -> FloatArray:
    """N(g / X) of MODEL.md sec. 1: the fraction of a spring engaged over a first harmonic."""
    with np.errstate(divide="ignore", invalid="ignore"):
        u = np.where(amplitude > 0.0, gap / amplitude, 0.0 if gap == 0.0 else np.inf)
    u_in = np.minimum(u, 1.0)
    value = 1.0 - (2.0 / math.pi) * (np.arcsin(u_in) + u_in * np.sqrt(1.0 - u_in * u_in))
    return np.where(u < 1.0, value, 0.0)


def describing_stiffness(joint: Joint, displacement_amplitude: ArrayLike) -> FloatArray:
    """Return the first-harmonic (describing-function) equivalent stiffness, N/m (MODEL.md sec. 1).

    k_eq(X) = k0 + (k_c / 2) N(g_c / X) + (k_t / 2) N(g_t / X) for the motion
    x = X sin(theta) about x = 0 (the gap's centre when ``gap_offset`` is 0).
    When k_c != k_t the true motion is not centred, so this is an approximation.

    Parameters
    ----------
    joint : Joint
    displacement_amplitude : float or array_like
        X >= 0, the displacement amplitude about x = 0, m.
    """
    x_amp = _amplitude(displacement_amplitude, "displacement_amplitude")
    return (
        joint.gap_stiffness
        + 0.5 * joint.compression_stiffness * _gap_fraction_term(joint.compression_gap, x_amp)
        + 0.5 * joint.tension_stiffness * _gap_fraction_term(joint.tension_gap, x_amp)
    )


def viscous_coefficient(joint: Joint, damping_ratio: float) -> float:
    """Return the viscous coefficient c_v = 2 zeta sqrt(m k_c), N s/m (MODEL.md eq 7)."""
    zeta = _checks.non_negative("damping_ratio", damping_ratio)
    return 2.0 * zeta * math.sqrt(joint.mass * joint.compression_stiffness)


@dataclass(frozen=True)
class ResponseBranch:
    """One solution of the equivalent linear forced response (MODEL.md eq 7).

    Attributes
    ----------
    penetration : float
        A, the penetration beyond the compression gap edge, m (0 for an orbit
        that stays in the gap).
    displacement_amplitude : float
        X = (x_max - x_min) / 2, m.
    stiffness : float
        The equivalent stiffness at that amplitude (k_d or k_eq), N/m.
    natural_frequency : float
        sqrt(stiffness / m), rad/s.
    stable : bool
        False on the middle branch of a fold (the residual decreases through the root).
    in_contact : bool
        False for the linear orbit that stays inside the gap.
    """

    penetration: float
    displacement_amplitude: float
    stiffness: float
    natural_frequency: float
    stable: bool
    in_contact: bool

    def __repr__(self) -> str:
        return (
            f"ResponseBranch(X = {self.displacement_amplitude * 1e6:.4g} um, "
            f"A = {self.penetration * 1e6:.4g} um, k = {self.stiffness:.4g} N/m, "
            f"w_n = {self.natural_frequency / (2 * math.pi):.4g} Hz, "
            f"{'stable' if self.stable else 'unstable'}"
            f"{'' if self.in_contact else ', inside the gap'})"
        )

    def to_xarray(self) -> xr.Dataset:
        """Return the branch as an ``xarray.Dataset`` of 0-d variables, units in attrs.

        Returns
        -------
        xarray.Dataset
            ``penetration`` (m), ``displacement_amplitude`` (m), ``stiffness`` (N/m),
            ``natural_frequency`` (rad/s), ``stable`` and ``in_contact`` (1 or 0).
        """
        import xarray as xr

        return xr.Dataset(
            {
                "penetration": ((), self.penetration, {"units": "m"}),
                "displacement_amplitude": ((), self.displacement_amplitude, {"units": "m"}),
                "stiffness": ((), self.stiffness, {"units": "N/m"}),
                "natural_frequency": ((), self.natural_frequency, {"units": "rad/s"}),
                "stable": ((), int(self.stable), {"units": "1 stable, 0 not"}),
                "in_contact": ((), int(self.in_contact), {"units": "1 in contact, 0 not"}),
            },
            attrs={"title": "clearjoint equivalent linear response branch (MODEL.md eq 7)"},
        )

    def to_pandas(self) -> pd.DataFrame:
        """Return the branch as a one-row ``pandas.DataFrame`` (one solution: no longer table).

        Columns ``penetration_m``, ``displacement_amplitude_m``, ``stiffness_n_per_m``,
        ``natural_frequency_rad_per_s``, ``stable``, ``in_contact``; the branches of
        :func:`equivalent_linear_response` together are ``pd.concat`` of theirs.
        """
        import pandas as pd

        return pd.DataFrame(
            {
                "penetration_m": [self.penetration],
                "displacement_amplitude_m": [self.displacement_amplitude],
                "stiffness_n_per_m": [self.stiffness],
                "natural_frequency_rad_per_s": [self.natural_frequency],
                "stable": [self.stable],
                "in_contact": [self.in_contact],
            }
        )

    def plot(self, ax: Axes | None = None) -> Axes:
        """Mark the branch at (w_n in Hz, X in um): filled if stable, open if not; return the Axes.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Where to draw (e.g. over a frequency response); a new figure's Axes when None.

        Returns
        -------
        matplotlib.axes.Axes
            Its last line is the one marker.
        """
        from clearjoint.plotting import axes_or_new

        axes: Axes = axes_or_new(ax)
        axes.plot(
            [self.natural_frequency / (2 * math.pi)],
            [self.displacement_amplitude * 1e6],
            "o",
            color="black",
            mfc="black" if self.stable else "none",
            label="stable" if self.stable else "unstable",
        )
        axes.set_xlabel("natural frequency of the equivalent system (Hz)")
        axes.set_ylabel("displacement amplitude X (µm)")
        return axes


def equivalent_linear_response(
    joint: Joint,
    force_amplitude: float,
    omega: float,
    damping_ratio: float = 0.0,
    method: Literal["period", "describing"] = "period",
    *,
    grid_points: int = 4000,
) -> tuple[ResponseBranch, ...]:
    """Return every branch of the forced amplitude of the equivalent linear system (MODEL.md eq 7).

    Solves, for the amplitude parameter s (penetration A for ``method="period"``,
    displacement amplitude X for ``method="describing"``),

        X(s) sqrt((k(s) - m w^2)^2 + (c_v w)^2) = F0

    with k = k_d(A) (``"period"``: our reading of the paper's static stiffness
    k in eq 7) or k = k_eq(X) (``"describing"``), and c_v = 2 zeta sqrt(m k_c)
    held fixed. A logarithmic grid of s is scanned and each sign change refined
    with Brent's method; two roots closer than one grid cell can be missed.
    Roots where the residual falls through zero (the middle of a fold) are
    flagged unstable. The linear orbit that never leaves the gap,
    X = F0 / sqrt((k0 - m w^2)^2 + (c_v w)^2), is included (``in_contact=False``)
    when it fits inside the gap.

    Parameters
    ----------
    joint : Joint
    force_amplitude : float
        F0 > 0, N.
    omega : float
        Excitation circular frequency w > 0, rad/s.
    damping_ratio : float
        zeta >= 0 of the linear part, c_v = 2 zeta sqrt(m k_c).
    method : {"period", "describing"}
    grid_points : int
        Size of the scanning grid.

    Returns
    -------
    tuple of ResponseBranch
        Sorted by displacement amplitude; empty if no orbit exists (undamped
        resonance of the in-gap system with no contacting orbit).
    """
    f0 = _checks.positive("force_amplitude", force_amplitude, unit="N")
    w = _checks.positive("omega", omega, unit="rad/s")
    c_v = viscous_coefficient(joint, damping_ratio)
    if method not in ("period", "describing"):
        raise ParameterError(f"method must be 'period' or 'describing', got {method!r}")
    if grid_points < 10:
        raise ParameterError(f"grid_points must be >= 10, got {grid_points!r}")
    m = joint.mass
    inertia = m * w * w
    damping = c_v * w

    def amplitude_and_stiffness(s: FloatArray) -> tuple[FloatArray, FloatArray]:
        if method == "period":
            orbit = free_orbit(joint, s)
            k = m * (2.0 * math.pi / orbit.period) ** 2
            return orbit.displacement_amplitude, k
        return s, describing_stiffness(joint, s)

    def residual(s: FloatArray) -> FloatArray:
        x_amp, k = amplitude_and_stiffness(s)
        return x_amp * np.hypot(k - inertia, damping) - f0

    branches: list[ResponseBranch] = []
    in_gap = f0 / math.hypot(joint.gap_stiffness - inertia, damping)
    fits = in_gap <= (
        min(joint.compression_gap, joint.tension_gap)
        if joint.gap_stiffness > 0.0
        else 0.5 * joint.clearance
    )
    if fits and np.isfinite(in_gap):
        branches.append(
            ResponseBranch(
                penetration=0.0,
                displacement_amplitude=in_gap,
                stiffness=joint.gap_stiffness,
                natural_frequency=math.sqrt(joint.gap_stiffness / m),
                stable=True,
                in_contact=False,
            )
        )

    s_low = 0.0 if method == "period" else min(joint.compression_gap, joint.tension_gap)
    # A length scale, then an upper end where the residual is surely positive.
    k_far = joint.large_amplitude_stiffness
    scale = max(joint.clearance, f0 / max(abs(k_far - inertia), damping, 1e-12 * k_far))
    s_high = s_low + 10.0 * scale
    for _ in range(30):
        if residual(np.array([s_high]))[0] > 0.0:
            break
        s_high = s_low + 10.0 * (s_high - s_low)
    span = s_high - s_low
    offsets = np.concatenate(([0.0], span * np.logspace(-12, 0, grid_points)))
    grid = s_low + offsets
    values = residual(grid)
    signs = np.sign(values)
    from scipy.optimize import brentq  # here, not at the top: it costs most of the start-up

    for i in np.nonzero(signs[:-1] * signs[1:] < 0.0)[0]:
        a, b = float(grid[i]), float(grid[i + 1])
        root = brentq(lambda s: float(residual(np.array([s]))[0]), a, b, xtol=1e-300, rtol=1e-15)
        x_amp, k = amplitude_and_stiffness(np.array([root]))
        penetration = root if method == "period" else max(root - joint.compression_gap, 0.0)
        branches.append(
            ResponseBranch(
                penetration=float(penetration),
                displacement_amplitude=float(x_amp[0]),
                stiffness=float(k[0]),
                natural_frequency=math.sqrt(float(k[0]) / m),
                stable=bool(values[i + 1] > values[i]),
                in_contact=True,
            )
        )
    return tuple(sorted(branches, key=lambda b: b.displacement_amplitude))


# ---- the c_d curve as a result a user can tabulate and draw --------------------------------


@dataclass(frozen=True, eq=False)
class StiffnessCurve:
    """A joint's dynamic stiffness against amplitude: T, w_n, k_d and c_d (MODEL.md eq 5-9).

    What ``clearjoint stiffness`` prints, as one object; every array is shaped
    like ``amplitude``.

    Attributes
    ----------
    joint : Joint
    amplitude : ndarray
        Penetration A beyond the compression gap edge, m.
    period : ndarray
        Exact period of free vibration T, s (eq 5).
    natural_frequency : ndarray
        w_n = 2 pi / T, rad/s (eq 6).
    dynamic_stiffness : ndarray
        k_d = m w_n^2, N/m (eq 8).
    stiffness_coefficient : ndarray
        c_d = k_d / k_inf (eq 9).
    """

    joint: Joint
    amplitude: FloatArray
    period: FloatArray
    natural_frequency: FloatArray
    dynamic_stiffness: FloatArray
    stiffness_coefficient: FloatArray

    def __repr__(self) -> str:
        a = np.atleast_1d(self.amplitude) * 1e6
        c_d = np.atleast_1d(self.stiffness_coefficient)
        j = self.joint
        amplitudes = (
            f"A = {a.min():.4g} um" if a.size == 1 else f"A = {a.min():.4g}-{a.max():.4g} um"
        )
        return (
            f"StiffnessCurve({a.size} amplitude{'s' if a.size != 1 else ''}, {amplitudes}: "
            f"c_d = {c_d.min():.4g} to {c_d.max():.4g}; joint m = {j.mass:g} kg, "
            f"c = {j.clearance * 1e3:g} mm, k_inf = {j.large_amplitude_stiffness:.4g} N/m)"
        )

    def _columns(self) -> dict[str, tuple[FloatArray, str]]:
        return {
            "period": (self.period, "s"),
            "natural_frequency": (self.natural_frequency, "rad/s"),
            "dynamic_stiffness": (self.dynamic_stiffness, "N/m"),
            "stiffness_coefficient": (self.stiffness_coefficient, "1"),
        }

    def to_xarray(self) -> xr.Dataset:
        """Return the curve as an ``xarray.Dataset`` on ``amplitude``, units in attrs.

        Returns
        -------
        xarray.Dataset
            Coordinate ``amplitude`` (N,) in m; variables ``period`` (s),
            ``natural_frequency`` (rad/s), ``dynamic_stiffness`` (N/m) and
            ``stiffness_coefficient`` (1), each (N,) with ``attrs["units"]``; the
            joint's parameters as attrs (SI, the unit in each name).
        """
        j = self.joint
        return dataset_on_amplitude(
            self.amplitude,
            self._columns(),
            {
                "title": "clearjoint dynamic stiffness against amplitude",
                "mass_kg": j.mass,
                "clearance_m": j.clearance,
                "compression_stiffness_n_per_m": j.compression_stiffness,
                "tension_stiffness_n_per_m": j.tension_stiffness,
                "gap_stiffness_n_per_m": j.gap_stiffness,
                "gap_offset_m": j.gap_offset,
            },
        )

    def to_pandas(self) -> pd.DataFrame:
        """Return the curve as a ``pandas.DataFrame``, one row per amplitude.

        Returns
        -------
        pandas.DataFrame
            Index ``amplitude_m`` (N,); columns ``period_s``,
            ``natural_frequency_rad_per_s``, ``dynamic_stiffness_n_per_m``,
            ``stiffness_coefficient``.
        """
        names = {
            "period": "period_s",
            "natural_frequency": "natural_frequency_rad_per_s",
            "dynamic_stiffness": "dynamic_stiffness_n_per_m",
            "stiffness_coefficient": "stiffness_coefficient",
        }
        return frame_on_amplitude(
            self.amplitude, {names[key]: v for key, (v, _) in self._columns().items()}
        )

    def plot(self, ax: Axes | None = None) -> Axes:
        """Draw c_d against A (um), as the paper's Fig. 12 does; return the Axes.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Where to draw; a new figure's Axes when None.

        Returns
        -------
        matplotlib.axes.Axes
            Its last line is c_d against A in um, labelled with the clearance.
        """
        from clearjoint.plotting import axes_or_new, one_dimensional

        axes: Axes = axes_or_new(ax)
        a = one_dimensional("amplitude", self.amplitude)
        axes.axhline(1.0, color="0.6", lw=0.8)
        axes.plot(
            a * 1e6,
            np.broadcast_to(self.stiffness_coefficient, a.shape),
            color="black",
            lw=1.6,
            marker="o" if a.size < 20 else None,
            label=f"c = {self.joint.clearance * 1e3:.4g} mm",
        )
        axes.set_xlabel("amplitude beyond the gap edge A (µm)")
        axes.set_ylabel("stiffness coefficient $c_d = k_d / k_\\infty$")
        axes.set_ylim(0.0, 1.05)
        axes.grid(True, color="0.85", lw=0.6)
        axes.legend(frameon=False)
        return axes


def stiffness_curve(joint: Joint, amplitude: ArrayLike) -> StiffnessCurve:
    """Return the period, w_n, k_d and c_d of ``joint`` at penetrations A, as one result (eq 5-9).

    Parameters
    ----------
    joint : Joint
    amplitude : float or array_like
        Penetration A >= 0 beyond the compression gap edge, m.

    Returns
    -------
    StiffnessCurve
        Arrays shaped like ``amplitude``; ``.plot()`` draws c_d against A.

    Examples
    --------
    >>> j = Joint(mass=2.0, clearance=0.106e-3, compression_stiffness=8e7)
    >>> curve = stiffness_curve(j, [1e-6, 20e-6])
    >>> float(curve.stiffness_coefficient[1])  # eq 9: (pi A / (pi A + c))^2
    0.1385...
    """
    a = _amplitude(amplitude)
    t = _period(joint, a)
    omega_n = (2.0 * math.pi) / t
    k_d = joint.mass * omega_n * omega_n
    return StiffnessCurve(
        joint=joint,
        amplitude=a,
        period=t,
        natural_frequency=omega_n,
        dynamic_stiffness=k_d,
        stiffness_coefficient=k_d / joint.large_amplitude_stiffness,
    )
