"""The ``clearjoint`` command line: parses, calls the library, prints. No physics here.

Quantities take units (``0.106mm``, ``5um``, ``8e7N/m``, ``400Hz``): a bare
number for a dimensional quantity is refused with the way to write it, since
"0.106" meant in mm would silently be 106 mm in SI. Frequencies are in Hz.
Options given beside ``--study`` override the study. Bad input, including a
file that is missing, a folder, empty, binary or of the wrong kind, ends with
exit code 2 and one line on stderr that says what is wrong and where.

The subcommands, their options and help are declared in :mod:`clearjoint.cli_parser`;
here each parsed command is run and its result printed.
"""

from __future__ import annotations

import argparse
import contextlib
import itertools
import json
import logging
import math
import os
import signal
import sys
import time
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from clearjoint import cli_progress
from clearjoint.checks import figure_target, netcdf_target, refuse_file_as_folder
from clearjoint.cli_parser import (
    EXIT_BAD_INPUT,
    OPTION_NAMES,
    amplitude_values,
    build_parser,
    rename_value,
    study_values,
)
from clearjoint.errors import ClearjointError, ParameterError

__all__ = ["build_parser", "main"]  # build_parser lives in clearjoint.cli_parser


def _cores() -> int:
    """The cores this process may run on (clearjoint.parallel.usable_cores, imported late)."""
    from clearjoint.parallel import usable_cores

    return usable_cores()


def _plot_target(args: argparse.Namespace) -> Path | None:
    """The --plot file, checked before any work: a figure suffix, not overwritten unasked."""
    return None if args.plot is None else figure_target(args.plot, "--plot", force=args.force)


def _save_plot(result: Any, path: Path | None, *, quiet: bool) -> None:
    """Save ``result`` (a Figure, or drawn by its ``plot(ax)``) to ``path`` (nothing if None)."""
    from clearjoint.plotting import save_figure

    if path is not None:
        save_figure(result, path)
        if not quiet:
            print(f"wrote {path}")


def _netcdf_target(args: argparse.Namespace) -> Path:
    """The --out netCDF file, checked before any work: a .nc suffix, not overwritten unasked."""
    return netcdf_target(args.out, args.command, force=args.force)


def _run_stiffness(args: argparse.Namespace) -> int:
    from clearjoint import stiffness
    from clearjoint.studies import joint_at
    from clearjoint.studies.text import json_value, stiffness_lines, stiffness_table

    given = study_values(args)
    _warn_unusual(args.command, given)
    joint = joint_at(None, given, OPTION_NAMES)
    amplitudes = amplitude_values(args)
    plot = _plot_target(args)
    _save_plot(stiffness.stiffness_curve(joint, amplitudes), plot, quiet=args.json)
    table = stiffness_table(joint, amplitudes)
    several = amplitudes.size > 1
    if args.json:
        print(json.dumps({key: json_value(val, several) for key, val in table.items()}))
    else:
        print("\n".join(stiffness_lines(joint, table)))
    return 0


def _run_dissipation(args: argparse.Namespace) -> int:
    from clearjoint import dissipation
    from clearjoint.studies import joint_at, load_study, losses_at
    from clearjoint.studies.text import dissipation_lines, json_value

    base = load_study(args.study) if args.study else None
    given = study_values(args)
    _warn_unusual(args.command, given)
    joint = joint_at(base.joint if base is not None else None, given, OPTION_NAMES)
    losses = losses_at(base, joint, given, OPTION_NAMES)
    amplitudes = amplitude_values(args)
    plot = _plot_target(args)
    values = dissipation.energies(joint, amplitudes, losses=losses)
    _save_plot(values, plot, quiet=args.json)
    several = amplitudes.size > 1
    if args.json:
        out = {"amplitude_m": json_value(amplitudes, several)}
        out.update({key: json_value(val, several) for key, val in values.items()})
        print(json.dumps(out))
    else:
        print("\n".join(dissipation_lines(joint, losses, amplitudes, values)))
    return 0


def _warn_unusual(command: str, given: dict[str, Any]) -> None:
    """One warning line for each value legal but unusual for a pin joint (clearjoint.plausible)."""
    from clearjoint.plausible import unusual_values

    for note in unusual_values(given, OPTION_NAMES):
        print(f"clearjoint {command}: warning: {note}", file=sys.stderr)


def _run_simulate(args: argparse.Namespace) -> int:
    from clearjoint.studies import load_study, run_study, summary, write_netcdf
    from clearjoint.studies.text import simulation_lines

    study = load_study(args.study)
    if study.mode == "transient" and not args.allow_long:  # a runaway duration, refused
        _check_transient(study)
    if study.mode == "steady" and not args.allow_long:  # a runaway output, refused
        from clearjoint.budget import check_output

        check_output(study.periods, study.samples_per_period)
    if args.out:  # before the run, not after
        out = netcdf_target(args.out, "simulate", force=args.force, example="result.nc")
        out.parent.mkdir(parents=True, exist_ok=True)
    plot = _plot_target(args)
    with cli_progress.shown_progress(args, f"simulating {study.source}"):  # says a compile
        motion = run_study(study)
    _save_plot(motion, plot, quiet=args.json)
    result = summary(study, motion)
    if args.out:
        write_netcdf(study, motion, args.out, force=args.force)
    if args.json:
        print(json.dumps(result))
        return 0
    lines = simulation_lines(study.source, study.mode, result)
    print("\n".join(lines + ([f"wrote {args.out}"] if args.out else [])))
    return 0


def _check_transient(study: Any) -> None:
    """Refuse a transient whose [excitation] duration would take above the budget's limit."""
    from clearjoint.budget import check_budget

    periods = study.duration * study.omega / (2.0 * math.pi)
    check_budget(
        periods,
        "joint forcing period",
        option="[excitation] duration",
        given=f"[excitation] duration {study.duration:g} s ({periods:.3g} forcing periods)",
    )


def _run_rig(args: argparse.Namespace) -> int:
    import time

    from clearjoint.rig import load_campaign, run_campaign

    campaign = load_campaign(args.campaign)
    refuse_file_as_folder(args.out, "--out")
    jobs = args.jobs or _cores()  # for the progress line only
    start = time.perf_counter()
    total = len(campaign.tests)
    with cli_progress.shown_progress(args, f"{total} tests on {jobs} processes"):
        manifest = run_campaign(campaign, args.out, jobs=args.jobs, force=args.force)
    print(f"wrote {total} records and {manifest} in {time.perf_counter() - start:.1f} s")
    return 0


def _run_identify(args: argparse.Namespace) -> int:
    from clearjoint.checks import refuse_to_overwrite
    from clearjoint.identify import identify_files
    from clearjoint.studies.identify import write_identification_results

    out = Path(args.out)
    if out.suffix.lower() not in (".csv", ".nc"):
        raise ParameterError(f"--out must end in .csv or .nc, got {out.name!r}")
    if not 0.0 < args.tolerance < 1.0:
        raise ParameterError(f"--tolerance must lie in (0, 1), got {args.tolerance}")
    if args.jobs is not None and args.jobs < 1:
        raise ParameterError(f"--jobs must be at least 1, got {args.jobs}")
    jobs = args.jobs or _cores()  # every core by default, as rig and reproduce
    plot = _plot_target(args)  # a figure suffix, not overwritten unless --force
    refuse_to_overwrite([out], force=args.force)
    out.parent.mkdir(parents=True, exist_ok=True)  # fails here, before the work, if it cannot
    options = {"resample": args.resample, "tolerance": args.tolerance, "jobs": jobs}

    if args.figures:
        refuse_file_as_folder(args.figures, "--figures")
    with cli_progress.shown_progress(args, f"identifying {len(args.files)} records") as shown:
        results, failures = identify_files(args.files, **options, progress=shown)
    if not results and len(failures) == 1:
        raise ParameterError(f"no record could be used: {failures[0]}")  # one file, one line
    for line in failures:
        print(f"not used: {line}", file=sys.stderr)
    for _, ident in results:
        for warning in ident.warnings:
            print(f"clearjoint identify: warning: {warning}", file=sys.stderr)
    if not results:
        print("clearjoint identify: error: no record could be used", file=sys.stderr)
        return EXIT_BAD_INPUT
    figures = Path(args.figures) if args.figures else None
    write_identification_results(results, out, figures=figures, plot=plot, force=args.force)
    if plot is not None:
        print(f"wrote {plot}")
    flagged = sum(ident.flag != "ok" for _, ident in results)
    print(
        f"identified {len(results)} of {len(args.files)} records ({flagged} flagged, see the "
        f"flag and flag_reason columns); wrote {out}"
    )
    return 0


def _run_reproduce(args: argparse.Namespace) -> int:
    import time

    from clearjoint.parallel import optional_client
    from clearjoint.reproduction import reproduce

    if args.jobs is not None and (args.scheduler or args.workers is not None):
        raise ParameterError(
            "--jobs sizes a process pool; leave it out with --scheduler or --workers"
        )
    refuse_file_as_folder(args.out, "--out")
    start = time.perf_counter()
    with (
        optional_client(args.scheduler, args.workers) as client,  # None: the --jobs pool
        cli_progress.shown_progress(args, "the virtual rig's campaign"),
    ):
        written = reproduce(
            Path(args.out),
            force=args.force,
            jobs=args.jobs,
            executor=client,
            campaign_path=Path(args.campaign) if args.campaign else None,
            progress=_stage_printer(args),
        )
    for path in written:
        print(f"wrote {path}")
    _print_findings(Path(args.out) / "results.json")
    print(f"done in {time.perf_counter() - start:.0f} s")
    return 0


def _stage_printer(args: argparse.Namespace) -> Callable[[str], None]:
    """Print each stage of a long job on stderr as ``- stage`` (nothing with --quiet)."""
    if getattr(args, "quiet", False):
        return lambda _message: None
    return lambda message: print(f"- {message}", file=sys.stderr, flush=True)


def _print_findings(results: Path) -> None:
    """Print the findings table of a written report, one row per paper finding."""
    import json

    from clearjoint.findings import testable

    rows = json.loads(results.read_text(encoding="utf-8"))["findings"]
    print("the paper's findings (reproduced, source): see report.html for the evidence")
    for row in rows:
        mark = "yes" if row["reproduced"] else ("NO " if testable(row) else "n/a")
        print(f"  {mark}  {row['source']:<9}  {row['finding']}")


def _run_report(args: argparse.Namespace) -> int:
    from clearjoint.records import RecordError
    from clearjoint.reproduction import report_records

    folder = Path(args.records)
    if not folder.exists():
        raise RecordError(f"{folder}: no such folder; give --records a folder of record files")
    if not folder.is_dir():
        raise RecordError(f"{folder}: not a folder; give --records a folder of record files")
    refuse_file_as_folder(args.out, "--out")
    if args.jobs is not None and args.jobs < 1:
        raise ParameterError(f"--jobs must be at least 1, got {args.jobs}")
    jobs = args.jobs or _cores()  # every core by default, as identify
    with cli_progress.shown_progress(args, "identifying the records") as shown:
        written = report_records(
            Path(args.records),
            Path(args.out),
            force=args.force,
            progress=_stage_printer(args),
            warn=lambda m: print(f"clearjoint report: warning: {m}", file=sys.stderr, flush=True),
            jobs=jobs,
            files_done=shown,
        )
    for path in written:
        print(f"wrote {path}")
    _print_findings(Path(args.out) / "results.json")
    return 0


@contextlib.contextmanager
def _harmonic_progress(command: str) -> Any:
    """Print clearjoint.harmonic's progress lines (its slow start) on stderr, one line each."""
    logger = logging.getLogger("clearjoint.harmonic")
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter(f"clearjoint {command}: %(message)s"))
    level = logger.level
    logger.addHandler(handler)
    logger.setLevel(logging.INFO)
    try:
        yield
    finally:
        logger.removeHandler(handler)
        logger.setLevel(level)


def _warning_printer(command: str) -> Callable[..., None]:
    """A warnings.showwarning that prints one line, without the source file and line."""

    def show(message: Warning | str, category: type[Warning], *_: Any, **__: Any) -> None:
        print(f"clearjoint {command}: warning: {message}", file=sys.stderr)

    return show


def _run_sweep(args: argparse.Namespace) -> int:
    import time

    if args.plot:
        return _plot_sweep(args)
    from clearjoint.sweep.run import run_sweep_file
    from clearjoint.units import parse_quantity

    if args.sweep is None or args.out is None:
        raise ParameterError("give a sweep file and --out results.zarr (or --plot STORE VAR)")
    lock_timeout = parse_quantity(args.lock_timeout, "time", name="--lock-timeout")
    every = parse_quantity(args.progress_every, "time", name="--progress-every")
    if not lock_timeout > 0 or not every > 0:
        raise ParameterError("--lock-timeout and --progress-every must be > 0 s, e.g. 60s")
    start = time.perf_counter()
    with contextlib.ExitStack() as stack:

        def bar(sweep: Any) -> Callable[[int, int], None] | None:
            if args.quiet:
                return None
            if not sys.stderr.isatty():  # a batch log: a line every `every` seconds
                return _progress_lines(every, start)
            from rich.progress import Progress, TimeRemainingColumn

            columns = (*Progress.get_default_columns()[:-1], TimeRemainingColumn())
            shown = stack.enter_context(cli_progress.progress_bar(*columns))
            task = shown.add_task(f"{sweep.n_points} points", total=sweep.n_points)
            return lambda done, _total: shown.update(task, completed=done)

        results, kept = run_sweep_file(  # Ctrl-C: main says what the store keeps
            args.sweep,
            args.out,
            scheduler=args.scheduler,
            workers=args.workers,
            resume=args.resume,
            force=args.force,
            progress=bar,
            retries=args.retries,
            lock_timeout=lock_timeout,
            cluster=args.cluster,
        )
    failed = results.attrs["points_failed"]
    kept_text = f", {kept} of them kept from the store" if kept else ""
    print(
        f"wrote {results.attrs['points']} points{kept_text} ({failed} failed: see `status`) "
        f"to {args.out} in {time.perf_counter() - start:.1f} s"
    )
    return 0


def _progress_lines(every: float, start: float) -> Callable[[int, int], None]:
    """A progress callback that prints one line on stderr at most every ``every`` seconds."""
    import time

    last = [time.perf_counter()]

    def line(done: int, total: int) -> None:
        now = time.perf_counter()
        if now - last[0] < every:  # the end is said by the "wrote" line
            return
        last[0] = now
        print(
            f"clearjoint sweep: {done} of {total} points stored ({100 * done / total:.0f} %) "
            f"after {now - start:.0f} s",
            file=sys.stderr,
            flush=True,
        )

    return line


def _plot_sweep(args: argparse.Namespace) -> int:
    from clearjoint.sweep import open_sweep
    from clearjoint.sweep.plot import default_picture, save_sweep_plot

    store, variable = args.plot
    if args.sweep is not None:
        raise ParameterError("--plot STORE VAR takes no sweep file")
    picture = args.out or str(default_picture(store, variable))
    out = figure_target(picture, "--out", force=args.force)  # checked before the work
    print(f"wrote {save_sweep_plot(open_sweep(store), variable, out)}")
    return 0


def _run_frf(args: argparse.Namespace) -> int:
    from clearjoint.budget import check_budget
    from clearjoint.structure.study import StructureStudy
    from clearjoint.studies import (
        curve_summary,
        frequency_response_of,
        load_any_study,
        write_curve,
    )
    from clearjoint.studies.text import curve_lines, curve_warnings
    from clearjoint.units import parse_quantity

    rename_value(args, "--parameter", "force", "forcing")
    # a force curve takes its forces from --from/--to, not from the study
    force_curve = args.parameter == "forcing"
    study = load_any_study(
        args.study, optional=("excitation.force_amplitude",) if force_curve else ()
    )
    _netcdf_target(args)  # before the run, not after
    plot_path = _plot_target(args)
    kind = "force" if force_curve else "frequency"
    start = parse_quantity(args.start, kind, name="--from")
    stop = parse_quantity(args.stop, kind, name="--to")
    for option, text, value in (("--from", args.start, start), ("--to", args.stop, stop)):
        if not (math.isfinite(value) and value > 0.0):
            raise ParameterError(f"{option} must be finite and > 0, got {text!r}")
        if kind == "frequency":
            _warn_rpm(args.command, option, text, value)
    if start == stop:
        raise ParameterError(
            f"--from and --to give a range of zero width ({args.start} to {args.stop}); "
            "give two different values"
        )
    if args.max_points < 2:
        raise ParameterError(f"--max-points must be >= 2, got {args.max_points}; e.g. 2000")
    structure = isinstance(study, StructureStudy)
    if not args.allow_long:
        kind_of_point = "structure curve point" if structure else "joint curve point"
        check_budget(args.max_points, kind_of_point, option="--max-points")
    for option, given in (("--harmonics", args.harmonics), ("--samples", args.samples)):
        if args.method != "harmonic" and given is not None:
            raise ParameterError(f"{option} goes with --method harmonic; drop it or add that")
    frequency = None
    if args.frequency and not force_curve:
        raise ParameterError(
            "--frequency goes with --parameter forcing (formerly --parameter force); "
            "drop it or add that"
        )
    if args.frequency:
        frequency = parse_quantity(args.frequency, "frequency", name="--frequency")
        if not (math.isfinite(frequency) and frequency > 0.0):
            raise ParameterError(f"--frequency must be finite and > 0, got {args.frequency!r}")
        _warn_rpm(args.command, "--frequency", args.frequency, frequency)
    with cli_progress.shown_progress(args, f"following the curve from {args.start} to {args.stop}"):
        curve = frequency_response_of(
            study,
            start,
            stop,
            parameter="force" if force_curve else "frequency",  # the Python API's name
            frequency=frequency,
            method=args.method,
            harmonics=args.harmonics,
            samples=args.samples,
            max_points=args.max_points,
            names=OPTION_NAMES,
        )
    write_curve(curve, args.out, study.source)
    _save_plot(curve, plot_path, quiet=True)
    for warning in curve_warnings(curve):
        print(f"clearjoint frf: warning: {warning}", file=sys.stderr)
    if args.json:
        print(json.dumps(curve_summary(curve)))
        return 0
    wrote = f"wrote {args.out}" + (f" and {args.plot}" if args.plot else "")
    print("\n".join([*curve_lines(curve, study.source), wrote]))
    return 0


def _warn_rpm(command: str, option: str, text: str, hz: float) -> None:
    """Warn in one line when a frequency option was written in rpm (clearjoint.plausible)."""
    from clearjoint.plausible import rpm_note

    note = rpm_note(text, hz, option)
    if note is not None:
        print(f"clearjoint {command}: warning: {note}", file=sys.stderr)


def _run_modes(args: argparse.Namespace) -> int:
    from clearjoint.budget import check_budget
    from clearjoint.structure.study import StructureStudy
    from clearjoint.studies import load_any_study, mode_summary, nonlinear_modes_of, write_curve

    study = load_any_study(args.study)
    _netcdf_target(args)  # before the run, not after
    plot_path = _plot_target(args)
    if not args.allow_long and ".." in args.amplitude:  # before the amplitudes are made
        structure = isinstance(study, StructureStudy)
        kind = "structure mode amplitude" if structure else "joint mode amplitude"
        check_budget(args.points, kind, option="--points")
    amplitudes = (amplitude_values if "," in args.amplitude else _amplitude_range)(args)
    listed = amplitudes.tolist()
    if min(listed) <= 0.0 or any(b <= a for a, b in itertools.pairwise(listed)):
        raise ParameterError(
            f"--amplitude {args.amplitude}: a mode's amplitudes must be above zero and "
            "ascending, e.g. 1um,5um,20um or 1um..1mm"
        )
    with cli_progress.shown_progress(args, f"mode {args.mode} at {amplitudes.size} amplitudes"):
        mode = nonlinear_modes_of(
            study,
            args.mode,
            amplitudes,
            harmonics=args.harmonics,
            samples=args.samples,
            names=OPTION_NAMES,
        )
    write_curve(mode, args.out, study.source)
    _save_plot(mode, plot_path, quiet=True)
    for line in filter(None, mode.note.split("; ")):
        print(f"clearjoint modes: warning: {line}", file=sys.stderr)
    if args.json:
        print(json.dumps(mode_summary(mode)))
        return 0
    wrote = f"wrote {args.out}" + (f" and {args.plot}" if args.plot else "")
    print("\n".join([f"study: {study.source}", repr(mode), wrote]))
    return 0


#: The options of ``clearjoint structure STUDY stepped-sine`` and nothing else.
_STEPPED_ONLY = (
    ("--from", "start", None),
    ("--to", "stop", None),
    ("--points", "points", 100),
    ("--direction", "direction", "up"),
    ("--settle-periods", "settle_periods", 200),
    ("--record-periods", "record_periods", 100),
    ("--workers", "workers", None),
    ("--scheduler", "scheduler", None),
)


def _amplitude_range(args: argparse.Namespace) -> Any:
    """A mode's --amplitude as one value or a range (clearjoint.units.parse_amplitude_range)."""
    from clearjoint.units import parse_amplitude_range

    return parse_amplitude_range(args.amplitude, args.points)


def _check_structure_budget(args: argparse.Namespace, study: Any) -> None:
    """Refuse a structure task whose periods of exact motion would take above the limit."""
    from clearjoint.budget import check_budget, structure_period_s, structure_tangent_s
    from clearjoint.studies import marched_periods

    periods = marched_periods(
        study,
        args.task,
        points=args.points * (2 if args.direction == "both" else 1),  # up, then down
        settle_periods=args.settle_periods,
        record_periods=args.record_periods,
    )
    n_dof = study.structure.n_dof
    given = {
        "respond": f"[excitation] periods {periods:.0f}",
        "decay": f"[decay] duration {study.decay_duration or 0.0:g} s "
        f"({periods:.3g} periods of closed mode 1)",
        "stepped-sine": f"--points {args.points} x (--settle-periods {args.settle_periods} "
        f"+ --record-periods {args.record_periods}) periods"
        + (" x 2 directions" if args.direction == "both" else ""),
    }.get(args.task)
    if given is not None:
        each, kind = structure_period_s(n_dof), f"period of this {n_dof}-DOF structure"
        recorded = periods * args.record_periods / max(1, args.settle_periods + args.record_periods)
        stepped = args.task == "stepped-sine"  # each recorded period carries the tangent flow
        extra = (recorded, structure_tangent_s(n_dof), "the tangent flow") if stepped else None
        check_budget(periods, kind, option="", each=each, given=given, extra=extra)


def _run_structure(args: argparse.Namespace) -> int:
    from clearjoint.structure.study import load_structure_study
    from clearjoint.studies import run_structure_task, write_structure_result

    stepped = args.task == "stepped-sine"
    for option, name, default in _STEPPED_ONLY:
        if not stepped and getattr(args, name) != default:
            raise ParameterError(f"{option} goes with the stepped-sine task; drop it or use that")
    if stepped and (args.start is None or args.stop is None):
        raise ParameterError("stepped-sine needs --from and --to, e.g. --from 2Hz --to 60Hz")
    out = _netcdf_target(args)
    plot_path = _plot_target(args)
    study = load_structure_study(args.study)
    if not args.allow_long:
        _check_structure_budget(args, study)
    with cli_progress.shown_progress(args, f"{args.task} of {study.source}"):
        if stepped:
            from clearjoint.parallel import optional_client
            from clearjoint.studies import stepped_sine_of
            from clearjoint.units import parse_quantity

            start = parse_quantity(args.start, "frequency", name="--from")
            stop = parse_quantity(args.stop, "frequency", name="--to")
            _warn_rpm(args.command, "--from", args.start, start)
            _warn_rpm(args.command, "--to", args.stop, stop)
            with optional_client(args.scheduler, args.workers) as client:
                result = stepped_sine_of(
                    study,
                    start,
                    stop,
                    points=args.points,
                    direction=args.direction,
                    settle_periods=args.settle_periods,
                    record_periods=args.record_periods,
                    runner=client,
                )
        else:
            result = run_structure_task(study, args.task, figure=plot_path is not None)
    write_structure_result(result, out)
    _save_plot(result.drawn, plot_path, quiet=True)
    if args.json:
        print(json.dumps(result.summary))
        return 0
    for key, value in result.summary.items():
        if isinstance(value, list):  # a cycle without a damping ratio (the last) says so
            value = ["n/a" if item is None else item for item in value]
        print(f"{key}: {value}")
    print(f"wrote {out}" + (f" and {args.plot}" if args.plot else ""))
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit code."""
    if argv is None:  # the command itself, whose interpreter ends when this returns
        import atexit
        import gc

        # at the end, skip the interpreter's collections over every object left (numpy's
        # modules: about 10 ms of each run); Python never promised their __del__ at exit
        atexit.register(gc.freeze)
        signal.signal(signal.SIGINT, cli_progress.on_interrupt)  # Ctrl-C noted, not only raised
        sys.unraisablehook = cli_progress.unraisable
    parser = build_parser()
    args = parser.parse_args(argv)
    args.progress_lines = argv is None or cli_progress.PROGRESS_LINES_IN_PROCESS
    args.as_command = argv is None
    started = time.time()
    runners = {
        "stiffness": _run_stiffness,
        "simulate": _run_simulate,
        "dissipation": _run_dissipation,
        "rig": _run_rig,
        "identify": _run_identify,
        "reproduce": _run_reproduce,
        "report": _run_report,
        "frf": _run_frf,
        "sweep": _run_sweep,
        "modes": _run_modes,
        "structure": _run_structure,
    }
    try:
        with warnings.catch_warnings(), _harmonic_progress(args.command):
            warnings.showwarning = _warning_printer(args.command)
            code = runners[args.command](args)
            cli_progress.stop_if_interrupted()  # a Ctrl-C that compiled code swallowed
            return code
    except KeyboardInterrupt:  # Ctrl-C: one line, exit 130, as a shell reports SIGINT
        return cli_progress.interrupted(args, started, end=argv is None)
    except BrokenPipeError:  # the reader stopped early (| head): not an error of ours
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())  # so the exit's flush does not raise again
        return 0
    except ClearjointError as exc:
        print(f"clearjoint {args.command}: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except OSError as exc:  # a path the readers and writers did not check themselves
        where = f"{exc.filename}: " if exc.filename else ""
        reason = exc.strerror or str(exc)
        if isinstance(exc, FileExistsError | NotADirectoryError):  # mkdir met a file
            reason = "a file stands where a folder is needed"
        print(
            f"clearjoint {args.command}: error: {where}{reason.lower()}; check the path",
            file=sys.stderr,
        )
        return EXIT_BAD_INPUT
    except Exception as exc:  # Ctrl-C inside compiled code arrives wrapped (a SystemError)
        if cli_progress.caused_by_interrupt(exc):
            return cli_progress.interrupted(args, started, end=argv is None)
        raise
