"""
The tolerance study of a 10-bay mast
====================================

The 10-bay deployable mast of ``examples/mast.toml`` has a hinge joint with clearance
in each of its 20 longerons. Manufacturing scatters each clearance on its own, here as
normal(0.1 mm, 0.02 mm) truncated at 0: how do the first mode's frequency and damping
ratio scatter? The sweep ``examples/mast_tolerance_sweep.toml`` draws the 20 clearances
of each of 1000 masts and solves the first nonlinear mode (EPMC by harmonic balance,
clearjoint.harmonic, H = 3) at two modal amplitudes, 10 mm and 30 mm at the tip.

This script does not run the 1000 samples (50 minutes on two cores shared with other
jobs): it draws the histograms from ``examples/mast_tolerance_sweep.nc``, which
these two commands, run from the repository's root, wrote::

    clearjoint sweep examples/mast_tolerance_sweep.toml --out mast_tolerance.zarr --workers 2
    python -c "from clearjoint.sweep import open_sweep; open_sweep('mast_tolerance.zarr').to_netcdf('examples/mast_tolerance_sweep.nc', engine='h5netcdf')"

(stopped midway, the first command finishes with ``--resume``).
"""

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import xarray as xr

DOCS_FIGURES = {}  # figures of the docs this script draws, by file name in docs/figures/
EXAMPLES = Path("..")  # the gallery runs from examples/gallery/

results = xr.load_dataset(EXAMPLES / "mast_tolerance_sweep.nc", engine="h5netcdf")
amplitudes = results["task.amplitude"].values
print(
    f"{results.sizes['sample']} masts x {amplitudes.size} amplitudes, "
    f"{results.attrs['points_failed']} points failed, {results.attrs['points_missing']} "
    "not computed"
)

fig, axes = plt.subplots(2, amplitudes.size, figsize=(10.5, 6.6), layout="constrained")
for column, amplitude in enumerate(amplitudes):
    at = results.sel({"task.amplitude": amplitude})
    for row, (name, label, scale) in enumerate(
        [
            ("frequency_hz", "first mode's frequency (Hz)", 1.0),
            # H = 3 and the damping ratio still rises with H: a lower bound (docs/sweep.md)
            ("damping_ratio", "damping ratio (x 1e-3), H = 3: not converged in H", 1e3),
        ]
    ):
        values = at[name].values[np.isfinite(at[name].values)] * scale
        ax = axes[row, column]
        ax.hist(values, bins=40, color="C0" if row == 0 else "C3")
        ax.set_xlabel(label)
        ax.set_ylabel("masts")
        ax.set_title(
            f"tip amplitude {amplitude * 1e3:.0f} mm: mean {values.mean():.4g}, "
            f"std {values.std(ddof=1):.2g} ({values.size} masts)",
            fontsize=9,
        )
fig.suptitle(
    "10-bay mast, 20 clearances each from normal(0.1 mm, 0.02 mm) truncated at 0; "
    "first nonlinear mode by harmonic balance, H = 3",
    fontsize=10,
)
DOCS_FIGURES["sweep_mast_tolerance_histograms.png"] = fig

# %%
# What the scatter follows: the frequency at 10 mm against the mean clearance of the
# two lowest joints (bay 1, where the bending moment is largest), and of all 20.
clearance = results["joint.clearance"].values * 1e3  # (sample, joint), mm
low = results.sel({"task.amplitude": amplitudes[0]}).frequency_hz.values
fig, axes = plt.subplots(1, 2, figsize=(10.5, 3.8), layout="constrained", sharey=True)
for ax, (x, label) in zip(
    axes,
    [
        (clearance[:, :2].mean(axis=1), "mean clearance of the 2 joints of bay 1 (mm)"),
        (clearance.mean(axis=1), "mean clearance of all 20 joints (mm)"),
    ],
    strict=True,
):
    good = np.isfinite(low)
    r = np.corrcoef(x[good], low[good])[0, 1]
    ax.plot(x, low, ".", markersize=3)
    ax.set_xlabel(label)
    ax.set_title(f"correlation {r:.2f}", fontsize=9)
axes[0].set_ylabel(f"frequency at {amplitudes[0] * 1e3:.0f} mm (Hz)")
DOCS_FIGURES["sweep_mast_tolerance_clearance.png"] = fig
