"""What a study's results say: JSON-ready values and the lines of text a summary prints.

No computing beyond the library's own functions and unit scaling for display (um, mm,
mJ); the command line prints these lines as they are.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from clearjoint.joint import Joint, Losses

__all__ = [
    "curve_lines",
    "curve_warnings",
    "dissipation_lines",
    "json_value",
    "simulation_lines",
    "stiffness_lines",
    "stiffness_table",
]


def json_value(values: Any, several: bool) -> Any:
    """Return a JSON number for one amplitude, a list for several; inf becomes null."""
    cleaned = [float(v) if np.isfinite(v) else None for v in np.atleast_1d(values)]
    return cleaned if several else cleaned[0]


def stiffness_table(joint: Joint, amplitudes: Any) -> dict[str, Any]:
    """Return T, f_n, k_d and c_d of the joint at each amplitude (MODEL.md eq 5-9).

    Keys: amplitude_m, period_s, natural_frequency_hz, dynamic_stiffness_n_per_m,
    stiffness_coefficient; f_n = 1/T, infinite T (no contact) giving f_n = 0.
    """
    from clearjoint import stiffness

    period = stiffness.period(joint, amplitudes)
    with np.errstate(divide="ignore"):
        frequency_hz = 1.0 / period
    return {
        "amplitude_m": amplitudes,
        "period_s": period,
        "natural_frequency_hz": frequency_hz,
        "dynamic_stiffness_n_per_m": stiffness.dynamic_stiffness(joint, amplitudes),
        "stiffness_coefficient": stiffness.stiffness_coefficient(joint, amplitudes),
    }


def stiffness_lines(joint: Joint, table: dict[str, Any]) -> list[str]:
    """Return the joint's line and a table of :func:`stiffness_table`, one row per amplitude."""
    header = f"{'A (um)':>12} {'T (ms)':>12} {'f_n (Hz)':>12} {'k_d (N/m)':>12} {'c_d':>8}"
    lines = [
        f"joint: m = {joint.mass:g} kg, c = {joint.clearance * 1e3:g} mm, "
        f"k_c = {joint.compression_stiffness:.4g} N/m, k_t = {joint.tension_stiffness:.4g} N/m, "
        f"k0 = {joint.gap_stiffness:.4g} N/m, k_inf = {joint.large_amplitude_stiffness:.4g} N/m",
        header,
        "-" * len(header),
    ]
    for a, t, f, k, c in zip(*table.values(), strict=True):
        lines.append(f"{a * 1e6:12.4g} {t * 1e3:12.5g} {f:12.5g} {k:12.5g} {c:8.4f}")
    return lines


def dissipation_lines(
    joint: Joint, losses: Losses, amplitudes: Any, values: Mapping[str, Any]
) -> list[str]:
    """Return the joint, its losses and a table of energies per cycle (MODEL.md eq 10-18)."""
    friction, pin = losses.friction, losses.pin
    columns = [
        ("A (um)", amplitudes * 1e6),
        ("E_P (mJ)", values["sliding_friction_j"] * 1e3),
        ("E_P paper", values["sliding_friction_paper_j"] * 1e3),
        ("E_C (mJ)", values["contact_friction_j"] * 1e3),
        ("E_I (mJ)", values["impact_j"] * 1e3),
        ("E_v (mJ)", values["viscous_j"] * 1e3),
        ("total (mJ)", values["total_j"] * 1e3),
        ("eta", values["loss_factor"]),
        ("b (um)", values["hertz_half_width_m"] * 1e6),
    ]
    lines = [
        f"joint: m = {joint.mass:g} kg, c = {joint.clearance * 1e3:g} mm, "
        f"k_c = {joint.compression_stiffness:.4g} N/m, k_t = {joint.tension_stiffness:.4g} N/m",
        f"losses: mu_s P = {friction.force if friction else 0.0:g} N "
        f"({friction.region if friction else 'none'}), e = {losses.restitution:g}, "
        f"zeta = {losses.damping_ratio:g}, mu_c = {losses.contact_friction_coefficient:g}"
        + (f", pin R = {pin.radius * 1e3:g} mm, L = {pin.length * 1e3:g} mm" if pin else ""),
        " ".join(f"{name:>11}" for name, _ in columns),
    ]
    for row in zip(*(np.atleast_1d(col) for _, col in columns), strict=True):
        lines.append(" ".join(f"{value:11.4g}" for value in row))
    return lines


def simulation_lines(source: str, mode: str, result: dict[str, Any]) -> list[str]:
    """Return the summary of a simulation (``joint_study.summary``'s values) as lines."""
    lines = [
        f"study: {source} ({mode})",
        f"excitation: {result['force_amplitude_n']:g} N at {result['frequency_hz']:g} Hz",
        f"amplitude X = {result['amplitude_m'] * 1e6:.4g} um "
        f"(x_max {result['x_max_m'] * 1e6:.4g} um, x_min {result['x_min_m'] * 1e6:.4g} um)",
    ]
    if "period_multiple" in result:
        lines.append(
            f"period-{result['period_multiple']} orbit, reached after "
            f"{result['periods_to_converge']} forcing periods"
        )
    lines.append(
        f"events {result['events']}, impacts {result['impacts']}, "
        f"stuck {result['stick_time_s'] * 1e3:.4g} ms"
    )
    energy = result["energy_j"]
    lines.append(
        "energy per orbit (J): " + ", ".join(f"{key} {val:.5g}" for key, val in energy.items())
    )
    lines.append(f"balance error {result['balance_error']:.2e}")
    return lines


def curve_lines(curve: Any, source: str) -> list[str]:
    """Return a frequency-response curve's summary: its repr, free play and events."""
    lines = [f"study: {source}", repr(curve)]
    free = getattr(curve, "free_play", None)
    if free is not None and free.any():
        by_force = curve.parameter == "force"
        span = curve.force_amplitude[free] if by_force else curve.omega[free] / (2 * math.pi)
        unit = f"N at {curve.omega[0] / (2 * math.pi):.6g} Hz" if by_force else "Hz"
        lines.append(
            f"free play from {span.min():.6g} to {span.max():.6g} {unit}: the orbit stays inside "
            "the gap (gap_stiffness 0), one of a continuum; its amplitude is set by the dynamics, "
            "its position is not (the curve shows the orbit centred in the gap)"
        )
    for e in curve.events:
        lines.append(
            f"{e.kind}: {e.omega / (2 * math.pi):.6g} Hz, {e.force_amplitude:.6g} N, "
            f"X = {e.amplitude * 1e6:.5g} um"
        )
    return lines


def curve_warnings(curve: Any) -> list[str]:
    """Return what a user must know of a curve: stopped early, or orbits not to be trusted."""
    out = []
    if curve.stop_reason != "reached":
        out.append(
            f"the continuation stopped early ({curve.stop_reason}) at "
            f"{curve.omega[-1] / (2 * math.pi):.6g} Hz, {curve.force_amplitude[-1]:.6g} N; "
            "the curve covers only part of the range"
        )
    found = curve.settings.get("stability_check")
    if found is not None and (not np.all(found.confirmed) or found.unchecked.size):
        refuted = int(np.sum(~found.confirmed)) + int(found.unchecked.size)
        out.append(
            f"harmonic balance called {refuted} of its points stable that the exact motion "
            "does not confirm (an unstable exact orbit nearby, or motion that leaves the "
            "orbit); they are marked unstable: see the curve's events, or run clearjoint "
            "structure STUDY stepped-sine for what the motion does there"
        )
    untrusted = [
        e for e in curve.events if e.kind == "untrusted" and "not stable here" not in e.note
    ]
    if untrusted:  # harmonic balance of a structure: orbits the exact motion does not follow
        where = ", ".join(f"{e.omega / (2 * math.pi):.4g}" for e in untrusted)
        out.append(
            f"at {where} Hz the harmonic-balance orbit misses one "
            "period of the exact motion, so its stability is not to be trusted; raise "
            "--harmonics or lower the force (docs/harmonic.md)"
        )
    return out
