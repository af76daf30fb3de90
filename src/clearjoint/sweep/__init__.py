"""Parameter studies and tolerance Monte Carlo from a sweep file, on Dask.

A sweep runs one task (:data:`TASKS`: the steady state of the forced joint, its energies
per cycle of MODEL.md eq 10-18, its free-cycle modal properties of eq 5-9, a
stepped-sine frequency-response curve, a virtual-rig test, the identification of a
record set, a nonlinear mode of a structure whose joints are drawn one by one) over a
grid of parameter values and/or Monte Carlo draws, in chunks of pure tasks on a
dask.distributed cluster (clearjoint.parallel), writing a zarr store as chunks finish.
The file format is in :mod:`clearjoint.sweep.file`.

>>> from clearjoint.sweep import Sweep, run_sweep
>>> sweep = Sweep.from_toml("examples/sweep.toml")  # doctest: +SKIP
>>> results = run_sweep(sweep, out="results.zarr")  # doctest: +SKIP
"""

from __future__ import annotations

from clearjoint.sweep.file import Axis, Draw, Sweep, SweepError
from clearjoint.sweep.run import SERIAL, open_sweep, run_sweep
from clearjoint.sweep.tasks import TASKS, Parameter, Task, register_task

__all__ = [
    "SERIAL",
    "TASKS",
    "Axis",
    "Draw",
    "Parameter",
    "Sweep",
    "SweepError",
    "Task",
    "open_sweep",
    "register_task",
    "run_sweep",
]
