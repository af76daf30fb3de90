"""A quick picture of one variable of a sweep: a map, a line or a histogram.

Two grid axes give a map (the first axis across), one gives a line, a Monte
Carlo sample gives a histogram (one per value of a grid axis, overlaid).
Failed points (NaN) are left blank and counted in the title.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from clearjoint.errors import ParameterError


def _label(data: Any, name: str) -> str:
    unit = data[name].attrs.get("units", "")
    return f"{name} ({unit})" if unit else name


def plot_sweep(results: Any, variable: str, ax: Any = None) -> Any:
    """Draw ``variable`` of a sweep's Dataset and return the matplotlib Axes.

    Parameters
    ----------
    results : xarray.Dataset
        From :func:`clearjoint.sweep.run_sweep` or :func:`clearjoint.sweep.open_sweep`.
    variable : str
        An output of the sweep (not ``status``).
    ax : matplotlib Axes, optional

    Raises
    ------
    ParameterError
        ``variable`` is not a numeric output, or the sweep has more than two grid axes.
    """
    import matplotlib.pyplot as plt

    numeric = [k for k, v in results.data_vars.items() if v.dtype.kind == "f"]
    if variable not in numeric:
        raise ParameterError(f"no output {variable!r} in this sweep; choose one of {numeric}")
    data = results[variable]
    if ax is None:
        _, ax = plt.subplots(figsize=(6.4, 4.4), layout="constrained")
    grid = [d for d in data.dims if d != "sample"]
    failed = int(np.count_nonzero(np.isnan(data.values)))
    if "sample" in data.dims:
        if len(grid) > 1:
            raise ParameterError("a histogram takes at most one grid axis beside `sample`")
        groups = (
            [(None, data)]
            if not grid
            else [(v, data.sel({grid[0]: v})) for v in data[grid[0]].values]
        )
        for value, part in groups:
            finite = part.values[np.isfinite(part.values)]
            label = None if value is None else f"{grid[0]} = {value:.4g}"
            ax.hist(finite, bins="auto", alpha=0.6 if grid else 1.0, label=label)
        ax.set_xlabel(_label(results, variable))
        ax.set_ylabel("samples")
        if grid:
            ax.legend()
    elif len(grid) == 1:
        ax.plot(data[grid[0]].values, data.values, "o-")
        ax.set_xlabel(_label(results, grid[0]))
        ax.set_ylabel(_label(results, variable))
    elif len(grid) == 2:
        across, up = grid
        mesh = ax.pcolormesh(
            data[across].values, data[up].values, data.transpose(up, across).values, shading="auto"
        )
        ax.figure.colorbar(mesh, ax=ax, label=_label(results, variable))
        ax.set_xlabel(_label(results, across))
        ax.set_ylabel(_label(results, up))
    else:
        raise ParameterError(
            f"{variable} has {len(grid)} grid axes; select down to two with xarray first"
        )
    title = f"{results.attrs.get('task', 'sweep')}: {variable}"
    ax.set_title(title + (f" ({failed} points failed)" if failed else ""))
    return ax
