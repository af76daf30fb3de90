"""The results of identifying a set of records, written: a table and two figures per test.

The identification itself is :mod:`clearjoint.identify`'s; here its rows become one
file (CSV, or netCDF over ``file``) and each test its stage and loop figures.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

__all__ = [
    "figure_files",
    "write_identification_figures",
    "write_identification_results",
    "write_identifications",
]


def write_identifications(rows: list[dict[str, Any]], out: Path) -> None:
    """Write one row per identified record to ``out`` (.csv, else netCDF over ``file``)."""
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


def write_identification_results(
    results: list[Any], out: Path, *, figures: Path | None, plot: Path | None, force: bool
) -> None:
    """Write the table ``out``, two figures per test into ``figures``, all loops to ``plot``.

    Every figure file is checked before any output is written.

    Raises
    ------
    OutputExistsError
        A figure exists and ``force`` is False.
    """
    from clearjoint.checks import refuse_to_overwrite

    if figures is not None:
        targets = [t for _, ident in results for t in figure_files(ident, figures)]
        refuse_to_overwrite(targets, force=force, option="--figures")
    write_identifications([ident.row() for _, ident in results], out)
    if figures is not None:
        write_identification_figures(results, figures, force=force)
    if plot is not None:
        from clearjoint.identify import identifications_figure

        plot.parent.mkdir(parents=True, exist_ok=True)
        identifications_figure([ident for _, ident in results]).savefig(plot, dpi=100)


def figure_files(ident: Any, folder: Path) -> list[Path]:
    """Return the two figure files of one identification: its stages and its loop."""
    stem = Path(ident.source).stem
    return [folder / f"{stem}_stages.png", folder / f"{stem}_loop.png"]


def write_identification_figures(results: list[Any], folder: Path, *, force: bool) -> None:
    """Draw each (record, identification)'s stages and loop into ``folder``, flag in the title.

    Raises
    ------
    OutputExistsError
        A figure exists and ``force`` is False.
    """
    from clearjoint.checks import refuse_to_overwrite
    from clearjoint.figures import displacement_stages_figure, identified_loop_figure

    folder.mkdir(parents=True, exist_ok=True)
    for record, ident in results:
        stem = Path(ident.source).stem
        targets = figure_files(ident, folder)
        refuse_to_overwrite(targets, force=force, option="--figures")
        first = ident.cycles[0]
        span = slice(first.start, ident.cycles[-1].stop)
        runs = ident.stage_runs(record.time)
        title = f"{stem} [{ident.flag}]"  # the credibility flag on every figure
        fig = displacement_stages_figure(record.time, record.displacement, runs, title=title)
        fig.savefig(targets[0], dpi=100)
        fig = identified_loop_figure(
            record.displacement[span],
            ident.restoring_force[span],
            ident.stage[span],
            (first.upper_edge, first.lower_edge),
            first.lines,
            title=title,
            model=ident.model,
            slip_levels=(
                ident.summary["friction_force_positive_n"],
                ident.summary["friction_force_negative_n"],
            ),
            note=ident.flag_reason,
        )
        fig.savefig(targets[1], dpi=100)
