"""Harmonic balance on masts of growing size: the cost per point against the unknowns (issue 25).

Run on demand:

    python benchmarks/bench_scale.py [--bays 5,10,20,40:30,80:10] [--points 100]
        [--save FILE.npz] [--compare FILE.npz] [--modes 40] [--pyharm PYTHON]
        [--json FILE.json] [--exact] [--plot FILE.png]

The issue's case: the planar mast of ``clearjoint.structure.mast`` (width and bay 0.5 m,
member rigidity 2e7 N, node mass 0.5 kg), a hinge ``ClearanceJoint(50e-6, 5e7,
gap_stiffness=1e5)`` in every longeron, Rayleigh beta 2e-6 s, 0.1 N at the tip (x), H = 7,
``points`` points at most (``--bays 40:30``: 30 at 40 bays) from 0.8 x the first open
mode to 1.2 x the first closed one, ``max_step=0.05``, ``check_points=0``. For each size
it prints the unknowns, the start
(the HB solve at the first frequency, ``harmonic.response._start``), the cost per point
of the rest of the curve, the share of it spent in the stability verdict and in the sparse
LU factorizations (scipy's ``splu``, wherever it is called), the peak resident memory so
far, then the growth exponent p of the cost per point ~ unknowns^p fitted (least squares
in log-log) over the sizes from 10 bays up.

``--json FILE`` writes the measured table (each size's row, the fitted exponent, the
command, the date and the load) to a JSON file: ``examples/bench_scale.json`` is the one
the gallery script ``examples/gallery/plot_harmonic_scale.py`` draws docs/harmonic.md's
growth plot from (rerun with ``--json examples/bench_scale.json`` to redraw it).

``--save`` writes every size's orbits (the harmonic coefficients), frequencies and
verdicts to an .npz file; ``--compare`` reads such a file (written by another source
tree, e.g. ``PYTHONPATH=/work/main/src python benchmarks/bench_scale.py --save old.npz``)
and prints the largest difference of the orbits (relative to the largest coefficient)
and the verdicts that differ. ``--exact`` also checks every point's verdict against the
exact monodromy's (``monodromy.multipliers``; slow at 40 bays and more). ``--modes B``
times the first nonlinear mode (EPMC) of the B-bay mast at 50 amplitudes (0.1 to 20 mm x
(B / 10)^2 at the tip; with ``--json`` its time, CPU time, converged count and sparse
LU calls go to the table's "modes"). ``--plot FILE.png`` draws the cost per point against
the unknowns (log-log) with the fitted exponent. ``--pyharm PYTHON`` runs pyHarm's SDOF comparison
(``bench_harmonic.py --pyharm PYTHON``, in its own interpreter) after the sizes.

BLAS runs on one thread unless ``OPENBLAS_NUM_THREADS`` says otherwise (the JSON's
"machine" says which); every timing is on a shared machine: the 1-minute load average is
printed beside it.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse
import math
import resource
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import scipy.sparse.linalg

from clearjoint import ClearanceJoint, ClearjointError
from clearjoint.harmonic import frequency_response, nonlinear_modes
from clearjoint.harmonic import monodromy as _monodromy
from clearjoint.harmonic import response as _response
from clearjoint.structure import mast

SIZES = "5,10,20,40,80"
H = 7


def model(bays: int) -> Any:
    """The issue's mast with ``bays`` bays."""
    return mast(bays, joints=ClearanceJoint(50e-6, 5e7, gap_stiffness=1e5), rayleigh=(0.0, 2e-6))


def tip_force(structure: Any, bays: int, newtons: float) -> np.ndarray:
    """``newtons`` on the top right node's x (n{2 bays + 1}x, the tip), zero elsewhere."""
    names = list(structure.dof_names)
    force = np.zeros(structure.n_dof)
    force[names.index(f"n{2 * bays + 1}x")] = newtons
    return force


class Timers:
    """Time calls of module attributes (summed), put back by :meth:`restore`."""

    def __init__(self) -> None:
        self.spent: dict[str, float] = {}
        self.calls: dict[str, int] = {}
        self._originals: list[tuple[Any, str, Any]] = []

    def wrap(self, name: str, module: Any, attr: str) -> None:
        original = getattr(module, attr, None)
        if original is None:
            return
        self.spent.setdefault(name, 0.0)
        self.calls.setdefault(name, 0)
        depth = [0]

        def timed(*args: Any, **kwargs: Any) -> Any:
            depth[0] += 1
            started = time.perf_counter()
            try:
                return original(*args, **kwargs)
            finally:
                depth[0] -= 1
                if depth[0] == 0:  # nested calls counted once
                    self.spent[name] += time.perf_counter() - started
                    self.calls[name] += 1

        setattr(module, attr, timed)
        self._originals.append((module, attr, original))

    def restore(self) -> None:
        for module, attr, original in reversed(self._originals):
            setattr(module, attr, original)
        self._originals.clear()


def verdict_functions() -> list[tuple[Any, str]]:
    """Where the stability verdict is computed (whichever of these the source tree has)."""
    found: list[tuple[Any, str]] = [(_response, "_verdicts")]
    if not hasattr(_response, "_verdicts"):
        found = [(_monodromy, "multipliers")]
    return found


def run_size(bays: int, points: int, exact: bool) -> dict[str, Any]:
    """One curve of the issue's case, timed; its numbers as a dict."""
    structure = model(bays)
    f_open = float(structure.modes("open").omega[0])
    f_closed = float(structure.modes("closed").omega[0])
    unknowns = (2 * H + 1) * structure.n_dof
    timers = Timers()
    timers.wrap("start", _response, "_start")
    for module, attr in verdict_functions():
        timers.wrap("verdict", module, attr)
    timers.wrap("splu", scipy.sparse.linalg, "splu")
    load = os.getloadavg()[0]
    started = time.perf_counter()
    cpu = time.process_time()
    try:
        fr = frequency_response(
            structure,
            tip_force(structure, bays, 0.1),
            0.8 * f_open,
            1.2 * f_closed,
            harmonics=H,
            max_points=points,
            max_step=0.05,
            check_points=0,
        )
    finally:
        timers.restore()
    took = time.perf_counter() - started
    cpu = time.process_time() - cpu
    start = timers.spent["start"]
    n = fr.omega.size
    rest = took - start
    # the start's own splu calls are part of the start, not of the points
    per_point = rest / max(n - 1, 1)
    out = {
        "bays": bays,
        "unknowns": unknowns,
        "points": n,
        "total": took,
        "cpu": cpu,
        "start": start,
        "per_point": per_point,
        "verdict": timers.spent.get("verdict", 0.0),
        "splu": timers.spent.get("splu", 0.0),
        "splu_calls": timers.calls.get("splu", 0),
        "rss_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
        "load": load,
        "omega": fr.omega,
        "coefficients": fr.coefficients,
        "stable": fr.stable,
        "reason": fr.stop_reason,
    }
    if exact:
        coef = fr.coefficients
        system = _system(structure)
        basis = _basis(fr)
        verdicts = np.array(
            [
                float(np.max(np.abs(_monodromy.multipliers(system, basis, coef[i], fr.omega[i]))))
                < 1.0
                for i in range(n)
            ]
        )
        out["exact_disagree"] = int(np.sum(verdicts != fr.stable))
    return out


def _system(structure: Any) -> Any:
    from clearjoint.harmonic.system import build

    return build(structure, None, 1.0)  # no friction: the speed is unused


def _basis(fr: Any) -> Any:
    from clearjoint.harmonic.aft import Basis

    return Basis.make(fr.settings["harmonics"], fr.settings["samples"])


def report(row: dict[str, Any]) -> None:
    """Print one size's line."""
    n = row["points"]
    verdict_share = row["verdict"] / max(row["total"] - row["start"], 1e-12)
    print(
        f"{row['bays']:3d} bays, {row['unknowns']:5d} unknowns: {n} points in "
        f"{row['total']:7.1f} s ({row['cpu']:.1f} s CPU); start {row['start']:6.2f} s; per point "
        f"{row['per_point']:.4f} s, of which the stability verdict {100 * verdict_share:4.1f} % "
        f"({row['verdict'] / n * 1e3:.1f} ms a point), splu {row['splu_calls']} calls "
        f"{row['splu']:.1f} s (start included); {int(np.sum(~row['stable']))} unstable; "
        f"peak RSS {row['rss_mib']:.0f} MiB; load {row['load']:.2f}; stop: {row['reason']}"
        + (
            f"; verdicts differing from the exact monodromy: {row['exact_disagree']}"
            if "exact_disagree" in row
            else ""
        ),
        flush=True,
    )


def fit(rows: list[dict[str, Any]], key: str) -> float:
    """Least-squares slope of log(row[key]) against log(unknowns)."""
    x = np.log([r["unknowns"] for r in rows])
    y = np.log([max(r[key], 1e-12) for r in rows])
    return float(np.polyfit(x, y, 1)[0])


def fitted_exponent(rows: list[dict[str, Any]]) -> float:
    """:func:`fit` of the cost per point, NaN with fewer than two sizes."""
    return fit(rows, "per_point") if len(rows) >= 2 else math.nan


def compare(rows: list[dict[str, Any]], path: str) -> None:
    """Print how far each size's orbits and verdicts are from those saved in ``path``."""
    old = np.load(path)
    for row in rows:
        b = row["bays"]
        if f"coef_{b}" not in old:
            print(f"{b:3d} bays: not in {path}")
            continue
        a_old, a_new = old[f"coef_{b}"], row["coefficients"]
        m = min(a_old.shape[0], a_new.shape[0])
        peak = float(np.max(np.abs(a_old)))
        diff = float(np.max(np.abs(a_old[:m] - a_new[:m]))) / peak
        dw = float(np.max(np.abs(old[f"omega_{b}"][:m] - row["omega"][:m])))
        verdicts = int(np.sum(old[f"stable_{b}"][:m] != row["stable"][:m]))
        each = np.max(np.abs(a_old[:m] - a_new[:m]).reshape(m, -1), axis=1) / peak
        apart = np.flatnonzero(each > 1e-8)
        first = f"first point beyond 1e-8: {apart[0]}" if apart.size else "all within 1e-8"
        print(
            f"{b:3d} bays: {m} points compared ({a_old.shape[0]} old, {a_new.shape[0]} new): "
            f"orbits differ by {diff:.2e} of the largest coefficient, omega by {dw:.2e} rad/s, "
            f"{verdicts} verdicts differ; {first}"
        )
        if apart.size:
            on, gap, nearest = on_old_curve(b, a_old, row, apart)
            other = int(np.sum(old[f"stable_{b}"][nearest] != row["stable"][apart]))
            print(
                f"          the {apart.size} points beyond 1e-8: the nearest old orbit is "
                f"{np.median(gap):.1e} (median), {np.max(gap):.1e} (largest) of the largest "
                f"coefficient away, and for {on} of them it solves HB at the new point's "
                f"frequency to the curve's tolerance, as the new orbit does (the two are one "
                f"solution to that tolerance); {other} verdicts differ from the nearest old "
                f"orbit's"
            )


def on_old_curve(
    bays: int, old: np.ndarray, row: dict[str, Any], points: np.ndarray
) -> tuple[int, np.ndarray, np.ndarray]:
    """For each of the new curve's ``points``: its distance to the nearest old orbit
    (relative to the largest coefficient), and whether that old orbit solves harmonic
    balance at the new point's frequency to the curve's tolerance (max abs(R) / k_ref at
    most ``solve.TOLERANCE`` times the continuation's ``u_scale``, as
    ``frequency_response`` accepts a point: max(scale_length / 2, max abs of the curve's
    start), one scale for the whole curve, not each orbit's own size): the count of those,
    the distances, and the nearest old points' indices."""
    from clearjoint.harmonic import aft, response, solve

    structure = model(bays)
    system = _system(structure)
    basis = aft.Basis.make(*aft.check_harmonics(H, None))
    force = tip_force(structure, bays, 0.1)
    k_ref = system.reference_stiffness
    start = np.asarray(row["coefficients"][0]).reshape(-1)
    scale = max(0.5 * response.scale_length(system), float(np.max(np.abs(start))))
    peak = float(np.max(np.abs(old)))
    flat_old = old.reshape(old.shape[0], -1)
    on, gaps, index = 0, [], []
    for i in points:
        new = np.asarray(row["coefficients"][i]).reshape(-1)
        distance = np.max(np.abs(flat_old - new), axis=1)
        gaps.append(float(np.min(distance)) / peak)
        index.append(int(np.argmin(distance)))
        nearest = flat_old[index[-1]]
        ev = aft.evaluate(system, basis, nearest, float(row["omega"][i]), force, jacobian=False)
        size = float(np.max(np.abs(ev.residual))) / k_ref
        if size <= solve.TOLERANCE * scale:
            on += 1
    return on, np.asarray(gaps), np.asarray(index)


def modes(bays: int) -> dict[str, Any]:
    """Time the first nonlinear mode of the ``bays``-bay mast at 50 amplitudes; its numbers."""
    structure = model(bays)
    amplitudes = np.geomspace(1e-4, 2e-2, 50) * (bays / 10) ** 2
    load = os.getloadavg()[0]
    started = time.perf_counter()
    cpu = time.process_time()
    timers = Timers()
    timers.wrap("splu", scipy.sparse.linalg, "splu")
    try:
        nm = nonlinear_modes(structure, 1, amplitudes, harmonics=H)
    finally:
        timers.restore()
    took = time.perf_counter() - started
    cpu = time.process_time() - cpu
    f = nm.frequency[nm.converged] / (2 * math.pi)
    span = f"{f.min():.3f} to {f.max():.3f} Hz" if f.size else "none"
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    print(
        f"first nonlinear mode (EPMC), {bays} bays, {(2 * H + 1) * structure.n_dof} unknowns: "
        f"50 amplitudes in {took:.1f} s ({cpu:.1f} s CPU), {int(nm.converged.sum())}/50 "
        f"converged, {span}; splu {timers.calls['splu']} calls {timers.spent['splu']:.1f} s; "
        f"peak RSS {rss:.0f} MiB; load {load:.2f}",
        flush=True,
    )
    return {
        "bays": bays,
        "unknowns": (2 * H + 1) * structure.n_dof,
        "amplitudes": int(amplitudes.size),
        "amplitude_range_m": [float(amplitudes[0]), float(amplitudes[-1])],
        "total": took,
        "cpu": cpu,
        "converged": int(nm.converged.sum()),
        "frequency_hz": [float(f.min()), float(f.max())] if f.size else None,
        "splu": timers.spent["splu"],
        "splu_calls": timers.calls["splu"],
        "rss_mib": rss,
        "load": load,
        "note": nm.note,
    }


def plot(rows: list[dict[str, Any]], exponent: float, path: str) -> None:
    """Cost per point against unknowns, log-log, with the fitted power law."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    x = np.array([r["unknowns"] for r in rows], dtype=float)
    y = np.array([r["per_point"] for r in rows])
    v = np.array([r["verdict"] / r["points"] for r in rows])
    fig, ax = plt.subplots(figsize=(5.5, 4))
    ax.loglog(x, y, "o-", label="cost per point")
    ax.loglog(x, np.maximum(v, 1e-6), "s--", label="of which the stability verdict")
    c = np.polyfit(np.log(x), np.log(y), 1)  # the same fit as ``exponent``
    ax.loglog(x, np.exp(np.polyval(c, np.log(x))), ":", label=f"fit ~ unknowns^{exponent:.2f}")
    ax.set_xlabel("unknowns (2H + 1) N")
    ax.set_ylabel("s")
    ax.set_title("Harmonic balance on the mast, H = 7 (cost per curve point)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    print(f"plot written to {path}")


#: The scalar numbers of a size's row that go to the JSON table (all SI: s, MiB).
TABLE_KEYS = (
    "bays",
    "unknowns",
    "points",
    "total",
    "cpu",
    "start",
    "per_point",
    "verdict",
    "splu",
    "splu_calls",
    "rss_mib",
    "load",
    "reason",
    "exact_disagree",
)


def blas_threads() -> str:
    """What BLAS ran on: its threads as threadpoolctl reads them, and the environment's
    setting (``OPENBLAS_NUM_THREADS``, one unless the caller set it)."""
    from threadpoolctl import threadpool_info

    counts = sorted({int(p["num_threads"]) for p in threadpool_info() if p["user_api"] == "blas"})
    setting = os.environ.get("OPENBLAS_NUM_THREADS")
    return f"BLAS on {'/'.join(map(str, counts)) or '?'} thread(s) (OPENBLAS_NUM_THREADS={setting})"


def write_json(
    path: str,
    rows: list[dict[str, Any]],
    failed: list[dict[str, Any]],
    fitted: list[dict[str, Any]],
    exponent: float,
    started: str,
    mode: dict[str, Any] | None = None,
) -> None:
    """The measured table as JSON: one object per size (``TABLE_KEYS``, plus the verdict's
    time per point and share, the unstable points), the sizes without a curve, the fit,
    and the nonlinear mode's timing (``--modes``) under "modes"."""
    import json

    table = []
    for r in rows:
        row = {k: r[k] for k in TABLE_KEYS if k in r}
        for k, v in row.items():
            row[k] = v if isinstance(v, str) else float(v) if isinstance(v, float) else int(v)
        row["verdict_per_point"] = r["verdict"] / max(r["points"], 1)
        row["verdict_share"] = r["verdict"] / max(r["total"] - r["start"], 1e-12)
        row["unstable"] = int(np.sum(~r["stable"]))
        table.append(row)
    out = {
        "what": "harmonic balance on the issue-25 mast: cost per curve point against unknowns",
        "command": "python " + " ".join(sys.argv),
        "date": started,
        "source": str(Path(_response.__file__).parents[2]),
        "harmonics": H,
        "machine": f"{os.cpu_count()} cores shared with other sessions; {blas_threads()}",
        "sizes": table,
        "no_curve": failed,
        "fit": {
            "exponent": None if math.isnan(exponent) else exponent,
            "bays": [r["bays"] for r in fitted],
            "of": "per_point ~ unknowns^exponent, least squares in log-log",
        },
    }
    if mode is not None:
        out["modes"] = mode
    Path(path).write_text(json.dumps(out, indent=1) + "\n")
    print(f"table written to {path}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--bays", default=SIZES, help=f"comma-separated sizes, BAYS or BAYS:POINTS ({SIZES})"
    )
    parser.add_argument("--points", type=int, default=100, help="points per curve (100)")
    parser.add_argument("--save", help="write the orbits and verdicts to this .npz")
    parser.add_argument("--compare", help="compare with the orbits in this .npz")
    parser.add_argument("--exact", action="store_true", help="check verdicts by the monodromy")
    parser.add_argument("--modes", type=int, default=0, help="time EPMC at this many bays")
    parser.add_argument("--plot", help="write the growth plot to this .png")
    parser.add_argument("--pyharm", help="pyHarm's interpreter: run bench_harmonic --pyharm")
    parser.add_argument("--json", help="write the measured table to this .json")
    args = parser.parse_args()
    started = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    failed: list[dict[str, Any]] = []
    sizes = [tuple(int(v) for v in b.split(":")) for b in args.bays.split(",") if b]
    print(
        f"mast, H = {H}, 0.1 N at the tip, {args.points} points from 0.8 x open to 1.2 x closed "
        f"first mode, max_step 0.05, check_points 0; clearjoint from "
        f"{Path(_response.__file__).parents[2]}; load {os.getloadavg()[0]:.2f}",
        flush=True,
    )
    rows = []
    for bays, *cap in sizes:
        try:
            row = run_size(bays, min(args.points, *cap) if cap else args.points, args.exact)
        except ClearjointError as error:  # e.g. no start found: say so, go on
            print(f"{bays:3d} bays: no curve: {error}", flush=True)
            failed.append({"bays": bays, "error": str(error)})
            if args.json:
                done = [r for r in rows if r["bays"] >= 10] if len(rows) > 2 else rows
                write_json(args.json, rows, failed, done, fitted_exponent(done), started)
            continue
        report(row)
        rows.append(row)
        if args.json:  # after each size: a long run stopped later keeps what it measured
            done = [r for r in rows if r["bays"] >= 10] if len(rows) > 2 else rows
            write_json(args.json, rows, failed, done, fitted_exponent(done), started)
    fitted = [r for r in rows if r["bays"] >= 10] if len(rows) > 2 else rows
    p = fitted_exponent(fitted)
    if len(fitted) >= 2:
        first, last = fitted[0], fitted[-1]
        print(
            f"cost per point ~ unknowns^{p:.2f} ({first['unknowns']} to {last['unknowns']} "
            f"unknowns: x{last['per_point'] / first['per_point']:.1f} for "
            f"x{last['unknowns'] / first['unknowns']:.0f} unknowns)"
        )
        if args.plot:
            plot(fitted, p, args.plot)
    mode = modes(args.modes) if args.modes else None
    if args.json:
        write_json(args.json, rows, failed, fitted, p, started, mode)
    if args.save:
        arrays: dict[str, Any] = {}
        for r in rows:
            b = r["bays"]
            arrays[f"coef_{b}"] = r["coefficients"]
            arrays[f"omega_{b}"] = r["omega"]
            arrays[f"stable_{b}"] = r["stable"]
        np.savez_compressed(args.save, **arrays)
        print(f"orbits written to {args.save}")
    if args.compare:
        compare(rows, args.compare)
    if args.pyharm:
        here = Path(__file__).resolve().parent / "bench_harmonic.py"
        subprocess.run([sys.executable, str(here), "--pyharm", args.pyharm], check=False)


if __name__ == "__main__":
    main()
