"""The ``clearjoint`` command line's parser: its subcommands, options and help. Parsing only.

:func:`build_parser` declares every subcommand; :func:`study_values` and
:func:`amplitude_values` read the options that carry quantities into SI (a bare number for a
dimensional quantity is refused). :mod:`clearjoint.cli` runs the parsed command and prints.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from typing import Any, NoReturn

import numpy as np

from clearjoint import __version__

__all__ = [
    "EXIT_BAD_INPUT",
    "OPTION_NAMES",
    "STUDY_OPTIONS",
    "amplitude_values",
    "build_parser",
    "rename_value",
    "study_values",
]

EXIT_BAD_INPUT = 2


class _Help(argparse.HelpFormatter):
    """Help that shows every option's default: ``(default X)`` added where the text has none.

    An option without a default (None) or an on/off flag (False) shows none.
    """

    def _get_help_string(self, action: argparse.Action) -> str | None:
        text = action.help or ""
        default = action.default
        if (
            "default" in text
            or not action.option_strings
            or default is None
            or default is False
            or default == argparse.SUPPRESS
        ):
            return action.help
        return f"{text} (default %(default)s)"


class _Parser(argparse.ArgumentParser):
    """An ArgumentParser whose errors are one line and exit code 2, its help with defaults."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs.setdefault("formatter_class", _Help)
        super().__init__(*args, **kwargs)

    def error(self, message: str) -> NoReturn:
        if message.endswith("expected one argument"):  # also "--gap-offset -0.01mm"
            option = message.removeprefix("argument ").split(":")[0].split("/")[-1]
            message += f"; for a negative value write {option}=-0.01mm"
        self.exit(EXIT_BAD_INPUT, f"{self.prog}: error: {message} (see --help)\n")


def _flags(p: argparse.ArgumentParser, **helps: str) -> None:
    """Add an on/off option ``--NAME`` (``_`` written ``-``) for each keyword, with its help."""
    for name, text in helps.items():
        p.add_argument(f"--{name.replace('_', '-')}", action="store_true", help=text)


def _options(p: argparse.ArgumentParser, **helps: str) -> None:
    """Add a text option ``--NAME`` (``_`` written ``-``) for each keyword, with its help."""
    for name, text in helps.items():
        p.add_argument(f"--{name.replace('_', '-')}", help=text)


def _default(owner: type, name: str, scale: float = 1.0, unit: str = "") -> str:
    """The default of dataclass field ``owner.name`` in ``--help``, e.g. ``(default 206GPa)``."""
    value = next(f.default for f in dataclasses.fields(owner) if f.name == name)
    assert isinstance(value, int | float), f"{owner.__name__}.{name} has no number default"
    return f"(default {value / scale:g}{unit})"


def _stiffness_parser(sub: Any) -> None:
    p = sub.add_parser(
        "stiffness",
        help="dynamic stiffness of a clearance joint at given amplitudes (MODEL.md sec. 1)",
        description=(
            "Exact period, natural frequency, dynamic stiffness k_d = m w_n^2 and stiffness "
            "coefficient c_d = k_d / k_inf of a joint with clearance, at one or several "
            "amplitudes A beyond the compression gap edge. Every dimensional value takes "
            "a unit (0.106mm, 5um, 8e7N/m); a bare number is refused."
        ),
    )
    _add_joint_options(p, required=True)
    _flags(p, json=_JSON_TABLE)
    _add_plot_option(p, force=True)


_JSON_TABLE = "print one JSON object instead of a table"
_JOBS = "processes (default: every core)"
_JOBS_FILES = "processes over the files (default: every core; the results do not depend on it)"
_QUIET = "no progress bar or progress lines on stderr"
_AMPLITUDES = "one (5um), a list (1um,5um,20um) or a range (1um..1mm, see --points)"
_POINTS = "amplitudes in an --amplitude range, spaced logarithmically (default 40)"
_ALLOW_LONG = "run a request estimated above an hour (refused otherwise, with the estimate)"


def _add_joint_options(p: argparse.ArgumentParser, *, required: bool) -> None:
    from clearjoint.joint import Joint

    p.add_argument("--mass", required=required, help="moving mass, e.g. 2kg")
    p.add_argument(
        "--stiffness", required=required, help="compression contact stiffness, e.g. 8e7N/m"
    )
    _options(
        p,
        tension_stiffness="tension contact stiffness (default: the study's, or --stiffness)",
        gap_stiffness=f"stiffness inside the gap k0 {_default(Joint, 'gap_stiffness')}",
    )
    p.add_argument("--clearance", required=required, help="total axial clearance, e.g. 0.106mm")
    _options(p, gap_offset=f"offset of the gap centre {_default(Joint, 'gap_offset')}")
    p.add_argument(
        "--amplitude",
        required=True,
        help="penetration(s) beyond the gap edge: " + _AMPLITUDES,
    )
    p.add_argument("--points", type=int, default=40, help=_POINTS)
    _flags(p, allow_long="run a range whose table is estimated above 4 GiB (refused otherwise)")


def _dissipation_parser(sub: Any) -> None:
    from clearjoint.joint import Losses, Pin

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
    _options(
        p,
        friction_coefficient="sliding-friction coefficient mu_s (default: the study's, else 0)",
        lateral_load="lateral load P, e.g. 300N (default: the study's, else 0)",
    )
    p.add_argument(
        "--friction-region",
        choices=["everywhere", "free-play"],
        help="where sliding friction acts: over the whole path (a bearing's load) or over the "
        "free-play stroke only (the joint's faces, which stop slipping once the pin bears) "
        "(default: the study's, else everywhere)",
    )
    _options(
        p,
        restitution=f"coefficient of restitution e {_default(Losses, 'restitution')}",
        damping_ratio="viscous damping ratio of the linear part (default: the study's, else 0)",
        pin_radius="pin radius, e.g. 5mm (gives a pin)",
        pin_length="pin contact length, e.g. 25mm",
        hole_radius="hole radius (default: pin radius + clearance/2)",
        youngs_modulus="Young's modulus of pin and hole "
        + _default(Pin, "youngs_modulus", 1e9, "GPa"),
        poisson_ratio=f"Poisson's ratio of pin and hole {_default(Pin, 'poisson_ratio')}",
        contact_friction_coefficient="friction coefficient on the pin mu_c "
        "(default: the study's, else 0)",
    )
    _flags(p, json=_JSON_TABLE)
    _add_plot_option(p, force=True)


def _reproduce_parser(sub: Any) -> None:
    p = sub.add_parser(
        "reproduce",
        help="run the paper's whole study on the virtual rig and write a report",
        description=(
            "Run the default campaign of the virtual rig (or --campaign), identify every "
            "record, fit eq 19-22, re-run the campaign without the rig's installation "
            "sensitivity as the findings' control, draw Figs. 7-13 and write "
            "DIR/report.html (opening with the findings table), DIR/results.json, "
            "DIR/results.csv, DIR/fits.csv and DIR/records/."
        ),
    )
    p.add_argument("--out", default="clearjoint-reproduction", help="output folder")
    p.add_argument("--campaign", help="campaign file (TOML); default: the shipped one")
    p.add_argument("--jobs", type=int, default=None, help=_JOBS)
    p.add_argument(
        "--scheduler",
        help="run the rig's tests on a running Dask scheduler, e.g. tcp://host:8786 "
        "(its workers must see --out)",
    )
    p.add_argument("--workers", type=int, help="run them on a local Dask cluster of N workers")
    _flags(p, force="overwrite existing output files", quiet=_QUIET)


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
    p.add_argument("--jobs", type=int, default=None, help=_JOBS_FILES)
    _flags(p, force="overwrite existing output files", quiet=_QUIET)


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
    _options(p, out="write the motion as a test record to this netCDF file (.nc; see records)")
    _flags(
        p,
        json="print the summary as one JSON object",
        force="overwrite --out or --plot if it exists",
    )
    _add_plot_option(p, force=False)
    _flags(p, allow_long=_ALLOW_LONG, quiet=_QUIET)


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
    p.add_argument("--jobs", type=int, default=None, help=_JOBS)
    _flags(p, force="overwrite existing records", quiet="no progress bar")


def _identify_parser(sub: Any) -> None:
    p = sub.add_parser(
        "identify",
        help="clearance, stiffness, friction and energy per cycle from test records",
        description=(
            "Identify every record (CSV, netCDF, BRFD JSON; recognised by content): one row "
            "per file in --out (.csv or .nc) with each quantity's value over the steady "
            "cycles, its spread over the cycles (_std) and its standard error (_se), then "
            "a credibility flag (ok, doubtful, rejected) and flag_reason; one line for "
            "every file not used."
        ),
    )
    p.add_argument("files", nargs="+", help="record files")
    p.add_argument("--out", required=True, help="results file, .csv or .nc")
    _options(p, figures="write two figures per test into this folder")
    p.add_argument(
        "--plot",
        metavar="FILE.png",
        help="draw every identified loop with its flag into one figure (.png, .pdf or .svg)",
    )
    p.add_argument(
        "--jobs",
        type=int,
        default=None,
        help=_JOBS_FILES,
    )
    _flags(p, resample="interpolate records that are not uniformly sampled")
    p.add_argument(
        "--tolerance",
        type=float,
        default=0.03,
        help="steady-cycle amplitude tolerance (default 0.03)",
    )
    _flags(p, force="overwrite existing output and --plot", quiet="no progress bar")


def _frf_parser(sub: Any) -> None:
    p = sub.add_parser(
        "frf",
        help="whole frequency-response curve of exact periodic orbits, stable and unstable",
        description=(
            "Follow the exact period-1 orbit of the joint in STUDY.toml (joint, force, losses; "
            "its frequency is not used) by continuation from --from to --to, through folds; "
            "report folds, period doublings and grazings. With --parameter forcing, --from and "
            "--to are forces and --frequency (default: the study's) is held fixed. A structure "
            "study (clearjoint structure's file: [structure], [joint], [excitation]) is followed "
            "by exact shooting too (its frequency only), or by harmonic balance (--method "
            "harmonic), with per-DOF extremes."
        ),
    )
    p.add_argument("study", help="study file (TOML), as for clearjoint simulate")
    p.add_argument("--from", dest="start", required=True, help="start: 20Hz (or 100N)")
    p.add_argument("--to", dest="stop", required=True, help="end: 900Hz (or 2kN)")
    p.add_argument("--out", required=True, help="write the curve to this netCDF file (.nc)")
    _add_plot_option(p, force=False)
    _flags(p, json="print the curve as one JSON object")
    p.add_argument(
        "--parameter",
        choices=["frequency", "forcing", "force"],
        metavar="{frequency,forcing}",
        default="frequency",
        help="what varies along the curve: frequency, or forcing (the force amplitude; "
        "'force', its old name, still works) (default frequency)",
    )
    _options(
        p, frequency="fixed frequency with --parameter forcing, e.g. 400Hz (default: the study's)"
    )
    p.add_argument("--max-points", type=int, default=2000, help="points at most (default 2000)")
    _flags(p, allow_long=_ALLOW_LONG)
    _flags(p, force="overwrite --out / --plot if they exist", quiet=_QUIET)
    p.add_argument(
        "--method",
        choices=["shooting", "harmonic"],
        default="shooting",
        help="exact shooting (default) or harmonic balance (clearjoint.harmonic)",
    )
    _add_harmonic_options(p, "H with --method harmonic")


def _add_harmonic_options(p: argparse.ArgumentParser, harmonics: str) -> None:
    # 7 is studies.rules.DEFAULT_HARMONICS, typed here: importing the study layer at
    # parser build would import every solver
    p.add_argument("--harmonics", type=int, help=f"{harmonics} (default 7)")
    p.add_argument(
        "--samples",
        type=int,
        help="harmonic balance: time samples per period, at least 2 (2H + 1) "
        "(default 32 (2H + 1) rounded up to a power of two)",
    )


def _add_plot_option(p: argparse.ArgumentParser, *, force: bool) -> None:
    p.add_argument(
        "--plot", metavar="FILE.png", help="draw the result into this figure (.png, .pdf or .svg)"
    )
    if force:
        _flags(p, force="overwrite --plot if it exists")


def _sweep_parser(sub: Any) -> None:
    p = sub.add_parser(
        "sweep",
        help="parameter study or tolerance Monte Carlo from a sweep file, on Dask",
        description=(
            "Run the task of SWEEP.toml at every point of its grid axes and Monte Carlo "
            "draws (see docs/sweep.md), on a local Dask cluster or on a running scheduler, "
            "writing --out (a zarr store) chunk by chunk. With --plot STORE VAR: draw one "
            "output (a map, a line or a histogram) to --out (PNG)."
        ),
    )
    p.add_argument("sweep", nargs="?", help="sweep file (TOML)")
    _options(
        p,
        out="zarr store to write (.zarr); with --plot, the PNG",
        scheduler="a running Dask scheduler, e.g. tcp://host:8786",
    )
    p.add_argument("--workers", type=int, help="local cluster's worker processes (default: cores)")
    p.add_argument(
        "--retries", type=int, default=0, help="runs again of a chunk whose worker is lost (0)"
    )
    p.add_argument(
        "--cluster",
        choices=("slurm", "pbs", "sge"),
        help="workers as batch jobs (dask-jobqueue; --workers jobs, default 1; docs/sweep.md)",
    )
    p.add_argument(
        "--lock-timeout",
        default="60s",
        help="another client's lock on --out without heartbeat this long is taken over (60s)",
    )
    p.add_argument(
        "--progress-every",
        default="30s",
        help="without a terminal: a progress line on stderr this often (30s)",
    )
    _flags(
        p,
        resume="finish an interrupted --out store",
        force="replace an existing --out",
        quiet="no progress bar",
    )
    p.add_argument("--plot", nargs=2, metavar=("STORE", "VAR"), help="draw VAR of a store")


def _modes_parser(sub: Any) -> None:
    p = sub.add_parser(
        "modes",
        help="nonlinear mode: frequency and damping ratio against amplitude (EPMC)",
        description=(
            "Nonlinear mode of the joint in STUDY.toml (joint and losses; its excitation is "
            "not used), or of the structure in a structure study, by harmonic balance and the "
            "extended periodic motion concept, at --points amplitudes spaced logarithmically "
            "over --amplitude (for a structure: on the DOF where the closed linear mode moves "
            "most)."
        ),
    )
    p.add_argument("study", help="study file (TOML), as for clearjoint simulate")
    p.add_argument("--mode", type=int, default=1, help="mode number (default 1)")
    p.add_argument("--amplitude", required=True, help="modal amplitude(s): " + _AMPLITUDES)
    p.add_argument("--points", type=int, default=40, help=_POINTS)
    _flags(p, allow_long=_ALLOW_LONG)
    _add_harmonic_options(p, "H")
    p.add_argument("--out", required=True, help="write the mode to this netCDF file (.nc)")
    _add_plot_option(p, force=False)
    _flags(
        p,
        json="print the mode as one JSON object",
        force="overwrite --out / --plot if they exist",
        quiet=_QUIET,
    )


def _structure_parser(sub: Any) -> None:
    p = sub.add_parser(
        "structure",
        help="modes, forced response, free decay or stepped sine of a structure (MODEL 5.2)",
        description=(
            "Read a structure study (TOML with units, see clearjoint.structure.study) and "
            "compute its linear modes with every joint closed and open (modes), its exact "
            "forced response (respond), its exact free decay and backbone (decay), or a "
            "stepped-sine test run exactly (stepped-sine: at each of --points frequencies "
            "from --from to --to, from the state the last one left, the motion settles and is "
            "recorded; each frequency's amplitude, kind of motion and Lyapunov exponent)."
        ),
    )
    p.add_argument("study", help="structure study TOML file")
    p.add_argument(
        "task", choices=("modes", "respond", "decay", "stepped-sine"), help="what to compute"
    )
    p.add_argument("--out", required=True, help="netCDF results file (.nc)")
    _add_plot_option(p, force=False)
    _flags(p, json="print a JSON summary", force="overwrite existing output", quiet=_QUIET)
    _flags(p, allow_long=_ALLOW_LONG)
    g = p.add_argument_group("stepped-sine")
    g.add_argument("--from", dest="start", help="first frequency, e.g. 2Hz")
    g.add_argument("--to", dest="stop", help="last frequency, e.g. 60Hz")
    g.add_argument("--points", type=int, default=100, help="frequencies (default 100)")
    g.add_argument(
        "--direction",
        choices=("up", "down", "both"),
        default="up",
        help="step up, down, or up then down marking the jumps (default up)",
    )
    g.add_argument(
        "--settle-periods", type=int, default=200, help="periods to settle (default 200)"
    )
    g.add_argument("--record-periods", type=int, default=100, help="periods recorded (default 100)")
    g.add_argument(
        "--workers", type=int, help="run chunks of frequencies on a local Dask cluster of N"
    )
    g.add_argument("--scheduler", help="run them on a running Dask scheduler, tcp://host:8786")


def build_parser() -> argparse.ArgumentParser:
    """Return the argument parser of the ``clearjoint`` command."""
    parser = _Parser(prog="clearjoint", description="Dynamics of joints with clearance.")
    parser.add_argument("--version", action="version", version=f"clearjoint {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    for add in (
        _stiffness_parser,
        _simulate_parser,
        _dissipation_parser,
        _rig_parser,
        _identify_parser,
        _reproduce_parser,
        _report_parser,
        _frf_parser,
        _sweep_parser,
        _modes_parser,
        _structure_parser,
    ):
        add(sub)
    return parser


#: Options that set a study value: (option, its key in the study file, kind of quantity).
STUDY_OPTIONS = (
    ("mass", "joint.mass", "mass"),
    ("clearance", "joint.clearance", "length"),
    ("stiffness", "joint.compression_stiffness", "stiffness"),
    ("tension-stiffness", "joint.tension_stiffness", "stiffness"),
    ("gap-stiffness", "joint.gap_stiffness", "stiffness"),
    ("gap-offset", "joint.gap_offset", "length"),
    ("friction-coefficient", "losses.friction_coefficient", "dimensionless"),
    ("lateral-load", "losses.lateral_load", "force"),
    ("friction-region", "losses.friction_region", "text"),
    ("restitution", "losses.restitution", "dimensionless"),
    ("damping-ratio", "losses.damping_ratio", "dimensionless"),
    ("pin-radius", "pin.radius", "length"),
    ("pin-length", "pin.length", "length"),
    ("hole-radius", "pin.hole_radius", "length"),
    ("youngs-modulus", "pin.youngs_modulus", "pressure"),
    ("poisson-ratio", "pin.poisson_ratio", "dimensionless"),
    ("contact-friction-coefficient", "losses.contact_friction_coefficient", "dimensionless"),
)
#: How the study layer's errors name each value: as the option that gives it.
OPTION_NAMES = {key: f"--{option}" for option, key, _ in STUDY_OPTIONS} | {
    "samples": "--samples",
    "harmonics": "--harmonics",
}


def study_values(args: argparse.Namespace) -> dict[str, Any]:
    """The study values given as options, in SI by study key; a bare number is refused."""
    from clearjoint.units import parse_quantity

    values: dict[str, Any] = {}
    for option, key, kind in STUDY_OPTIONS:
        text = getattr(args, option.replace("-", "_"), None)
        if text is not None:
            values[key] = (
                text
                if kind == "text"
                else parse_quantity(text, kind, name=f"--{option}", bare="refuse")
            )
    return values


def amplitude_values(args: argparse.Namespace) -> Any:
    """The --amplitude values in m, as an array: one, a list or a range, as every command reads it.

    One value (``5um``), a comma-separated list (``1um,5um,20um``) or a range (``1um..1mm``:
    ``--points`` values spaced logarithmically), the same in stiffness, dissipation and modes.
    """
    from clearjoint.units import parse_amplitude_range, parse_quantity_list

    if ".." in args.amplitude:
        if not getattr(args, "allow_long", True):  # stiffness, dissipation: a table in memory
            from clearjoint.budget import check_table

            check_table(args.points)
        return parse_amplitude_range(args.amplitude, args.points)
    values = parse_quantity_list(args.amplitude, "length", name="--amplitude", bare="refuse")
    return np.array(values)


#: Deprecation lines when main() is called from Python rather than run as the command: off,
#: so that a caller's stderr holds what the old spelling did (the command says it).
DEPRECATION_LINES_IN_PROCESS = False


def rename_value(args: argparse.Namespace, option: str, old: str, new: str) -> None:
    """Take ``option old``, a value's old spelling, as ``option new``, saying so in one line.

    One meaning per option name (issue 28): ``--force`` overwrites, so ``--parameter force``
    became ``--parameter forcing``; the old spelling keeps working.
    """
    name = option.removeprefix("--").replace("-", "_")
    if getattr(args, name) != old:
        return
    setattr(args, name, new)
    if getattr(args, "as_command", False) or DEPRECATION_LINES_IN_PROCESS:
        print(
            f"clearjoint {args.command}: warning: {option} {old} is now {option} {new} "
            f"(--force means overwrite); write {option} {new}",
            file=sys.stderr,
        )
