"""Shared plumbing of the result objects' ``plot``, ``to_xarray`` and ``to_pandas`` methods.

No physics here: where a new Axes comes from, how a drawn result is saved to a file,
and how a result's 1-D amplitude axis is checked before it becomes a table.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from clearjoint.errors import ParameterError

if TYPE_CHECKING:
    import pandas as pd
    import xarray as xr


def axes_or_new(ax: Any | None) -> Any:
    """Return ``ax``, or a new Axes on a new pyplot figure when ``ax`` is None.

    pyplot is imported only here, so that a result made in a script without a
    display costs nothing until it is drawn.
    """
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt

    _, new = plt.subplots(layout="constrained")
    return new


def one_dimensional(name: str, values: NDArray[np.float64]) -> NDArray[np.float64]:
    """Return ``values`` as a 1-D array (a scalar becomes one entry), or refuse a grid.

    Raises
    ------
    ParameterError
        ``values`` has more than one dimension: a table needs one row per value.
    """
    array = np.atleast_1d(np.asarray(values, dtype=np.float64))
    if array.ndim != 1:
        raise ParameterError(
            f"{name} has shape {array.shape}; a table needs a 1-D {name}: "
            "compute the result for a 1-D array of amplitudes"
        )
    return array


def save_figure(drawn: Any, path: str | Path) -> Path:
    """Save ``drawn`` to the figure file ``path`` (its folder made) and return the path.

    ``drawn`` is a matplotlib Figure already drawn, or a result with ``plot(ax)``, drawn
    here on a new 6.4 x 4.4 inch Figure (no pyplot, so no display is needed). The file
    is written at 120 dpi in the format of its suffix (.png, .pdf or .svg).
    """
    from matplotlib.figure import Figure

    if not isinstance(drawn, Figure):
        result, drawn = drawn, Figure(figsize=(6.4, 4.4), layout="constrained")
        result.plot(drawn.add_subplot())
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    drawn.savefig(path, dpi=120)
    return path


def dataset_on_amplitude(
    amplitude: NDArray[np.float64],
    columns: dict[str, tuple[NDArray[Any], str]],
    attrs: dict[str, object],
) -> xr.Dataset:
    """Return ``columns`` (name: (values, unit)) as a Dataset on the 1-D coordinate ``amplitude``.

    Each array broadcast like ``amplitude`` (m), its unit in its attrs; ``attrs`` the
    Dataset's. The body of the amplitude results' ``to_xarray``.
    """
    import xarray as xr

    a = one_dimensional("amplitude", amplitude)
    return xr.Dataset(
        {
            name: ("amplitude", np.broadcast_to(values, a.shape).copy(), {"units": unit})
            for name, (values, unit) in columns.items()
        },
        coords={"amplitude": ("amplitude", a, {"units": "m"})},
        attrs=attrs,
    )


def frame_on_amplitude(
    amplitude: NDArray[np.float64], columns: dict[str, NDArray[Any]]
) -> pd.DataFrame:
    """Return ``columns`` (name: values) as a DataFrame on the 1-D index ``amplitude_m``.

    Each array broadcast like ``amplitude`` (m). The body of the amplitude results'
    ``to_pandas`` where the column names carry the unit.
    """
    import pandas as pd

    a = one_dimensional("amplitude", amplitude)
    return pd.DataFrame(
        {name: np.broadcast_to(values, a.shape) for name, values in columns.items()},
        index=pd.Index(a, name="amplitude_m"),
    )
