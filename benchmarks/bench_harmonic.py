"""Harmonic balance with continuation against pyHarm on pyHarm's SDOF clearance case.

Run on demand:

    python benchmarks/bench_harmonic.py [--pyharm /work/venv-pyharm/bin/python]

The case (issue 10): m = 1, c_v = 0.05, k0 = 1, gap edges at +-0.1745, contact adds
3, F0 = 0.03, omega from 0.05 to 1.8, H = 12 harmonics. Both codes follow the whole
curve (both stable branches and the unstable one) by arclength continuation; each is
timed four times in its own interpreter, and the best of the last three (warm) calls
is compared. pyHarm is
not installed in the project's environment: give its interpreter with --pyharm.
BLAS runs on one thread in both (OPENBLAS_NUM_THREADS=1), since the machine's cores
are shared and threaded BLAS on 25 x 25 matrices only adds waiting.

It also prints the peak, both folds, and how the time grows with H.

    python benchmarks/bench_harmonic.py --issue --pyharm /work/venv-pyharm/bin/python

runs the issue's whole speed section in one run (docs/harmonic.md, "Speed"): pyHarm's
case and its ratio, then the example mast's 300-point curve and 50-amplitude first mode
at 10 bays, H = 7, and the same for 5, 20, 40 bays (H = 7) and H = 3, 15 (10 bays), each
curve's stop reason said; the 40-bay curve is capped at 20 points (ISSUE_SIZES), with
the time 300 would take. ``--old-src OLD/src [--old-bays 10]`` times a mast curve with another src
tree and this one in turn (a before/after ratio in one run).

    python benchmarks/bench_harmonic.py --monodromy [5:300,10:300,20:300,40:12]

times the exact monodromy of every HB orbit of each mast's curve (BAYS:POINTS) by the
plain product of scipy.linalg.expm and by the cached eigen-decompositions (the default
route, harmonic/monodromy.py "Speed"), side by side on the same orbits, and prints how
far apart they are beside how far expm on the balanced matrices is from expm.
``--mast-sizes 5:7,10:7,20:7,40:7 --curves-only`` gives the growth of a whole curve with
the bays without the nonlinear modes (which the monodromy does not touch).

    python benchmarks/bench_harmonic.py --mast [--mast-points 300]

times the planar mast (clearjoint.structure.mast, hinge joints ClearanceJoint(1e-4, 1e8,
gap_stiffness=1e6) in every longeron, Rayleigh beta 2e-6 s): the first nonlinear mode
at 50 amplitudes (0.1 to 20 mm on the tip) for 5, 10, 20 and 40 bays at H = 7 and for
H = 3, 7, 15 at 10 bays; the frequency response of the 10-bay mast (tip force 2 N,
from the open to past the closed first mode) for --mast-points points, and the cost
per point of the frequency response (continuation and Hill's eigenproblem timed apart,
on a 10-point stretch) against the bays and H.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse
import json
import math
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from clearjoint import ClearjointError, Joint, Losses
from clearjoint.harmonic import frequency_response

JOINT = Joint(mass=1.0, clearance=2 * 0.1745, compression_stiffness=3.0, gap_stiffness=1.0)
ZETA = 0.05 / (2.0 * math.sqrt(3.0))  # c_v = 2 zeta sqrt(m k_c) = 0.05
H = 12
#: pyHarm's continuation settings, as in benchmarks/bench_periodic.py: its documented tangent
#: predictor, arc-length corrector and "acceptance" step sizer with ds_max = 0.01. With ds_max
#: 0.05 its predictor turns back and forth between 1.09 and 1.14 rad/s after the upper fold
#: without end (the sign of det J flips on the sampled law's kinks); with 0.01 it follows
#: the whole curve, 326 points (docs/harmonic.md, "Speed"). Give up after this many s.
PYHARM_TIMEOUT = 240

PYHARM_SCRIPT = """
import json, sys, time
import numpy as np
import pyHarm
from pyHarm.DynamicOperator import compute_DFT

def problem():
    return {
        "analysis": {"frf": {"study": "frf", "puls_inf": 0.05, "puls_start": 0.05,
                             "puls_sup": 1.8, "ds0": 1e-2, "ds_min": 1e-4, "ds_max": 0.01,
                             "sign_ds": 1, "verbose": False, "stepsizer": "acceptance",
                             "predictor": "tangent", "corrector": "arc_length",
                             "stopper": "bounds", "solver": "NewtonRaphson"}},
        "system": {"type": "Base", "nh": %(h)d, "nti": 512},
        "substructures": {"sdof": {"type": "substructure", "ndofs": 1, "matrix": {
            "M": np.array([[1.0]]), "K": np.array([[1.0]]), "C": np.array([[0.05]])}}},
        "connectors": {
            "gap": {"connect": {"sdof": [0]}, "dirs": [0], "type": "PenaltyBilateralGap",
                    "g": 0.1745, "k": 3.0},
            "force": {"connect": {"sdof": [0]}, "dirs": [0], "type": "SinusForcing",
                      "amp": 0.03},
        },
    }

times = []
for _ in range(%(repeats)d):
    t = time.perf_counter(); m = pyHarm.Maestro(problem()); m.operate()
    times.append(time.perf_counter() - t)
sols = [s for s in m.nls["frf"].SolList if s.flag_accepted]
idx = m.getIndex("sdof", 0, 0)
dft = compute_DFT(m.system.nti, m.system.nh)
om = np.array([s.x[-1] for s in sols])
xt = np.array([s.x[idx] @ dft["ft"] for s in sols])
print(json.dumps({"first_s": times[0], "best_s": min(times[1:]), "points": len(sols),
                  "omega": om.tolist(), "amplitude": ((xt.max(1) - xt.min(1)) / 2).tolist()}))
"""


#: Each code runs this many times in its interpreter: the first call (imports, compiled-code
#: cache) is reported apart, the best of the others is compared (the machine is shared).
REPEATS = 4

#: Largest arclength step on pyHarm's case: 330 points, the issue asks for 326 or more.
PYHARM_MAX_STEP = 0.024


def ours(harmonics: int, samples: int | None, max_step: float) -> tuple[float, float, object]:
    times = []
    curve = None
    for _ in range(REPEATS):
        start = time.perf_counter()
        curve = frequency_response(
            JOINT,
            0.03,
            0.05,
            1.8,
            harmonics=harmonics,
            samples=samples,
            losses=Losses(damping_ratio=ZETA),
            max_step=max_step,
        )
        times.append(time.perf_counter() - start)
    return times[0], min(times[1:]), curve


def pyharm(python: str, harmonics: int) -> dict[str, object]:
    with tempfile.TemporaryDirectory() as folder:
        script = Path(folder) / "pyharm_case.py"
        script.write_text(PYHARM_SCRIPT % {"h": harmonics, "repeats": REPEATS})
        try:
            done = subprocess.run(
                [python, str(script)],
                capture_output=True,
                text=True,
                check=True,
                cwd=folder,
                timeout=PYHARM_TIMEOUT,
            )
        except subprocess.TimeoutExpired:
            return {}
    result: dict[str, object] = json.loads(done.stdout.strip().splitlines()[-1])
    return result


def describe(name: str, omega: np.ndarray, amplitude: np.ndarray) -> str:
    i = int(np.argmax(amplitude))
    return f"{name}: peak X = {amplitude[i]:.4f} at omega = {omega[i]:.4f} rad/s"


def mast_model(bays: int) -> object:
    from clearjoint import ClearanceJoint
    from clearjoint.structure import mast

    return mast(bays, joints=ClearanceJoint(1e-4, 1e8, gap_stiffness=1e6), rayleigh=(0, 2e-6))


def mast_benchmarks(points: int) -> None:
    """The mast timings (see the module docstring)."""
    from clearjoint.harmonic import aft, nonlinear_modes
    from clearjoint.harmonic.system import from_structure

    amplitudes = np.geomspace(1e-4, 2e-2, 50)
    print("mast, first nonlinear mode (EPMC), 50 amplitudes 0.1 to 20 mm:")
    for bays, h in ((5, 7), (10, 7), (20, 7), (40, 7), (10, 3), (10, 15)):
        s = mast_model(bays)
        start = time.perf_counter()
        nm = nonlinear_modes(s, 1, amplitudes, harmonics=h)
        took = time.perf_counter() - start
        f = nm.frequency[nm.converged] / (2 * math.pi)
        print(
            f"  {bays:2d} bays ({s.n_dof} DOF, {(2 * h + 1) * s.n_dof} unknowns), H = {h:2d}: "  # type: ignore[attr-defined]
            f"{took:7.2f} s, {int(nm.converged.sum())}/50 converged, {f.min():.3f} to "
            f"{f.max():.3f} Hz"
        )
    print("mast frequency response, cost per point (10-point stretch near the open mode):")
    for bays, h in ((5, 7), (10, 7), (20, 7), (10, 3), (10, 15)):
        s = mast_model(bays)
        force = np.zeros(s.n_dof)  # type: ignore[attr-defined]
        force[-2] = 2.0  # the tip node, along x
        f_open = float(s.modes("open").omega[0])  # type: ignore[attr-defined]
        start = time.perf_counter()
        fr = frequency_response(s, force, 0.8 * f_open, 2.0 * f_open, harmonics=h, max_points=10)
        took = time.perf_counter() - start
        model = from_structure(s)
        basis = aft.Basis.make(h, 1 << math.ceil(math.log2(32 * (2 * h + 1))))
        q = fr.coefficients[-1].ravel()  # type: ignore[union-attr]
        w = float(fr.omega[-1])
        ev = aft.evaluate(model, basis, q, w, force)
        start = time.perf_counter()
        aft.hill_exponents(model, basis, ev.jacobian, w)
        hill = time.perf_counter() - start
        print(
            f"  {bays:2d} bays, H = {h:2d}: {took / fr.omega.size:.3f} s per point "
            f"({fr.omega.size} points), of which Hill's eigenproblem {hill:.3f} s"
        )
    example_mast_curve(points)


#: The example mast's curve: from below its open first mode to past its closed one, with
#: the study's force pattern scaled to 0.1 N (at the study's 20 N the H = 7 orbits near
#: the first mode are violently unstable, docs/harmonic.md).
MAST_FROM_HZ, MAST_TO_HZ, MAST_MAX_STEP, MAST_FORCE_N = 0.9, 20.0, 0.05, 0.1


def example_mast_curve(points: int) -> None:
    """The frequency response of examples/mast.toml around its first mode, H = 7, timed."""
    from clearjoint.harmonic import aft, monodromy
    from clearjoint.harmonic.system import from_structure
    from clearjoint.structure.study import load_structure_study

    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    study = load_structure_study(os.path.join(root, "examples", "mast.toml"))
    s = study.structure
    force = study.force * (MAST_FORCE_N / float(np.max(np.abs(study.force))))
    modes = (float(s.modes(p).omega[0]) / (2 * math.pi) for p in ("open", "closed"))
    print(
        f"examples/mast.toml ({s.n_dof} DOF, {len(s.joint_laws)} joints, first mode open "
        f"{next(modes):.3f} Hz, closed {next(modes):.3f} Hz), force "
        f"{MAST_FORCE_N} N at its [excitation] DOF, H = 7, "
        f"{MAST_FROM_HZ} to {MAST_TO_HZ} Hz, max_step {MAST_MAX_STEP}, {points} points at most:"
    )
    start = time.perf_counter()
    fr = _example_curve(s, force, points)
    took = time.perf_counter() - start
    hz = fr.omega / (2 * math.pi)
    peak = int(np.argmax(np.max(fr.amplitude, axis=1)))
    print(
        f"  {fr.omega.size} points in {took:.1f} s ({took / fr.omega.size:.3f} s per point), "
        f"{hz.min():.3f} to {hz.max():.3f} Hz, stop: {fr.stop_reason}"
    )
    print(
        f"  largest amplitude {1e3 * np.max(fr.amplitude[peak]):.3f} mm at {hz[peak]:.3f} Hz; "
        f"{int(np.sum(fr.stable))} stable, {int(np.sum(~fr.stable))} unstable points"
    )
    for e in fr.events:
        print(f"  {e.kind}: {e.omega / (2 * math.pi):.4f} Hz, {1e3 * e.amplitude:.4f} mm")
    model = from_structure(s)
    basis = aft.Basis.make(7, int(fr.settings["samples"]))
    coef, w = fr.coefficients[peak], float(fr.omega[peak])  # type: ignore[index]
    ev = aft.evaluate(model, basis, coef.ravel(), w, force)
    start = time.perf_counter()
    monodromy.multipliers(model, basis, coef, w)
    mono = time.perf_counter() - start
    start = time.perf_counter()
    aft.hill_exponents(model, basis, ev.jacobian, w)
    hill = time.perf_counter() - start
    # the verdicts against the exact motion: 30 periods of structure.time_response from the
    # HB state of the first stable point and of the most unstable one
    from clearjoint.structure import time_response

    n = s.n_dof
    dof = int(np.argmax(np.abs(force)))
    for verdict in (True, False):
        picks = np.flatnonzero(fr.stable == verdict)
        if picks.size == 0:
            continue
        largest = np.max(np.abs(fr.multipliers[picks]), axis=1)
        i = int(picks[0]) if verdict else int(picks[np.argmax(largest)])
        x0 = fr.initial_state[i]
        w_i = float(fr.omega[i])
        motion = time_response(
            s, force, w_i, 30 * 2 * math.pi / w_i, initial=(x0[:n], x0[n:]), samples_per_period=64
        )
        peaks = motion.u[: 30 * 64, dof].reshape(30, 64).max(axis=1)
        print(
            f"  {'stable' if verdict else 'unstable'} point at {w_i / (2 * math.pi):.4f} Hz "
            f"(largest multiplier {np.max(np.abs(fr.multipliers[i])):.3f}): HB tip maximum "
            f"{1e3 * fr.x_max[i, dof]:.4f} mm, exact motion from the HB state over 30 periods "
            f"{1e3 * peaks.min():.4f} to {1e3 * peaks.max():.4f} mm "
            f"(last 5 periods {1e3 * peaks[-5:].min():.4f} to {1e3 * peaks[-5:].max():.4f})"
        )
    print(
        f"  stability at the peak: exact monodromy {mono:.3f} s "
        f"({monodromy.crossings(model, basis, coef).size} gap-edge crossings), "
        f"Hill's dense eigenproblem (not used) {hill:.3f} s"
    )


def example_mast(bays: int) -> tuple[Any, np.ndarray]:
    """examples/mast.toml with ``bays`` bays, its force moved to the tip's x (n{2 bays + 1}x)."""
    from clearjoint.structure.study import load_structure_study

    root = Path(__file__).resolve().parents[1]
    text = (root / "examples" / "mast.toml").read_text()
    text = text.replace("bays = 10", f"bays = {bays}").replace(
        'force_dof = "n21x"', f'force_dof = "n{2 * bays + 1}x"'
    )
    text = text.replace('dof = "n21x"', f'dof = "n{2 * bays + 1}x"')
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "mast.toml"
        path.write_text(text)
        study = load_structure_study(path)
    assert study.force is not None
    return study.structure, study.force


#: The sizes of --mast-sizes: (bays, H).
MAST_SIZES = "5:7,10:7,20:7,40:7,10:3,10:15"


def _curve_lines(
    fr: Any,
    bays: int,
    h: int,
    s: Any,
    unknowns: int,
    took: float,
    points: int,
    asked: int,
    summary: list[str],
) -> float:
    """Print one mast curve's lines (--mast-sizes) and add its summary; its s a point."""
    f_open = float(s.modes("open").omega[0])
    f_closed = float(s.modes("closed").omega[0])
    hz = fr.omega / (2 * math.pi)
    per_point = took / fr.omega.size
    print(
        f"  {bays:2d} bays ({s.n_dof} DOF, {unknowns} unknowns), H = {h:2d}: curve "
        f"{fr.omega.size} points in {took:8.1f} s ({took / fr.omega.size:.3f} s/point), "
        f"{hz.min():.3f} to {hz.max():.3f} Hz (open {f_open / (2 * math.pi):.3f}, closed "
        f"{f_closed / (2 * math.pi):.3f}), {int(np.sum(~fr.stable))} unstable, "
        f"load {os.getloadavg()[0]:.2f}",
        flush=True,
    )
    ended = (
        f"all {points} points asked"
        if fr.omega.size == points
        else f"{fr.omega.size} of {points} points: {fr.stop_reason}"
    )
    if points < asked:
        ended += f", capped from {asked}"
    print(f"      curve stop: {fr.stop_reason} ({ended})", flush=True)
    summary.append(
        f"{bays:2d} bays, H = {h:2d}: curve {fr.omega.size} points {took:.1f} s "
        f"({took / fr.omega.size:.3f} s/point; {ended})"
    )
    return per_point


def _spent_in() -> Any:
    """Time the exact monodromy and the orbit check from now on; the returned function
    puts them back and says how long each took."""
    from clearjoint.harmonic import check, monodromy

    wrapped = {"monodromy": (monodromy, "multipliers"), "orbit check": (check, "check_orbits")}
    spent = dict.fromkeys(wrapped, 0.0)
    calls = dict.fromkeys(wrapped, 0)
    originals = {name: getattr(module, attr) for name, (module, attr) in wrapped.items()}

    def timer(name: str) -> Any:
        def timed(*args: Any, **kwargs: Any) -> Any:
            started = time.perf_counter()
            try:
                return originals[name](*args, **kwargs)
            finally:
                spent[name] += time.perf_counter() - started
                calls[name] += 1

        return timed

    for name, (module, attr) in wrapped.items():
        setattr(module, attr, timer(name))

    def report() -> str:
        for name, (module, attr) in wrapped.items():
            setattr(module, attr, originals[name])
        return ", ".join(f"{k} {spent[k]:.1f} s ({calls[k]} calls)" for k in wrapped)

    return report


def mast_sizes(sizes: str, points: int, force_n: float, modes: bool = True) -> list[str]:
    """The example mast's cost against bays and H: the frequency response (``points``
    points from 0.8 times the open first mode, the study's force pattern scaled to
    ``force_n`` at the tip) and the first nonlinear mode (50 amplitudes; not with
    ``modes=False``), one line each."""
    from clearjoint.harmonic import nonlinear_modes

    print(
        f"examples/mast.toml with other bay counts; force {force_n} N at the tip (x); "
        f"curves of {points} points at most from 0.8 x the open first mode, max_step "
        f"{MAST_MAX_STEP}; "
        + (
            "modes at 50 amplitudes 0.1 to 20 mm x (bays / 10)^2 at the tip"
            if modes
            else "no modes (--curves-only)"
        )
    )
    print(f"  load before: {os.getloadavg()[0]:.2f} (1-min average)")
    summary: list[str] = []
    for item in sizes.split(","):
        bays, h, *cap = (int(v) for v in item.split(":"))
        asked = points
        points = min(points, cap[0]) if cap else points
        s, pattern = example_mast(bays)
        force = pattern * (force_n / float(np.max(np.abs(pattern))))
        f_open = float(s.modes("open").omega[0])
        f_closed = float(s.modes("closed").omega[0])
        unknowns = (2 * h + 1) * s.n_dof
        spent = _spent_in() if not modes else None
        start = time.perf_counter()
        try:
            fr = frequency_response(
                s,
                force,
                0.8 * f_open,
                1.2 * f_closed,
                harmonics=h,
                max_points=points,
                max_step=MAST_MAX_STEP,
            )
        except ClearjointError as error:  # no start found (e.g. the start's budget): say so
            took = time.perf_counter() - start
            print(f"  {bays:2d} bays, H = {h:2d}: no curve after {took:.1f} s: {error}")
            summary.append(f"{bays:2d} bays, H = {h:2d}: no curve ({took:.1f} s): {error}")
            fr = None
        if fr is not None:
            took = time.perf_counter() - start
            per_point = _curve_lines(fr, bays, h, s, unknowns, took, points, asked, summary)
        if spent is not None:
            line = spent()
            print(f"      of which {line}", flush=True)
            summary[-1] += f"; of which {line}"
        if not modes:
            points = asked
            continue
        amplitudes = np.geomspace(1e-4, 2e-2, 50) * (bays / 10) ** 2
        start = time.perf_counter()
        nm = nonlinear_modes(s, 1, amplitudes, harmonics=h)
        took = time.perf_counter() - start
        f = nm.frequency[nm.converged] / (2 * math.pi)
        span = f"{f.min():.3f} to {f.max():.3f} Hz" if f.size else "none"
        print(
            f"  {bays:2d} bays, H = {h:2d}: mode, 50 amplitudes in {took:8.1f} s, "
            f"{int(nm.converged.sum())}/50 converged, {span}, load {os.getloadavg()[0]:.2f}",
            flush=True,
        )
        summary[-1] += f"; mode 50 amplitudes {took:.1f} s ({int(nm.converged.sum())} converged)"
        if points < asked and fr is not None:
            summary[-1] += (
                f"; capped at {points} of {asked} points: {asked} would take about "
                f"{asked * per_point / 60:.0f} min at its {per_point:.1f} s a point"
            )
        points = asked
    return summary


def mast_decay(bays: int, beta: float, cycles: int) -> None:
    """The example mast's first nonlinear mode (EPMC, H = 7) against its exact free decay.

    As tests/test_harmonic_structure.py does on 2 bays: released on the closed first
    mode at 2 mm x (bays / 2)^2 on the tip, ``cycles`` cycles of structure.free_decay read
    per cycle on closed mode 1 (decay_backbone), against EPMC at the same peak amplitude.
    """
    from clearjoint import ClearanceJoint
    from clearjoint.harmonic import nonlinear_modes
    from clearjoint.structure import decay_backbone, free_decay, mast

    j = ClearanceJoint(clearance=5e-5, compression_stiffness=5e7, gap_stiffness=1e5)
    s = mast(bays, joints=j, rayleigh=(0.0, beta))
    closed = s.modes("closed")
    phi = closed.shapes[:, 0]
    ref = int(np.argmax(np.abs(phi)))
    start_amplitude = 2e-3 * (bays / 2) ** 2
    period = 2.0 * math.pi / float(closed.omega[0])
    start = time.perf_counter()
    motion = free_decay(s, (start_amplitude * phi / phi[ref], np.zeros(s.n_dof)), cycles * period)
    took_decay = time.perf_counter() - start
    bb = decay_backbone(motion, ref, mode=1)
    start = time.perf_counter()
    a = bb.amplitude
    nm = nonlinear_modes(s, 1, np.geomspace(0.8 * a.min(), 1.2 * a.max(), 30), harmonics=7)
    took_mode = time.perf_counter() - start
    ok = nm.converged
    peak = 0.5 * (nm.x_max[ok, ref] - nm.x_min[ok, ref])
    print(
        f"mast, {bays} bays (50 um joints, k_c 5e7 N/m, k0 1e5 N/m, Rayleigh beta {beta:g} s): "
        f"closed first mode {closed.omega[0] / (2 * math.pi):.3f} Hz, open "
        f"{s.modes('open').omega[0] / (2 * math.pi):.3f} Hz; free decay from "
        f"{1e3 * start_amplitude:.1f} mm on {s.dof_names[ref]}, {cycles} cycles in "
        f"{took_decay:.1f} s ({motion.events} events); EPMC H = 7, 30 amplitudes in "
        f"{took_mode:.1f} s, {int(ok.sum())}/30 converged"
    )
    print("  cycle  amplitude (mm)  decay (Hz)  EPMC (Hz)  rel. gap   zeta decay  zeta EPMC")
    inside = (a >= peak.min()) & (a <= peak.max())
    for k in range(a.size):
        if not inside[k]:
            print(f"  {k:5d}  {1e3 * a[k]:14.4f}  {bb.omega[k] / (2 * math.pi):10.4f}  (outside)")
            continue
        w_e = float(np.interp(a[k], peak, nm.frequency[ok]))
        z_e = float(np.interp(a[k], peak, nm.epmc_damping_ratio[ok]))
        print(
            f"  {k:5d}  {1e3 * a[k]:14.4f}  {bb.omega[k] / (2 * math.pi):10.4f}  "
            f"{w_e / (2 * math.pi):9.4f}  {bb.omega[k] / w_e - 1:+9.2e}  "
            f"{bb.damping_ratio[k]:10.3e}  {z_e:9.3e}"
        )


def _example_at(force_n: float) -> tuple[Any, np.ndarray, int]:
    s, pattern = example_mast(10)
    force = pattern * (force_n / float(np.max(np.abs(pattern))))
    return s, force, int(np.argmax(np.abs(force)))


def _example_curve(s: Any, force: Any, points: int, **options: Any) -> Any:
    """The example mast's H = 7 curve from MAST_FROM_HZ to MAST_TO_HZ (``options`` passed on)."""
    return frequency_response(
        s,
        force,
        2 * math.pi * MAST_FROM_HZ,
        2 * math.pi * MAST_TO_HZ,
        harmonics=7,
        max_points=points,
        max_step=MAST_MAX_STEP,
        **options,
    )


def mast_check(force_n: float, points: int, checks: int) -> None:
    """The example mast's H = 7 curve at ``force_n`` with ``checks`` points run through one
    exact period (clearjoint.harmonic.check): residual, exact events, orbit crossings."""
    s, force, dof = _example_at(force_n)
    start = time.perf_counter()
    fr = _example_curve(s, force, points, check_points=checks)
    hz = fr.omega / (2 * math.pi)
    print(
        f"examples/mast.toml at {force_n} N, H = 7: {fr.omega.size} points in "
        f"{time.perf_counter() - start:.1f} s, {hz.min():.3f} to {hz.max():.3f} Hz, "
        f"{int(np.sum(~fr.stable))} unstable; {fr.settings['orbit_check']!r}"
    )
    found = fr.settings["orbit_check"]
    print("  point  f (Hz)   tip x_max (mm)  max|mu|    residual  exact events  HB crossings")
    for m, i in enumerate(found.index):
        print(
            f"  {i:5d}  {hz[i]:.4f}  {1e3 * fr.x_max[i, dof]:14.4f}  "
            f"{np.max(np.abs(fr.multipliers[i])):9.4g}  {found.residual[m]:8.2e}  "
            f"{found.exact_events[m]:12d}  {found.orbit_crossings[m]:12d}"
        )


def mast_orders(force_n: float, freqs: list[float]) -> None:
    """The example mast's HB orbit at H = 7, 15, 31 (each Newton from the one before,
    padded with zeros): tip maximum, largest multiplier, one-period residual."""
    from clearjoint.harmonic import aft, monodromy
    from clearjoint.harmonic.response import _start
    from clearjoint.harmonic.solve import newton
    from clearjoint.harmonic.system import build

    s, force, dof = _example_at(force_n)
    model = build(s, None)
    n, k_ref = s.n_dof, model.reference_stiffness
    for f in freqs:
        w = 2 * math.pi * f
        prev = None
        for h in (7, 15, 31):
            basis = aft.Basis.make(h, 1 << math.ceil(math.log2(32 * (2 * h + 1))))

            def function(
                q: np.ndarray, basis: aft.Basis = basis, w: float = w
            ) -> tuple[np.ndarray, np.ndarray]:
                ev = aft.evaluate(model, basis, q, w, force)
                return ev.residual / k_ref, ev.jacobian / k_ref

            if prev is None:
                q = _start(model, basis, w, force, k_ref)
            else:
                q0 = np.zeros((2 * h + 1, n))
                q0[: prev.shape[0]] = prev
                found = newton(function, q0.ravel(), float(np.max(np.abs(q0))))
                if found is None:
                    print(f"  {force_n} N, {f} Hz, H = {h}: no orbit (Newton from H's before)")
                    break
                q = found[0]
            coef = q.reshape(2 * h + 1, n)
            prev = coef
            fr_like = _one_point(s, force, w, h, basis, coef)
            mu = monodromy.multipliers(model, basis, coef, w)
            top, _ = basis.extremes(coef)
            print(
                f"  {force_n} N, {f} Hz, H = {h:2d}: tip x_max {1e3 * top[dof]:.4f} mm, "
                f"max|mu| {np.max(np.abs(mu)):.4g}, residual {fr_like[0]:.2e}, exact events "
                f"{fr_like[1]}, HB crossings {monodromy.crossings(model, basis, coef).size}",
                flush=True,
            )


def _one_point(
    s: Any, force: np.ndarray, w: float, h: int, basis: Any, coef: np.ndarray
) -> tuple[float, int]:
    """One period of exact motion from an HB orbit's state: (residual, events)."""
    from clearjoint.structure import time_response

    n = s.n_dof
    row = np.zeros(2 * h + 1)
    row[2::2] = np.arange(1, h + 1)
    x = np.concatenate((coef[0] + coef[1::2].sum(axis=0), w * (row @ coef)))
    m = time_response(s, force, w, 2 * math.pi / w, initial=(x[:n], x[n:]), samples_per_period=8)
    scale = np.concatenate((np.ones(n), np.full(n, 1 / w)))
    r = np.linalg.norm(scale * (np.concatenate(m.final_state) - x)) / np.linalg.norm(scale * x)
    return float(r), int(m.events)


def mast_shoot(force_n: float, f: float, iterations: int) -> None:
    """Look for the exact periodic orbit near the H = 7 one: x <- x - (Phi_HB - I)^-1 (P(x) - x),
    P one period of exact motion, Phi_HB the HB orbit's monodromy (a fixed Jacobian)."""
    from clearjoint.harmonic import aft, monodromy
    from clearjoint.harmonic.response import _start
    from clearjoint.harmonic.system import build
    from clearjoint.structure import time_response

    s, force, dof = _example_at(force_n)
    model = build(s, None)
    n, w = s.n_dof, 2 * math.pi * f
    basis = aft.Basis.make(7, 512)
    coef = _start(model, basis, w, force, model.reference_stiffness).reshape(15, n)
    jac = monodromy.monodromy(model, basis, coef, w) - np.eye(2 * n)
    row = np.zeros(15)
    row[2::2] = np.arange(1, 8)
    x = np.concatenate((coef[0] + coef[1::2].sum(axis=0), w * (row @ coef)))
    x_hb = x.copy()
    scale = np.concatenate((np.ones(n), np.full(n, 1 / w)))
    top, _ = basis.extremes(coef)
    print(f"  {force_n} N, {f} Hz: HB (H = 7) tip x_max {1e3 * top[dof]:.4f} mm")
    for k in range(iterations):
        m = time_response(s, force, w, 2 * math.pi / w, initial=(x[:n], x[n:]))
        miss = np.concatenate(m.final_state) - x
        r = np.linalg.norm(scale * miss) / np.linalg.norm(scale * x)
        d = np.linalg.norm(scale * (x - x_hb)) / np.linalg.norm(scale * x_hb)
        print(
            f"    iteration {k}: residual {r:.2e}, tip max over the period "
            f"{1e3 * m.u[:, dof].max():.4f} mm, {m.events} events, distance from the HB state "
            f"{d:.2e}",
            flush=True,
        )
        x = x - np.linalg.solve(jac, miss)


def hill_sorting() -> None:
    """Hill's exponents picked by the centred eigenvector against the exact monodromy.

    The 3-link chain of tests/test_harmonic_structure.py. Of Hill's 2N (2H + 1)
    eigenvalues, keep the 2N whose eigenvector's mean complex harmonic index
    sum m abs(c_m)^2 / sum abs(c_m)^2 (c_(+-h) = (a_h -+ i b_h) / 2) is closest to 0
    (each family lambda + i k w shifts that index by k), and also the 2N with the
    smallest abs(Im lambda) (the strip); compare the largest multiplier with the
    monodromy's.
    """
    import scipy.linalg

    from clearjoint import ClearanceJoint
    from clearjoint.harmonic import aft, monodromy
    from clearjoint.harmonic.system import build
    from clearjoint.structure import chain

    j = ClearanceJoint(clearance=1e-4, compression_stiffness=1e7, gap_stiffness=1e5)
    s = chain([1.0] * 3, [1e6] * 3, [j] * 3, dampers=[150.0] * 3)
    force = np.array([0.0, 0.0, 40.0])
    model = build(s, None)
    n = s.n_dof
    print("3-link chain, largest multiplier: monodromy / strip / centred eigenvector")
    for h in (7, 15):
        for w in (200.0, 300.0, 400.0, 600.0, 800.0):
            fr = frequency_response(
                s, force, w, 1.001 * w, harmonics=h, max_points=2, check_points=0
            )
            basis = aft.Basis.make(h, int(fr.settings["samples"]))
            assert fr.coefficients is not None
            q = fr.coefficients[0]
            ev = aft.evaluate(model, basis, q.ravel(), w, force)
            n_c = 2 * h + 1
            size = n_c * n
            scale = np.tile(1.0 / np.diag(model.mass), n_c)[:, None]
            a = np.zeros((2 * size, 2 * size))
            a[:size, size:] = np.eye(size)
            a[size:, :size] = -scale * ev.jacobian
            a[size:, size:] = -scale * aft._damping_operator(model, basis, w)
            lam, vec = scipy.linalg.eig(a)
            v = vec[:size].reshape(n_c, n, -1)
            power = np.sum(np.abs(v[0]) ** 2, axis=0)
            moment = np.zeros(lam.size)
            for k in range(1, h + 1):
                up = np.sum(np.abs(0.5 * (v[2 * k - 1] - 1j * v[2 * k])) ** 2, axis=0)
                down = np.sum(np.abs(0.5 * (v[2 * k - 1] + 1j * v[2 * k])) ** 2, axis=0)
                power = power + up + down
                moment = moment + k * (up - down)
            centred = np.argsort(np.abs(moment / power))[: 2 * n]
            strip = np.argsort(np.abs(lam.imag))[: 2 * n]
            period = 2 * math.pi / w
            exact = np.max(np.abs(monodromy.multipliers(model, basis, q, w)))
            print(
                f"  H = {h:2d}, {w:5.0f} rad/s: {exact:.4f} / "
                f"{np.max(np.abs(np.exp(lam[strip] * period))):.4f} / "
                f"{np.max(np.abs(np.exp(lam[centred] * period))):.4f}"
            )


def samples_error() -> None:
    """HB x_max against the exact orbit (clearjoint.periodic) as N_t grows, pyHarm's case."""
    from clearjoint.harmonic import aft, solve, system
    from clearjoint.periodic import periodic_orbit

    model = system.from_joint(JOINT, Losses(damping_ratio=ZETA))
    omega, force = 1.3, np.array([0.03])
    print(f"x_max error / X against the exact orbit, omega = {omega} rad/s (upper branch):")
    for h in (7, 12):
        exact = None
        row = []
        for n_t in (2 * (2 * h + 1), 64, 128, 256, 512, 1024, 4096):
            basis = aft.Basis.make(h, n_t)
            q0 = np.zeros(2 * h + 1)
            q0[1], q0[2] = -0.3, 0.1

            def function(q: np.ndarray, basis: aft.Basis = basis) -> tuple[np.ndarray, np.ndarray]:
                ev = aft.evaluate(model, basis, q, omega, force)
                return ev.residual, ev.jacobian

            found = solve.newton(function, q0, 0.1)
            assert found is not None
            q = found[0]
            if exact is None:
                x0 = q[0] + q[1::2].sum()
                v0 = omega * float(np.arange(1, h + 1) @ q[2::2])
                exact = periodic_orbit(
                    JOINT, 0.03, omega, losses=Losses(damping_ratio=ZETA), initial=(x0, v0)
                )
            top, _ = basis.extremes(q[:, None])
            row.append(f"N_t = {n_t}: {abs(top[0] - exact.x_max) / exact.amplitude:.1e}")
        print(f"  H = {h}: " + ", ".join(row))


def pyharm_part(python: str | None) -> float | None:
    """pyHarm's SDOF clearance case, H = 12: our curve, pyHarm's, and the ratio (or None)."""
    print(f"pyHarm SDOF clearance case, H = {H}, omega 0.05 to 1.8 rad/s")
    first, second, curve = ours(H, 512, PYHARM_MAX_STEP)
    print(
        f"clearjoint.harmonic (N_t = 512, as pyHarm): {curve.omega.size} points, "  # type: ignore[attr-defined]
        f"first call {first:.3f} s, best of {REPEATS - 1} more {second:.3f} s"
    )
    print(describe("  clearjoint", curve.omega, curve.amplitude))  # type: ignore[attr-defined]
    for e in curve.events:  # type: ignore[attr-defined]
        print(f"  {e.kind}: omega = {e.omega:.4f} rad/s, X = {e.amplitude:.4f}")
    if python:
        ph = pyharm(python, H)
        if not ph:
            print(
                f"pyHarm did not finish within {PYHARM_TIMEOUT} s "
                "(it sometimes stalls after the fold)"
            )
            return None
        om, amp = np.array(ph["omega"]), np.array(ph["amplitude"])
        print(
            f"pyHarm (nti = 512): {ph['points']} points, first call {ph['first_s']:.3f} s, "
            f"best of {REPEATS - 1} more {ph['best_s']:.3f} s"
        )
        print(describe("  pyHarm", om, amp))
        # the load of the shared machine drifts: time ours again after pyHarm and compare
        # with the slower of our two best times (the ratio that favours pyHarm)
        _, again, _ = ours(H, 512, PYHARM_MAX_STEP)
        print(f"clearjoint.harmonic again after pyHarm: best of {REPEATS - 1} {again:.3f} s")
        second = max(second, again)
        ratio = float(ph["best_s"]) / second  # type: ignore[arg-type]
        per_point = (float(ph["best_s"]) / float(ph["points"])) / (  # type: ignore[arg-type]
            second / curve.omega.size  # type: ignore[attr-defined]
        )
        print(f"ratio pyHarm / clearjoint (whole curve, best warm call): {ratio:.2f}x")
        print(f"ratio per point: {per_point:.2f}x")
    else:
        print("pyHarm not run (give --pyharm PYTHON to compare)")
        return None
    return ratio


#: The issue's sizes, the 10-bay H = 7 mast first (the issue's mast part), then the growth
#: (BAYS:H[:most points]): the 40-bay curve capped at 20 points: its stability cost about
#: 10 s a point with expm's product, about 1.3 s with the cached eigen route, and 300 points
#: still did not end within 34 minutes (docs/harmonic.md, "Speed").
ISSUE_SIZES = "10:7,5:7,20:7,10:3,10:15,40:7:20"


def issue_run(python: str | None, points: int) -> None:
    """The issue's speed section in one run: pyHarm's case, then the mast and its growth."""
    started = time.perf_counter()
    print(f"uptime: {subprocess.run(['uptime'], capture_output=True, text=True).stdout.strip()}")
    ratio = pyharm_part(python)
    print(flush=True)
    summary = mast_sizes(ISSUE_SIZES, points, MAST_FORCE_N)
    print(f"uptime: {subprocess.run(['uptime'], capture_output=True, text=True).stdout.strip()}")
    print("summary (one run):")
    shown = "not run" if ratio is None else f"{ratio:.2f}x (target 10x)"
    print(f"  pyHarm's SDOF case, H = {H}, whole curve: pyHarm / clearjoint {shown}")
    for line in summary:
        print(f"  mast {line}")
    print(f"  whole run {time.perf_counter() - started:.0f} s", flush=True)


def one_curve(bays: int, points: int) -> None:
    """Time one mast curve (as --mast-sizes) after a 2-point warm-up; print it as JSON."""
    import clearjoint

    s, pattern = example_mast(bays)
    force = pattern * (MAST_FORCE_N / float(np.max(np.abs(pattern))))
    f_open = float(s.modes("open").omega[0])
    f_closed = float(s.modes("closed").omega[0])
    options: dict[str, Any] = {"harmonics": 7, "max_step": MAST_MAX_STEP}
    frequency_response(s, force, 0.8 * f_open, 1.2 * f_closed, max_points=2, **options)
    wall, cpu = time.perf_counter(), time.process_time()
    fr = frequency_response(s, force, 0.8 * f_open, 1.2 * f_closed, max_points=points, **options)
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    print(
        json.dumps(
            {
                "src": str(Path(clearjoint.__file__).parents[1]),
                "points": int(fr.omega.size),
                "wall": wall,
                "cpu": cpu,
                "unstable": int(np.sum(~fr.stable)),
                "omega": fr.omega.tolist(),
            }
        )
    )


def old_against_new(old_src: str, bays: int, points: int) -> None:
    """The same mast curve timed with another clearjoint src tree and this one, in turn."""
    runs = {}
    for src in (old_src, str(Path(__file__).resolve().parents[1] / "src")):
        env = dict(os.environ, PYTHONPATH=src)
        done = subprocess.run(
            [sys.executable, __file__, "--one-curve", f"{bays}:{points}"],
            capture_output=True,
            text=True,
            check=True,
            env=env,
        )
        runs[src] = json.loads(done.stdout.strip().splitlines()[-1])
        r = runs[src]
        print(
            f"  {r['src']}: {r['points']} points, {r['wall']:.1f} s wall, {r['cpu']:.1f} s CPU, "
            f"{r['unstable']} unstable",
            flush=True,
        )
    old, new = runs.values()
    same = min(len(old["omega"]), len(new["omega"]))
    gap = np.abs(np.array(old["omega"][:same]) - np.array(new["omega"][:same]))
    first = int(np.argmax(gap > 1e-9 * np.array(old["omega"][:same])))
    print(
        f"{bays} bays, H = 7, {points} points: old / this tree {old['wall'] / new['wall']:.2f}x "
        f"wall, {old['cpu'] / new['cpu']:.2f}x CPU; the points agree in w to 1e-9 up to "
        f"point {first if gap.max() > 0 else same}"
    )


#: --monodromy: BAYS:POINTS per mast, the curve whose every orbit both routes multiply
#: (the 40-bay one cut short: the expm route costs about 10 s a point there).
MONODROMY_BAYS = "5:300,10:300,20:300,40:12"


def monodromy_routes(bays_list: str) -> None:
    """The exact monodromy by both routes side by side on the same HB orbits, per bay count.

    For each mast (examples/mast.toml with BAYS bays, H = 7, the --mast-sizes force) a
    POINTS-point curve from 0.8 x the open first mode (no orbit check) gives the orbits;
    then, on all of them in the curve's order (as frequency_response meets them), the plain
    product of scipy.linalg.expm (``method="expm"``, the old route) and the cached
    eigen-decompositions (the default), the cache emptied first so that its cold start
    (every pattern decomposed) is in the time. Accuracy: the eigen route against the
    expm product, beside expm on the balanced matrix against expm (how far the reference
    itself is determined), and the largest multiplier's modulus by both.
    """
    import scipy.linalg

    from clearjoint.harmonic import aft, monodromy
    from clearjoint.harmonic.system import from_structure

    print(f"uptime: {subprocess.run(['uptime'], capture_output=True, text=True).stdout.strip()}")
    print("the exact monodromy of each HB orbit (H = 7) of a mast's curve: expm, eigen route")
    summary = []
    for item in bays_list.split(","):
        bays, points = (int(v) for v in item.split(":"))
        s, pattern = example_mast(bays)
        force = pattern * (MAST_FORCE_N / float(np.max(np.abs(pattern))))
        f_open = float(s.modes("open").omega[0])
        f_closed = float(s.modes("closed").omega[0])
        started = time.perf_counter()
        fr = frequency_response(
            s,
            force,
            0.8 * f_open,
            1.2 * f_closed,
            harmonics=7,
            max_points=points,
            max_step=MAST_MAX_STEP,
            check_points=0,
        )
        made = time.perf_counter() - started
        model = from_structure(s)
        basis = aft.Basis.make(7, int(fr.settings["samples"]))
        orbits = list(zip(fr.coefficients, fr.omega, strict=True))  # type: ignore[arg-type]
        segments = [monodromy.crossings(model, basis, c).size + 1 for c, _ in orbits]
        patterns = [
            {x.tobytes() for x in monodromy._segments(model, basis, c)[1]} for c, _ in orbits
        ]
        in_all = len(set().union(*patterns))
        started = time.perf_counter()
        old = [monodromy.monodromy(model, basis, c, float(w), method="expm") for c, w in orbits]
        t_old = time.perf_counter() - started
        monodromy._FLOWS.clear()
        monodromy._TRANSITIONS.clear()
        started = time.perf_counter()
        new = [monodromy.monodromy(model, basis, orbits[0][0], float(orbits[0][1]))]
        t_first = time.perf_counter() - started
        new += [monodromy.monodromy(model, basis, c, float(w)) for c, w in orbits[1:]]
        t_new = time.perf_counter() - started
        # the reference's own spread: expm of the balanced segment matrices, on the orbit
        # with the most segments
        most = int(np.argmax(segments))
        widths, states = monodromy._segments(model, basis, orbits[most][0])
        n = model.n_dof
        a = np.zeros((2 * n, 2 * n))
        a[:n, n:] = np.eye(n)
        a[n:, n:] = -model.damping / np.diag(model.mass)[:, None]
        balanced = np.eye(2 * n)
        for width, state in zip(widths, states, strict=True):
            a[n:, :n] = -monodromy._pattern_stiffness(model, state) / np.diag(model.mass)[:, None]
            b, (d, _) = scipy.linalg.matrix_balance(
                a * (width / orbits[most][1]), permute=False, separate=True
            )
            balanced = (d[:, None] * scipy.linalg.expm(b) / d[None, :]) @ balanced
        spread = np.linalg.norm(balanced - old[most]) / np.linalg.norm(old[most])
        gap = max(np.linalg.norm(x - y) / np.linalg.norm(y) for x, y in zip(new, old, strict=True))
        mu_gap = max(
            abs(np.max(np.abs(np.linalg.eigvals(x))) - np.max(np.abs(np.linalg.eigvals(y))))
            / np.max(np.abs(np.linalg.eigvals(y)))
            for x, y in zip(new, old, strict=True)
        )
        k = len(orbits)
        line = (
            f"{bays:2d} bays (2N = {2 * n}, {min(segments)} to {max(segments)} segments a "
            f"period, {min(map(len, patterns))} to {max(map(len, patterns))} contact patterns, "
            f"{in_all} over the curve): expm {t_old / k:.3f} s/point, eigen "
            f"{t_new / k:.3f} s/point ({t_first:.3f} s the first, cold; "
            f"{(t_new - t_first) / max(k - 1, 1):.3f} s after): {t_old / t_new:.1f}x over "
            f"{k} points"
        )
        print(
            f"  {line}; the {fr.omega.size}-point curve made in {made:.1f} s, load "
            f"{os.getloadavg()[0]:.2f}",
            flush=True,
        )
        there = np.linalg.norm(new[most] - old[most]) / np.linalg.norm(old[most])
        print(
            f"      eigen vs expm: largest relative difference {gap:.1e} (Frobenius), largest "
            f"multiplier's modulus {mu_gap:.1e}; on the orbit with the most segments "
            f"{there:.1e}, where expm on the balanced matrices differs from expm by {spread:.1e}",
            flush=True,
        )
        summary.append(line)
    print(f"uptime: {subprocess.run(['uptime'], capture_output=True, text=True).stdout.strip()}")
    print("summary (one run):")
    for line in summary:
        print(f"  {line}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pyharm", help="python interpreter that has pyHarm (pyharm-os)")
    parser.add_argument("--mast", action="store_true", help="the mast timings instead")
    parser.add_argument("--mast-points", type=int, default=300, help="mast curve points")
    parser.add_argument(
        "--mast-curve", action="store_true", help="only the example mast's curve (--mast's last)"
    )
    parser.add_argument("--samples", action="store_true", help="the error against N_t instead")
    parser.add_argument(
        "--mast-sizes",
        nargs="?",
        const=MAST_SIZES,
        help=f"the example mast's cost against bays and H, as BAYS:H,... (default {MAST_SIZES})",
    )
    parser.add_argument("--mast-force", type=float, default=MAST_FORCE_N, help="N, --mast-sizes")
    parser.add_argument(
        "--curves-only", action="store_true", help="--mast-sizes without the nonlinear modes"
    )
    parser.add_argument(
        "--mast-decay",
        type=int,
        metavar="BAYS",
        help="a BAYS-bay mast's first nonlinear mode against its free decay instead",
    )
    parser.add_argument("--decay-cycles", type=int, default=12, help="cycles, --mast-decay")
    parser.add_argument("--mast-check", type=float, metavar="N", help="the check at N newtons")
    parser.add_argument("--mast-orders", type=float, metavar="N", help="H = 7, 15, 31 at N")
    parser.add_argument("--mast-shoot", type=float, metavar="N", help="exact orbit near HB at N")
    parser.add_argument("--at", default="0.9,1.28", help="Hz list for --mast-orders/--mast-shoot")
    parser.add_argument("--hill-sorting", action="store_true", help="Hill's exponent picks")
    parser.add_argument(
        "--issue",
        action="store_true",
        help="the issue's speed section in one run: pyHarm's case (with --pyharm), the 10-bay "
        f"mast (H = 7, --mast-points points, 50 amplitudes) and its growth ({ISSUE_SIZES})",
    )
    parser.add_argument(
        "--old-src",
        help="time the mast's curve (--old-bays, --mast-points) with another clearjoint src tree "
        "(e.g. main's: git archive main src | tar -x -C OLD) and with this one, in turn",
    )
    parser.add_argument(
        "--monodromy",
        nargs="?",
        const=MONODROMY_BAYS,
        metavar="BAYS:POINTS,...",
        help="the exact monodromy by scipy's expm product and by the cached eigen route, side "
        f"by side on every orbit of a POINTS-point curve per mast (default {MONODROMY_BAYS})",
    )
    parser.add_argument("--old-bays", type=int, default=10, help="the mast's bays, --old-src")
    parser.add_argument("--one-curve", help=argparse.SUPPRESS)  # BAYS:POINTS, for --old-src
    args = parser.parse_args()
    if args.monodromy:
        monodromy_routes(args.monodromy)
        return
    if args.one_curve:
        one_curve(*(int(v) for v in args.one_curve.split(":")))
        return
    if args.old_src:
        old_against_new(args.old_src, args.old_bays, args.mast_points)
        return
    if args.issue:
        issue_run(args.pyharm, args.mast_points)
        return
    if args.hill_sorting:
        hill_sorting()
        return
    freqs = [float(v) for v in args.at.split(",")]
    if args.mast_check:
        mast_check(args.mast_check, args.mast_points, 25)
        return
    if args.mast_orders:
        mast_orders(args.mast_orders, freqs)
        return
    if args.mast_shoot:
        for f in freqs:
            mast_shoot(args.mast_shoot, f, 6)
        return
    if args.mast_decay:
        mast_decay(args.mast_decay, 2e-5, args.decay_cycles)
        return
    if args.mast_sizes:
        mast_sizes(args.mast_sizes, args.mast_points, args.mast_force, not args.curves_only)
        return
    if args.samples:
        samples_error()
        return
    if args.mast_curve:
        example_mast_curve(args.mast_points)
        return
    if args.mast:
        mast_benchmarks(args.mast_points)
        return
    pyharm_part(args.pyharm)
    print("growth with H (default N_t = 32 (2H + 1) rounded up to a power of two):")
    for h in (3, 7, 12, 15, 31):
        _, warm, c = ours(h, None, PYHARM_MAX_STEP)
        print(f"  H = {h:2d}: {c.omega.size} points, {warm:.3f} s")  # type: ignore[attr-defined]
    sys.stdout.flush()


if __name__ == "__main__":
    main()
