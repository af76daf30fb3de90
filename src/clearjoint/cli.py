"""The ``clearjoint`` command line: parses, calls the library, prints. No physics here.

Quantities take units (``0.106mm``, ``5um``, ``8e7N/m``; SI when none) and
frequencies are in Hz. Bad input ends with exit code 2 and one line on stderr
that says what is wrong.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any, NoReturn

import numpy as np

from clearjoint import __version__
from clearjoint.errors import ClearjointError, ParameterError

EXIT_BAD_INPUT = 2


class _Parser(argparse.ArgumentParser):
    """An ArgumentParser whose errors are one line and exit code 2."""

    def error(self, message: str) -> NoReturn:
        self.exit(EXIT_BAD_INPUT, f"{self.prog}: error: {message} (see --help)\n")


def _stiffness_parser(sub: Any) -> None:
    p = sub.add_parser(
        "stiffness",
        help="dynamic stiffness of a clearance joint at given amplitudes (MODEL.md sec. 1)",
        description=(
            "Exact period, natural frequency, dynamic stiffness k_d = m w_n^2 and stiffness "
            "coefficient c_d = k_d / k_inf of a joint with clearance, at one or several "
            "amplitudes A beyond the compression gap edge. Units may be given "
            "(0.106mm, 5um, 8e7N/m); a bare number is SI."
        ),
    )
    _add_joint_options(p, required=True)
    p.add_argument("--json", action="store_true", help="print one JSON object instead of a table")


def _add_joint_options(p: argparse.ArgumentParser, *, required: bool) -> None:
    p.add_argument("--mass", required=required, help="moving mass, e.g. 2kg")
    p.add_argument(
        "--stiffness", required=required, help="compression contact stiffness, e.g. 8e7N/m"
    )
    p.add_argument("--tension-stiffness", help="tension contact stiffness (default: --stiffness)")
    p.add_argument("--gap-stiffness", default="0", help="stiffness inside the gap k0 (default 0)")
    p.add_argument("--clearance", required=required, help="total axial clearance, e.g. 0.106mm")
    p.add_argument("--gap-offset", default="0", help="offset of the gap centre (default 0)")
    p.add_argument(
        "--amplitude", required=True, help="penetration(s) beyond the gap edge, e.g. 1um,5um,20um"
    )


def _dissipation_parser(sub: Any) -> None:
    p = sub.add_parser(
        "dissipation",
        help="energy dissipated per cycle by each mechanism (MODEL.md sec. 2)",
        description=(
            "Sliding friction (exact and the paper's viscous form), Hertz contact friction on "
            "the pin, impact and their total per cycle, with the loss factor, on the free "
            "cycle at penetration A. The joint, losses and pin come from options or from a "
            "study file (--study); options given beside --study override it."
        ),
    )
    p.add_argument("--study", help="take the joint, losses and pin from this study TOML")
    _add_joint_options(p, required=False)
    p.add_argument("--friction-coefficient", help="sliding-friction coefficient mu_s")
    p.add_argument("--lateral-load", help="lateral load P, e.g. 300N")
    p.add_argument("--friction-region", choices=["everywhere", "free-play"])
    p.add_argument("--restitution", help="coefficient of restitution e (default 1)")
    p.add_argument("--damping-ratio", help="viscous damping ratio of the linear part")
    p.add_argument("--pin-radius", help="pin radius, e.g. 5mm (gives a pin)")
    p.add_argument("--pin-length", help="pin contact length, e.g. 25mm")
    p.add_argument("--hole-radius", help="hole radius (default: pin radius + clearance/2)")
    p.add_argument("--youngs-modulus", help="Young's modulus of pin and hole (default 206GPa)")
    p.add_argument("--poisson-ratio", help="Poisson's ratio of pin and hole (default 0.3)")
    p.add_argument("--contact-friction-coefficient", help="friction coefficient on the pin mu_c")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of a table")


def _reproduce_parser(sub: Any) -> None:
    p = sub.add_parser(
        "reproduce",
        help="run the paper's whole study on the virtual rig and write a report",
        description=(
            "Run the default campaign of the virtual rig (or --campaign), identify every "
            "record, fit eq 19-22, draw Figs. 7-13 and write DIR/report.html, "
            "DIR/results.json, DIR/results.csv, DIR/fits.csv and DIR/records/."
        ),
    )
    p.add_argument("--out", default="clearjoint-reproduction", help="output folder")
    p.add_argument("--campaign", help="campaign file (TOML); default: the shipped one")
    p.add_argument("--jobs", type=int, default=None, help="processes (default: every core)")
    p.add_argument("--force", action="store_true", help="overwrite existing output files")


def _report_parser(sub: Any) -> None:
    p = sub.add_parser(
        "report",
        help="identify a folder of your own records, fit the laws and write a report",
        description=(
            "Identify every record in --records (CSV, netCDF, BRFD JSON), fit eq 19-22 where "
            "the tests allow, and write DIR/report.html, results.json, results.csv, fits.csv."
        ),
    )
    p.add_argument("--records", required=True, help="folder of record files")
    p.add_argument("--out", default="clearjoint-report", help="output folder")
    p.add_argument("--force", action="store_true", help="overwrite existing output files")


def _simulate_parser(sub: Any) -> None:
    p = sub.add_parser(
        "simulate",
        help="exact forced response of a joint described in a study file",
        description=(
            "Run the study in STUDY.toml (joint, excitation, losses; see docs/simulate.md): "
            "the exact steady state (or transient), its stages, impacts and energy ledger. "
            "Prints a summary, or with --json one JSON object; --out writes netCDF."
        ),
    )
    p.add_argument("study", help="study file (TOML)")
    p.add_argument("--out", help="write the result to this netCDF file (.nc)")
    p.add_argument("--json", action="store_true", help="print the summary as one JSON object")
    p.add_argument("--force", action="store_true", help="overwrite --out if it exists")


def _rig_parser(sub: Any) -> None:
    p = sub.add_parser(
        "rig",
        help="run a campaign of the virtual test rig and write its records",
        description=(
            "Simulate every test of CAMPAIGN.toml (the shipped default when none is given: "
            "the paper's two joints and the bare beam over a grid of forces and frequencies) "
            "and write one record per test and DIR/manifest.csv with the truth of each."
        ),
    )
    p.add_argument("campaign", nargs="?", help="campaign file (TOML); default: the shipped one")
    p.add_argument("--out", required=True, help="output folder")
    p.add_argument("--jobs", type=int, default=None, help="processes (default: every core)")
    p.add_argument("--force", action="store_true", help="overwrite existing records")
    p.add_argument("--quiet", action="store_true", help="no progress bar")


def _identify_parser(sub: Any) -> None:
    p = sub.add_parser(
        "identify",
        help="clearance, stiffness, friction and energy per cycle from test records",
        description=(
            "Identify every record (CSV, netCDF, BRFD JSON; recognised by content): one row "
            "per file in --out (.csv or .nc) with each quantity's mean over the steady "
            "cycles and its spread in a _std column; one line for every file not used."
        ),
    )
    p.add_argument("files", nargs="+", help="record files")
    p.add_argument("--out", required=True, help="results file, .csv or .nc")
    p.add_argument("--figures", help="write two figures per test into this folder")
    p.add_argument(
        "--resample", action="store_true", help="interpolate records that are not uniformly sampled"
    )
    p.add_argument(
        "--tolerance",
        type=float,
        default=0.03,
        help="steady-cycle amplitude tolerance (default 0.03)",
    )
    p.add_argument("--force", action="store_true", help="overwrite existing output")
    p.add_argument("--quiet", action="store_true", help="no progress bar")


def _frf_parser(sub: Any) -> None:
    p = sub.add_parser(
        "frf",
        help="whole frequency-response curve of exact periodic orbits, stable and unstable",
        description=(
            "Follow the exact period-1 orbit of the joint in STUDY.toml (joint, force, losses; "
            "its frequency is not used) by continuation from --from to --to, through folds; "
            "report folds, period doublings and grazings. With --parameter force, --from and "
            "--to are forces and --frequency (default: the study's) is held fixed."
        ),
    )
    p.add_argument("study", help="study file (TOML), as for clearjoint simulate")
    p.add_argument("--from", dest="start", required=True, help="start: 20Hz (or 100N)")
    p.add_argument("--to", dest="stop", required=True, help="end: 900Hz (or 2kN)")
    p.add_argument("--out", required=True, help="write the curve to this netCDF file (.nc)")
    p.add_argument("--plot", help="draw the curve to this image file (.png)")
    p.add_argument("--json", action="store_true", help="print the curve as one JSON object")
    p.add_argument(
        "--parameter",
        choices=["frequency", "force"],
        default="frequency",
        help="what varies along the curve (default frequency)",
    )
    p.add_argument("--frequency", help="fixed frequency with --parameter force, e.g. 400Hz")
    p.add_argument("--max-points", type=int, default=2000, help="points at most (default 2000)")
    p.add_argument("--force", action="store_true", help="overwrite --out / --plot if they exist")
    p.add_argument(
        "--method",
        choices=["shooting", "harmonic"],
        default="shooting",
        help="exact shooting (default) or harmonic balance (clearjoint.harmonic)",
    )
    p.add_argument("--harmonics", type=int, help="H with --method harmonic (default 7)")


def _modes_parser(sub: Any) -> None:
    p = sub.add_parser(
        "modes",
        help="nonlinear mode: frequency and damping ratio against amplitude (EPMC)",
        description=(
            "Nonlinear mode of the joint in STUDY.toml (joint and losses; its excitation is "
            "not used) by harmonic balance and the extended periodic motion concept, at "
            "--points amplitudes spaced logarithmically over --amplitude."
        ),
    )
    p.add_argument("study", help="study file (TOML), as for clearjoint simulate")
    p.add_argument("--mode", type=int, default=1, help="mode number (default 1)")
    p.add_argument(
        "--amplitude", required=True, help="modal amplitude range, e.g. 1um..1mm (or one value)"
    )
    p.add_argument("--points", type=int, default=40, help="amplitudes in the range (default 40)")
    p.add_argument("--harmonics", type=int, default=7, help="H (default 7)")
    p.add_argument("--out", required=True, help="write the mode to this netCDF file (.nc)")
    p.add_argument("--plot", help="draw frequency and damping against amplitude (.png)")
    p.add_argument("--json", action="store_true", help="print the mode as one JSON object")
    p.add_argument("--force", action="store_true", help="overwrite --out / --plot if they exist")


def _structure_parser(sub: Any) -> None:
    p = sub.add_parser(
        "structure",
        help="modes, forced response or free decay of a structure with many joints (MODEL 5.2)",
        description=(
            "Read a structure study (TOML with units, see clearjoint.structure.study) and "
            "compute its linear modes with every joint closed and open (modes), its exact "
            "forced response (respond) or its exact free decay and backbone (decay)."
        ),
    )
    p.add_argument("study", help="structure study TOML file")
    p.add_argument("task", choices=("modes", "respond", "decay"), help="what to compute")
    p.add_argument("--out", required=True, help="netCDF results file (.nc)")
    p.add_argument("--plot", help="also draw a figure into this PNG")
    p.add_argument("--json", action="store_true", help="print a JSON summary")
    p.add_argument("--force", action="store_true", help="overwrite existing output")


def build_parser() -> argparse.ArgumentParser:
    """Return the argument parser of the ``clearjoint`` command."""
    parser = _Parser(prog="clearjoint", description="Dynamics of joints with clearance.")
    parser.add_argument("--version", action="version", version=f"clearjoint {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    _stiffness_parser(sub)
    _simulate_parser(sub)
    _dissipation_parser(sub)
    _rig_parser(sub)
    _identify_parser(sub)
    _reproduce_parser(sub)
    _report_parser(sub)
    _frf_parser(sub)
    _modes_parser(sub)
    _structure_parser(sub)
    return parser


def _joint_from(args: argparse.Namespace) -> Any:
    from clearjoint.joint import Joint
    from clearjoint.units import parse_quantity

    for option in ("mass", "stiffness", "clearance"):
        if getattr(args, option) is None:
            raise ParameterError(f"--{option} is required (or give a --study file)")
    stiffness = parse_quantity(args.stiffness, "stiffness", name="--stiffness")
    return Joint(
        mass=parse_quantity(args.mass, "mass", name="--mass"),
        clearance=parse_quantity(args.clearance, "length", name="--clearance"),
        compression_stiffness=stiffness,
        tension_stiffness=(
            stiffness
            if args.tension_stiffness is None
            else parse_quantity(args.tension_stiffness, "stiffness", name="--tension-stiffness")
        ),
        gap_stiffness=parse_quantity(args.gap_stiffness, "stiffness", name="--gap-stiffness"),
        gap_offset=parse_quantity(args.gap_offset, "length", name="--gap-offset"),
    )


def _json_value(values: np.ndarray, several: bool) -> Any:
    """A JSON number for one amplitude, a list for several; inf becomes null."""
    cleaned = [float(v) if np.isfinite(v) else None for v in np.atleast_1d(values)]
    return cleaned if several else cleaned[0]


def _run_stiffness(args: argparse.Namespace) -> int:
    from clearjoint import stiffness
    from clearjoint.units import parse_quantity_list

    joint = _joint_from(args)
    amplitudes = np.array(parse_quantity_list(args.amplitude, "length", name="--amplitude"))
    period = stiffness.period(joint, amplitudes)
    with np.errstate(divide="ignore"):
        frequency_hz = 1.0 / period
    k_d = stiffness.dynamic_stiffness(joint, amplitudes)
    c_d = stiffness.stiffness_coefficient(joint, amplitudes)
    several = amplitudes.size > 1
    if args.json:
        out = {
            "amplitude_m": _json_value(amplitudes, several),
            "period_s": _json_value(period, several),
            "natural_frequency_hz": _json_value(frequency_hz, several),
            "dynamic_stiffness_n_per_m": _json_value(k_d, several),
            "stiffness_coefficient": _json_value(c_d, several),
        }
        print(json.dumps(out))
        return 0
    print(
        f"joint: m = {joint.mass:g} kg, c = {joint.clearance * 1e3:g} mm, "
        f"k_c = {joint.compression_stiffness:.4g} N/m, k_t = {joint.tension_stiffness:.4g} N/m, "
        f"k0 = {joint.gap_stiffness:.4g} N/m, k_inf = {joint.large_amplitude_stiffness:.4g} N/m"
    )
    header = f"{'A (um)':>12} {'T (ms)':>12} {'f_n (Hz)':>12} {'k_d (N/m)':>12} {'c_d':>8}"
    print(header)
    print("-" * len(header))
    for a, t, f, k, c in zip(amplitudes, period, frequency_hz, k_d, c_d, strict=True):
        print(f"{a * 1e6:12.4g} {t * 1e3:12.5g} {f:12.5g} {k:12.5g} {c:8.4f}")
    return 0


def _losses_from(args: argparse.Namespace, base: Any | None) -> dict[str, Any]:
    """Friction, restitution, damping, pin and mu_c from options, over a study's values."""
    from clearjoint.joint import Friction, Pin
    from clearjoint.units import parse_quantity

    def number(option: str, kind: str, default: float) -> float:
        text = getattr(args, option.replace("-", "_"))
        return default if text is None else parse_quantity(text, kind, name=f"--{option}")

    friction = base.friction if base is not None else None
    mu_s = number("friction-coefficient", "dimensionless", friction.coefficient if friction else 0)
    load = number("lateral-load", "force", friction.lateral_load if friction else 0.0)
    region = args.friction_region or (friction.region if friction else "everywhere")
    pin = base.pin if base is not None else None
    if args.pin_radius is not None or args.pin_length is not None:
        if args.pin_radius is None or args.pin_length is None:
            raise ParameterError("give both --pin-radius and --pin-length for a pin")
        radius = number("pin-radius", "length", 0.0)
        clearance = number("clearance", "length", base.joint.clearance if base else 0.0)
        pin = Pin(
            radius=radius,
            hole_radius=number("hole-radius", "length", radius + 0.5 * clearance),
            length=number("pin-length", "length", 0.0),
            youngs_modulus=number("youngs-modulus", "pressure", 2.06e11),
            poisson_ratio=number("poisson-ratio", "dimensionless", 0.3),
        )
    return {
        "friction": Friction(mu_s, load, region) if mu_s > 0 and load > 0 else None,
        "restitution": number("restitution", "dimensionless", base.restitution if base else 1.0),
        "damping_ratio": number(
            "damping-ratio", "dimensionless", base.damping_ratio if base else 0.0
        ),
        "pin": pin,
        "contact_friction_coefficient": number(
            "contact-friction-coefficient",
            "dimensionless",
            base.contact_friction_coefficient if base else 0.0,
        ),
    }


def _run_dissipation(args: argparse.Namespace) -> int:
    from clearjoint import dissipation
    from clearjoint.units import parse_quantity_list

    base = None
    if args.study:
        from clearjoint.simulate.study import load_study

        base = load_study(args.study)
    joint = base.joint if base is not None and args.mass is None else _joint_from(args)
    losses = _losses_from(args, base)
    amplitudes = np.array(parse_quantity_list(args.amplitude, "length", name="--amplitude"))
    values = dissipation.energies(joint, amplitudes, **losses)
    several = amplitudes.size > 1
    if args.json:
        out = {"amplitude_m": _json_value(amplitudes, several)}
        out.update({key: _json_value(val, several) for key, val in values.items()})
        print(json.dumps(out))
        return 0
    print(
        f"joint: m = {joint.mass:g} kg, c = {joint.clearance * 1e3:g} mm, "
        f"k_c = {joint.compression_stiffness:.4g} N/m, k_t = {joint.tension_stiffness:.4g} N/m"
    )
    friction = losses["friction"]
    pin = losses["pin"]
    print(
        f"losses: mu_s P = {friction.force if friction else 0.0:g} N "
        f"({friction.region if friction else 'none'}), e = {losses['restitution']:g}, "
        f"zeta = {losses['damping_ratio']:g}, mu_c = {losses['contact_friction_coefficient']:g}"
        + (f", pin R = {pin.radius * 1e3:g} mm, L = {pin.length * 1e3:g} mm" if pin else "")
    )
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
    print(" ".join(f"{name:>11}" for name, _ in columns))
    for row in zip(*(np.atleast_1d(col) for _, col in columns), strict=True):
        print(" ".join(f"{value:11.4g}" for value in row))
    return 0


def _run_rig(args: argparse.Namespace) -> int:
    import os
    import time

    from clearjoint.rig import load_campaign, run_campaign

    campaign = load_campaign(args.campaign)
    jobs = args.jobs or os.cpu_count() or 1  # for the progress line only
    start = time.perf_counter()
    total = len(campaign.tests)
    if args.quiet:
        manifest = run_campaign(campaign, args.out, jobs=args.jobs, force=args.force)
    else:
        from rich.progress import Progress

        with Progress(transient=True) as bar:
            task = bar.add_task(f"{total} tests on {jobs} processes", total=total)
            manifest = run_campaign(
                campaign,
                args.out,
                jobs=args.jobs,
                force=args.force,
                progress=lambda done, _total: bar.update(task, completed=done),
            )
    print(f"wrote {total} records and {manifest} in {time.perf_counter() - start:.1f} s")
    return 0


def _run_identify(args: argparse.Namespace) -> int:
    from clearjoint._checks import refuse_to_overwrite
    from clearjoint.identify import identify_files

    out = Path(args.out)
    if out.suffix.lower() not in (".csv", ".nc"):
        raise ParameterError(f"--out must end in .csv or .nc, got {out.name!r}")
    if not 0.0 < args.tolerance < 1.0:
        raise ParameterError(f"--tolerance must lie in (0, 1), got {args.tolerance}")
    refuse_to_overwrite([out], force=args.force)
    if args.quiet:
        results, failures = identify_files(
            args.files, resample=args.resample, tolerance=args.tolerance
        )
    else:
        from rich.progress import Progress

        with Progress(transient=True) as bar:
            task = bar.add_task(f"{len(args.files)} records", total=len(args.files))
            results, failures = identify_files(
                args.files,
                resample=args.resample,
                tolerance=args.tolerance,
                progress=lambda done, _total: bar.update(task, completed=done),
            )
    for line in failures:
        print(f"not used: {line}", file=sys.stderr)
    if not results:
        print("clearjoint identify: error: no record could be used", file=sys.stderr)
        return EXIT_BAD_INPUT
    rows = [ident.row() for _, ident in results]
    _write_rows(rows, out)
    if args.figures:
        _identify_figures(results, Path(args.figures), force=args.force)
    print(f"identified {len(results)} of {len(args.files)} records; wrote {out}")
    return 0


def _write_rows(rows: list[dict[str, Any]], out: Path) -> None:
    import csv

    out.parent.mkdir(parents=True, exist_ok=True)
    if out.suffix.lower() == ".csv":
        with out.open("w", newline="", encoding="utf-8") as handle:
            writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
            writer.writeheader()
            writer.writerows(rows)
        return
    import xarray as xr

    columns = {key: [row[key] for row in rows] for key in rows[0]}
    data = xr.Dataset(
        {key: ("file", np.asarray(values)) for key, values in columns.items() if key != "file"},
        coords={"file": ("file", np.asarray(columns["file"], dtype=str))},
        attrs={"title": "clearjoint identification"},
    )
    data.to_netcdf(out, engine="h5netcdf")


def _identify_figures(results: list[Any], folder: Path, *, force: bool) -> None:
    from clearjoint._checks import refuse_to_overwrite
    from clearjoint.figures import displacement_stages_figure, identified_loop_figure

    folder.mkdir(parents=True, exist_ok=True)
    for record, ident in results:
        stem = Path(ident.source).stem
        targets = [folder / f"{stem}_stages.png", folder / f"{stem}_loop.png"]
        refuse_to_overwrite(targets, force=force)
        first = ident.cycles[0]
        span = slice(first.start, ident.cycles[-1].stop)
        runs = ident.stage_runs(record.time)
        fig = displacement_stages_figure(record.time, record.displacement, runs, title=stem)
        fig.savefig(targets[0], dpi=100)
        fig = identified_loop_figure(
            record.displacement[span],
            ident.restoring_force[span],
            ident.stage[span],
            (first.upper_edge, first.lower_edge),
            first.lines,
            title=stem,
        )
        fig.savefig(targets[1], dpi=100)


def _run_simulate(args: argparse.Namespace) -> int:
    from clearjoint.simulate.study import load_study, run_study, summary, write_netcdf

    study = load_study(args.study)
    if args.out:
        from clearjoint._checks import refuse_to_overwrite

        refuse_to_overwrite([Path(args.out)], force=args.force)  # before the run, not after
    motion = run_study(study)
    result = summary(study, motion)
    if args.out:
        write_netcdf(study, motion, args.out, force=args.force)
    if args.json:
        print(json.dumps(result))
        return 0
    energy = result["energy_j"]
    lines = [
        f"study: {study.source} ({study.mode})",
        f"excitation: {study.force_amplitude:g} N at {result['frequency_hz']:g} Hz",
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
    lines.append(
        "energy per orbit (J): " + ", ".join(f"{key} {val:.5g}" for key, val in energy.items())
    )
    lines.append(f"balance error {result['balance_error']:.2e}")
    if args.out:
        lines.append(f"wrote {args.out}")
    print("\n".join(lines))
    return 0


def _run_reproduce(args: argparse.Namespace) -> int:
    import time

    from clearjoint.report import reproduce

    start = time.perf_counter()
    written = reproduce(
        Path(args.out),
        force=args.force,
        jobs=args.jobs,
        campaign_path=Path(args.campaign) if args.campaign else None,
        progress=lambda m: print(f"- {m}", file=sys.stderr, flush=True),
    )
    for path in written:
        print(f"wrote {path}")
    print(f"done in {time.perf_counter() - start:.0f} s")
    return 0


def _run_report(args: argparse.Namespace) -> int:
    from clearjoint.report import report_records

    written = report_records(
        Path(args.records),
        Path(args.out),
        force=args.force,
        progress=lambda m: print(f"- {m}", file=sys.stderr, flush=True),
    )
    for path in written:
        print(f"wrote {path}")
    return 0


def _run_frf(args: argparse.Namespace) -> int:
    import math

    from clearjoint._checks import refuse_to_overwrite
    from clearjoint.periodic import frequency_response
    from clearjoint.simulate.study import load_study
    from clearjoint.units import parse_quantity

    study = load_study(args.study)
    outputs = [Path(args.out)] + ([Path(args.plot)] if args.plot else [])
    refuse_to_overwrite(outputs, force=args.force)  # before the run, not after
    kind = "force" if args.parameter == "force" else "frequency"
    start = parse_quantity(args.start, kind, name="--from")
    stop = parse_quantity(args.stop, kind, name="--to")
    for option, text, value in (("--from", args.start, start), ("--to", args.stop, stop)):
        if not (math.isfinite(value) and value > 0.0):
            raise ParameterError(f"{option} must be finite and > 0, got {text!r}")
    if start == stop:
        raise ParameterError(
            f"--from and --to give a range of zero width ({args.start} to {args.stop}); "
            "give two different values"
        )
    losses: dict[str, Any] = {
        "damping_ratio": study.damping_ratio,
        "friction": study.friction,
        "restitution": study.restitution,
    }
    if args.method == "harmonic":
        import functools

        from clearjoint import harmonic

        h = 7 if args.harmonics is None else args.harmonics
        frequency_response = functools.partial(harmonic.frequency_response, harmonics=h)
    elif args.harmonics is not None:
        raise ParameterError("--harmonics goes with --method harmonic; drop it or add that")
    if args.parameter == "force":
        frequency = (
            parse_quantity(args.frequency, "frequency", name="--frequency")
            if args.frequency
            else study.omega / (2.0 * math.pi)
        )
        curve = frequency_response(
            study.joint,
            start,
            2.0 * math.pi * frequency,
            None,
            parameter="force",
            force_stop=stop,
            max_points=args.max_points,
            **losses,
        )
    else:
        if args.frequency:
            raise ParameterError("--frequency goes with --parameter force; drop it or add that")
        curve = frequency_response(
            study.joint,
            study.force_amplitude,
            2.0 * math.pi * start,
            2.0 * math.pi * stop,
            max_points=args.max_points,
            **losses,
        )
    data = curve.to_xarray()
    data.attrs["study"] = study.source
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    data.to_netcdf(args.out, engine="h5netcdf")
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        figure: Any = curve.plot().figure
        figure.savefig(args.plot, dpi=120, bbox_inches="tight")
    if curve.stop_reason != "reached":
        print(
            f"clearjoint frf: warning: the continuation stopped early ({curve.stop_reason}) at "
            f"{curve.omega[-1] / (2 * math.pi):.6g} Hz, {curve.force_amplitude[-1]:.6g} N; "
            "the curve covers only part of the range",
            file=sys.stderr,
        )
    if args.json:
        print(
            json.dumps(
                {
                    "frequency_hz": (curve.omega / (2 * math.pi)).tolist(),
                    "force_n": curve.force_amplitude.tolist(),
                    "amplitude_m": curve.amplitude.tolist(),
                    "x_max_m": curve.x_max.tolist(),
                    "x_min_m": curve.x_min.tolist(),
                    "stable": curve.stable.tolist(),
                    "events": [
                        {
                            "kind": e.kind,
                            "frequency_hz": e.omega / (2 * math.pi),
                            "force_n": e.force_amplitude,
                            "amplitude_m": e.amplitude,
                        }
                        for e in curve.events
                    ],
                }
            )
        )
        return 0
    lines = [f"study: {study.source}", repr(curve)]
    for e in curve.events:
        lines.append(
            f"{e.kind}: {e.omega / (2 * math.pi):.6g} Hz, {e.force_amplitude:.6g} N, "
            f"X = {e.amplitude * 1e6:.5g} um"
        )
    lines.append(f"wrote {args.out}" + (f" and {args.plot}" if args.plot else ""))
    print("\n".join(lines))
    return 0


def _amplitude_range(text: str, points: int) -> Any:
    """'1um..1mm' -> ``points`` values spaced logarithmically (m); one value -> itself."""
    import numpy as np

    from clearjoint.units import parse_quantity

    if points < 1:
        raise ParameterError(f"--points must be >= 1, got {points}")
    parts = text.split("..")
    if len(parts) > 2:
        raise ParameterError(f"--amplitude: write a range like 1um..1mm, got {text!r}")
    values = [parse_quantity(part, "length", name="--amplitude") for part in parts]
    if any(not value > 0.0 for value in values):
        raise ParameterError(
            f"--amplitude must start above zero (a mode has no amplitude 0), got {text!r}; "
            "write it like 1um..1mm"
        )
    if len(values) == 1:
        return np.array(values)
    if values[0] == values[1]:
        raise ParameterError(f"--amplitude range {text!r} has zero width; give two values")
    return np.geomspace(values[0], values[1], points)


def _run_modes(args: argparse.Namespace) -> int:
    import math

    from clearjoint._checks import refuse_to_overwrite
    from clearjoint.harmonic import nonlinear_modes
    from clearjoint.simulate.study import load_study

    study = load_study(args.study)
    outputs = [Path(args.out)] + ([Path(args.plot)] if args.plot else [])
    refuse_to_overwrite(outputs, force=args.force)
    amplitudes = _amplitude_range(args.amplitude, args.points)
    mode = nonlinear_modes(
        study.joint,
        args.mode,
        amplitudes,
        harmonics=args.harmonics,
        damping_ratio=study.damping_ratio,
        friction=study.friction,
        restitution=study.restitution,
    )
    data = mode.to_xarray()
    data.attrs["study"] = study.source
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    data.to_netcdf(args.out, engine="h5netcdf")
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        figure: Any = mode.plot().figure
        figure.savefig(args.plot, dpi=120, bbox_inches="tight")
    missing = int((~mode.converged).sum())
    if missing:
        print(
            f"clearjoint modes: warning: no mode found at {missing} of {mode.amplitude.size} "
            "amplitudes (NaN there; e.g. a mass floating in its gap)",
            file=sys.stderr,
        )

    def finite(values: Any) -> list[float | None]:
        return [float(v) if math.isfinite(v) else None for v in values]

    if args.json:
        print(
            json.dumps(
                {
                    "amplitude_m": mode.amplitude.tolist(),
                    "frequency_hz": finite(mode.frequency / (2 * math.pi)),
                    "damping_ratio": finite(mode.damping_ratio),
                    "energy_per_cycle_j": finite(mode.energy_per_cycle),
                }
            )
        )
        return 0
    print("\n".join([f"study: {study.source}", repr(mode), f"wrote {args.out}"]))
    return 0


def _run_structure(args: argparse.Namespace) -> int:
    import math

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import xarray as xr

    from clearjoint import _checks
    from clearjoint.structure import decay_backbone, free_decay, time_response
    from clearjoint.structure.study import load_structure_study

    out = Path(args.out)
    outputs = [out] + ([Path(args.plot)] if args.plot else [])
    _checks.refuse_to_overwrite(outputs, force=args.force)
    study = load_structure_study(args.study)
    s = study.structure
    summary: dict[str, Any] = {"structure": repr(s)}
    fig = None
    if args.task == "modes":
        closed, opened = s.modes("closed"), s.modes("open")
        data = xr.concat(
            [closed.to_xarray(), opened.to_xarray()],
            dim=xr.DataArray(["closed", "open"], dims="pattern"),
        )
        summary["closed_hz"] = closed.frequency_hz[:6].tolist()
        summary["open_hz"] = opened.frequency_hz[:6].tolist()
        if args.plot:
            fig, axes = plt.subplots(1, 2, figsize=(9, 6))
            closed.plot(axes[0])
            opened.plot(axes[1])
    elif args.task == "respond":
        if study.omega is None or study.force is None:
            raise ParameterError(f"{study.source}: respond needs an [excitation] section")
        duration = study.periods * 2.0 * math.pi / study.omega
        motion = time_response(
            s, study.force, study.omega, duration, samples_per_period=study.samples_per_period
        )
        data = motion.to_xarray()
        summary |= {
            "events": motion.events,
            "patterns": motion.patterns_visited,
            "energy_j": motion.energy.as_dict(),
            "balance_error": motion.balance_error,
            "max_displacement_m": float(np.abs(motion.u).max()),
        }
        if args.plot:
            fig = motion.plot().figure
    else:
        if study.decay_initial is None or study.decay_duration is None:
            raise ParameterError(f"{study.source}: decay needs a [decay] section")
        motion = free_decay(
            s,
            (study.decay_initial, np.zeros(s.n_dof)),
            study.decay_duration,
            samples_per_period=max(study.samples_per_period, 64),
        )
        backbone = decay_backbone(motion, int(study.decay_dof or 0))
        data = xr.merge([motion.to_xarray(), backbone.to_xarray()], combine_attrs="drop_conflicts")
        summary |= {
            "events": motion.events,
            "balance_error": motion.balance_error,
            "amplitude_m": backbone.amplitude.tolist(),
            "frequency_hz": (backbone.omega / (2.0 * math.pi)).tolist(),
            "damping_ratio": [None if math.isnan(z) else z for z in backbone.damping_ratio],
        }
        if args.plot:
            fig = backbone.plot().figure
    data.to_netcdf(out, engine="h5netcdf")
    if fig is not None:
        fig.savefig(args.plot, dpi=120)
    if args.json:
        print(json.dumps(summary))
    else:
        for key, value in summary.items():
            print(f"{key}: {value}")
        print(f"wrote {out}" + (f" and {args.plot}" if args.plot else ""))
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    runners = {
        "stiffness": _run_stiffness,
        "simulate": _run_simulate,
        "dissipation": _run_dissipation,
        "rig": _run_rig,
        "identify": _run_identify,
        "reproduce": _run_reproduce,
        "report": _run_report,
        "frf": _run_frf,
        "modes": _run_modes,
        "structure": _run_structure,
    }
    try:
        return runners[args.command](args)
    except ClearjointError as exc:
        print(f"clearjoint {args.command}: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
