"""A quick picture of one variable of a sweep: a map, a line or a histogram.

Two grid axes give a map (the first axis across), one gives a line, a Monte
Carlo sample gives a histogram (one per value of a grid axis, overlaid).
Failed points (NaN) are left blank and counted in the title, apart from the points of
a store not yet computed.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from clearjoint.errors import ParameterError

__all__ = [
    "default_picture",
    "plot_sweep",
    "save_sweep_plot",
]

#: Display units for SI lengths and energies: (largest magnitude below which, unit, scale).
_SCALES = {
    "m": [(1e-3, "um", 1e6), (1.0, "mm", 1e3)],
    "J": [(1e-3, "mJ", 1e3)],
    "N/m": [(math.inf, "MN/m", 1e-6)],
}


def _factor(data: Any, name: str) -> tuple[float, str]:
    """The factor to an engineering unit for ``name``'s values, and its axis label."""
    values = np.asarray(data[name].values, dtype=np.float64)
    unit = data[name].attrs.get("units", "")
    finite = np.abs(values[np.isfinite(values)])
    top = float(finite.max()) if finite.size else 0.0
    for below, shown, factor in _SCALES.get(unit, []):
        if top < below and top * factor >= 1.0:
            return factor, f"{name} ({shown})"
    return 1.0, f"{name} ({unit})" if unit else name


def _scaled(data: Any, name: str) -> tuple[Any, str]:
    """The values of ``name`` in an engineering unit, and its axis label."""
    factor, label = _factor(data, name)
    return np.asarray(data[name].values, dtype=np.float64) * factor, label


def _geometric(values: Any) -> bool:
    v = np.asarray(values, dtype=np.float64)
    if v.size < 3 or np.any(v <= 0):
        return False
    ratio = v[1:] / v[:-1]
    return bool(np.allclose(ratio, ratio[0], rtol=1e-6) and not np.isclose(ratio[0], 1.0))


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
    blank = np.isnan(data.values)
    if "status" in results:  # a point not yet computed (empty status) has not failed
        missing = int(np.count_nonzero(blank & (results["status"].values.astype(str) == "")))
    else:
        missing = 0
    failed = int(np.count_nonzero(blank)) - missing
    if "sample" in data.dims:
        if len(grid) > 1:
            raise ParameterError("a histogram takes at most one grid axis beside `sample`")
        groups = (
            [(None, data)]
            if not grid
            else [(v, data.sel({grid[0]: v})) for v in data[grid[0]].values]
        )
        factor, label = _factor(results, variable)
        if grid:
            axis_factor, axis_label = _factor(results, grid[0])
            axis_unit = axis_label[len(grid[0]) :].strip(" ()")
        for value, part in groups:
            finite = part.values[np.isfinite(part.values)] * factor
            name = None if value is None else f"{grid[0]} = {value * axis_factor:.4g} {axis_unit}"
            ax.hist(finite, bins="auto", alpha=0.6 if grid else 1.0, label=name)
        ax.set_xlabel(label)
        ax.set_ylabel("samples")
        if grid:
            ax.legend()
    elif len(grid) == 1:
        x, x_label = _scaled(results, grid[0])
        y, y_label = _scaled(results, variable)
        ax.plot(x, y, "o-")
        ax.set_xlabel(x_label)
        ax.set_ylabel(y_label)
        if _geometric(x):
            ax.set_xscale("log")
    elif len(grid) == 2:
        across, up = grid
        x, x_label = _scaled(results, across)
        y, y_label = _scaled(results, up)
        z, z_label = _scaled(results.transpose(up, across, ...), variable)
        mesh = ax.pcolormesh(x, y, z, shading="nearest")
        ax.figure.colorbar(mesh, ax=ax, label=z_label)
        ax.set_xlabel(x_label)
        ax.set_ylabel(y_label)
        if _geometric(x):
            ax.set_xscale("log")
        if _geometric(y):
            ax.set_yscale("log")
    else:
        raise ParameterError(
            f"{variable} has {len(grid)} grid axes; select down to two with xarray first"
        )
    title = f"{results.attrs.get('task', 'sweep')}: {variable}"
    counts = [f"{failed} points failed"] if failed else []
    counts += [f"{missing} not computed"] if missing else []
    ax.set_title(title + (f" ({', '.join(counts)})" if counts else ""))
    return ax


def default_picture(store: str | Path, variable: str) -> Path:
    """The picture of ``variable`` beside its store: ``STORE_VARIABLE.png`` (``.zarr`` dropped)."""
    store = Path(store)
    return store.with_name(f"{store.stem}_{variable}.png")


def save_sweep_plot(results: Any, variable: str, path: str | Path) -> Path:
    """Draw ``variable`` of a sweep's Dataset (:func:`plot_sweep`) into the file ``path``.

    Written at 110 dpi in the format of the file's suffix; returns the path.
    """
    path = Path(path)
    plot_sweep(results, variable).figure.savefig(path, dpi=110)
    return path
