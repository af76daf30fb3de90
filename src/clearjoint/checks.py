"""Input checks shared by every module: one clear message per bad value.

Every check also takes a pint Quantity or a unit string ("2kg", "400Hz") and
converts it to the SI ``unit`` it is given (through :func:`clearjoint.units.to_si`);
a bare number is SI.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from clearjoint.errors import OutputExistsError, ParameterError, ParameterTypeError
from clearjoint.units import to_si


def real_scalar(name: str, value: Any, *, unit: str = "") -> float:
    """Return ``value`` as a finite float, or raise an error naming ``name``."""
    value = to_si(value, unit, name=name)
    if isinstance(value, bool | np.bool_) or not isinstance(value, numbers.Real):
        raise ParameterTypeError(
            f"{name} must be a real number{_in(unit)}, got {value!r} of type {type(value).__name__}"
        )
    result = float(value)
    if not math.isfinite(result):
        raise ParameterError(f"{name} must be finite{_in(unit)}, got {result!r}")
    return result


def positive(name: str, value: Any, *, unit: str = "") -> float:
    """Return ``value`` as a float > 0, or raise an error naming ``name``."""
    result = real_scalar(name, value, unit=unit)
    if result <= 0.0:
        raise ParameterError(f"{name} must be > 0{_in(unit)}, got {result!r}")
    return result


def non_negative(name: str, value: Any, *, unit: str = "") -> float:
    """Return ``value`` as a float >= 0, or raise an error naming ``name``."""
    result = real_scalar(name, value, unit=unit)
    if result < 0.0:
        raise ParameterError(f"{name} must be >= 0{_in(unit)}, got {result!r}")
    return result


def non_negative_array(name: str, value: Any, *, unit: str = "") -> NDArray[np.float64]:
    """Return ``value`` as a float array with every entry finite and >= 0."""
    value = to_si(value, unit, name=name)
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ParameterTypeError(
            f"{name} must be a number or an array of numbers{_in(unit)}, got {value!r}"
        ) from exc
    if array.size and not np.all(np.isfinite(array)):
        raise ParameterError(f"{name} must be finite{_in(unit)}; it contains NaN or inf")
    if array.size and np.any(array < 0.0):
        raise ParameterError(
            f"{name} must be >= 0{_in(unit)}; smallest value is {float(array.min())!r}"
        )
    return array


def _in(unit: str) -> str:
    return f" (in {unit})" if unit else ""


def refuse_to_overwrite(paths: Iterable[Path], *, force: bool, option: str = "--out") -> None:
    """Raise OutputExistsError naming every path that exists, unless ``force``.

    ``option`` is the command-line option that chose those paths (named in the message).
    """
    existing = [str(path) for path in paths if path.exists()]
    if existing and not force:
        named = ", ".join(existing[:3])
        if len(existing) > 3:
            named += f" and {len(existing) - 3} more"
        raise OutputExistsError(
            f"will not overwrite {named}; choose another {option} or pass --force"
        )


#: Figure formats a ``--plot`` file may take (matplotlib picks the format from the suffix).
FIGURE_SUFFIXES = (".png", ".pdf", ".svg")


def figure_target(text: str, option: str, *, force: bool) -> Path:
    """Return the figure file ``text`` named by ``option``, checked before any work.

    It must end in one of :data:`FIGURE_SUFFIXES`, must not be a folder, and is not
    overwritten unless ``force``.
    """
    path = Path(text)
    if path.suffix.lower() not in FIGURE_SUFFIXES:
        raise ParameterError(
            f"{option} must end in {', '.join(FIGURE_SUFFIXES)}, got {path.name!r}; "
            f"e.g. {option} result.png"
        )
    if path.is_dir():
        raise ParameterError(
            f"{option} {path} is a folder; give a file name such as {path}/plot.png"
        )
    if path.exists() and not force:
        raise OutputExistsError(
            f"will not overwrite {path}; choose another {option} file or pass --force"
        )
    return path


def netcdf_target(text: str, command: str, *, force: bool, example: str = "") -> Path:
    """Return the netCDF ``--out`` file ``text`` of ``command``: a .nc name, not overwritten.

    ``example`` is the file name the message suggests (default ``{command}.nc``).
    """
    path = Path(text)
    if path.suffix.lower() != ".nc":
        raise ParameterError(
            f"--out {text}: {command} writes netCDF; name the file .nc, "
            f"e.g. {example or command + '.nc'}"
        )
    refuse_to_overwrite([path], force=force)
    return path


def refuse_file_as_folder(path: str | Path, option: str) -> None:
    """Raise ParameterError if the output folder ``path`` is, or lies under, a file.

    Checked before the work, so that it is not lost at the first write.
    """
    for folder in (Path(path), *Path(path).parents):
        if folder.exists():
            if not folder.is_dir():
                raise ParameterError(f"{option} {path}: {folder} is a file; give a folder")
            return
