"""pyHarm on the masts of issue 25, side by side with clearjoint (harmonic balance, H = 7).

Run on demand, with pyHarm in its own interpreter (pyHarm is ``pyharm-os`` on PyPI and pins
an old jax and pandas: never install it in the project's environment):

    python benchmarks/pyharm_scale.py --pyharm /work/venv-pyharm/bin/python [--bays 5,10,20]
        [--points 100] [--timeout 900]

The case is ``bench_scale.py``'s: the planar mast of ``clearjoint.structure.mast`` with a
hinge ``ClearanceJoint(50e-6, 5e7, gap_stiffness=1e5)`` in every longeron, Rayleigh beta
2e-6 s, 0.1 N at the tip (x), H = 7 and 512 time samples a period (clearjoint's default
for H = 7), ``points`` points at most from 0.8 x the first open mode to 1.2 x the first
closed one. pyHarm gets the same model: clearjoint's assembled mass, stiffness and
damping matrices as one substructure (two DOFs a node), and each hinge as what clearjoint
assembles it to (the hinge in series with its member: one piecewise-linear law of the
member's elongation): a ``LinearSpring`` of the open slope k0 and a
``PenaltyBilateralGap`` of the contact slope k_c beyond the gap edge g, along the member
(a coordinate system of its own where the member is not along x or y). pyHarm's
continuation is its documented default for an FRF (tangent predictor, arc length,
Newton-Raphson, acceptance step sizer) with a step of at most ``PYHARM_STEP`` of the start
frequency, stopped at ``points`` solutions: both codes then take steps of about the same
size through the first resonance, and the frequency range each covered is printed.

Printed per size: the unknowns, each code's wall time, points and cost per point, and the
frequency range each covered; a size pyHarm does not finish within ``--timeout`` seconds
is said so. Each code runs in its own process, one after the other, on a machine that
other sessions may load (the load average is printed): compare ratios within one run.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse
import json
import math
import subprocess
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from clearjoint import ClearanceJoint
from clearjoint.harmonic import frequency_response
from clearjoint.structure import mast

H = 7
SAMPLES = 512
#: pyHarm's arclength step (its largest and first), as a share of the start frequency in
#: rad/s: the mast's displacements are tens of micrometres, so its arclength is nearly the
#: frequency step. 0.4 % a point, as clearjoint's max_step = 0.05 takes near the start.
PYHARM_STEP = 0.004

PYHARM_SCRIPT = r"""
import json, sys, time
import numpy as np
import pyHarm

data = np.load(sys.argv[1])
points = int(sys.argv[2])
m, k, c = data["mass"], data["stiffness"], data["damping"]
b, k0, kc, g = data["directions"], data["k0"], data["k_c"], data["g_c"]
nodes = m.shape[0] // 2
coordinates, connectors = {}, {}
for j, row in enumerate(b):
    touched = sorted({int(i) // 2 for i in np.flatnonzero(row)})
    first = touched[0]
    direction = row[2 * first : 2 * first + 2]
    if len(touched) == 2:
        connect = [("mast", [touched[0]]), ("mast", [touched[1]])]
    else:
        connect = [("mast", [first]), ("GROUND", [None])]
    axis = np.flatnonzero(np.abs(direction) > 1e-12)
    if axis.size == 1:
        extra = {"dirs": [int(axis[0])]}
    else:
        unit = direction / np.linalg.norm(direction)
        coordinates[f"cs{j}"] = [[unit[0], unit[1]], [-unit[1], unit[0]]]
        extra = {"dirs": [0], "coordinatesystem": f"cs{j}"}
    connectors[f"open{j}"] = {"connect": connect, "type": "LinearSpring",
                              "k": float(k0[j]), **extra}
    connectors[f"gap{j}"] = {"connect": connect, "type": "PenaltyBilateralGap",
                             "g": float(g[j]), "k": float(kc[j]), **extra}
connectors["force"] = {"connect": [("mast", [int(data["tip"]) // 2]), ("GROUND", [None])],
                       "dirs": [int(data["tip"]) % 2], "type": "SinusForcing",
                       "amp": float(data["force"])}
w0, w1 = float(data["omega_start"]), float(data["omega_stop"])
ds = STEP * w0
problem = {
    "analysis": {"frf": {"study": "frf", "puls_inf": w0, "puls_start": w0, "puls_sup": w1,
                         "ds0": ds, "ds_min": 1e-6 * ds, "ds_max": ds, "sign_ds": 1,
                         "verbose": False, "stepsizer": "acceptance", "predictor": "tangent",
                         "corrector": "arc_length", "stopper": "solnumber",
                         "stopper_options": {"max_solutions": points},
                         "solver": "NewtonRaphson"}},
    "system": {"type": "Base", "nh": HARMONICS, "nti": SAMPLES},
    "coordinates": coordinates,
    "substructures": {"mast": {"type": "substructure", "ndofs": 2,
                               "matrix": {"M": m, "K": k, "C": c}}},
    "connectors": connectors,
}
start = time.perf_counter()
maestro = pyHarm.Maestro(problem)
maestro.operate()
took = time.perf_counter() - start
sols = [s for s in maestro.nls["frf"].SolList if s.flag_accepted]
om = [float(s.x[-1]) for s in sols]
print(json.dumps({"seconds": took, "points": len(sols), "omega_first": om[0] if om else None,
                  "omega_last": om[-1] if om else None}))
"""


def model(bays: int) -> Any:
    """bench_scale's mast with ``bays`` bays."""
    return mast(bays, joints=ClearanceJoint(50e-6, 5e7, gap_stiffness=1e5), rayleigh=(0.0, 2e-6))


def export(bays: int, folder: Path) -> tuple[Path, dict[str, Any]]:
    """The mast's assembled model and the curve's range, as an .npz pyHarm's script reads."""
    structure = model(bays)
    system = structure.to_system()
    w0 = 0.8 * float(structure.modes("open").omega[0])
    w1 = 1.2 * float(structure.modes("closed").omega[0])
    tip = list(system.dof_names).index(f"n{2 * bays + 1}x")
    laws = system.law_arrays()
    if not (np.allclose(laws.g_c, laws.g_t) and np.allclose(laws.k_c, laws.k_t)):
        raise SystemExit("pyHarm's PenaltyBilateralGap is symmetric: the hinges must be too")

    def dense(matrix: Any) -> np.ndarray:
        return np.asarray(matrix.toarray() if hasattr(matrix, "toarray") else matrix, dtype=float)

    path = folder / f"mast{bays}.npz"
    np.savez(
        path,
        mass=np.diag(system.mass_diagonal()),
        stiffness=dense(system.stiffness),
        damping=dense(system.damping),
        directions=dense(system.directions),
        k0=laws.k0,
        k_c=laws.k_c,
        g_c=laws.g_c,
        tip=tip,
        force=0.1,
        omega_start=w0,
        omega_stop=w1,
    )
    force = np.zeros(system.n_dof)
    force[tip] = 0.1
    return path, {"structure": structure, "force": force, "w0": w0, "w1": w1}


def ours(case: dict[str, Any], points: int) -> dict[str, Any]:
    start = time.perf_counter()
    fr = frequency_response(
        case["structure"],
        case["force"],
        case["w0"],
        case["w1"],
        harmonics=H,
        samples=SAMPLES,
        max_points=points,
        max_step=0.05,
        check_points=0,
    )
    took = time.perf_counter() - start
    return {
        "seconds": took,
        "points": int(fr.omega.size),
        "omega_first": float(fr.omega[0]),
        "omega_last": float(fr.omega[-1]),
    }


def theirs(python: str, path: Path, points: int, timeout: float) -> dict[str, Any] | None:
    with tempfile.TemporaryDirectory() as folder:
        script = Path(folder) / "pyharm_mast.py"
        script.write_text(
            PYHARM_SCRIPT.replace("HARMONICS", str(H))
            .replace("SAMPLES", str(SAMPLES))
            .replace("STEP", repr(PYHARM_STEP))
        )
        try:
            done = subprocess.run(
                [python, str(script), str(path), str(points)],
                capture_output=True,
                text=True,
                cwd=folder,
                timeout=timeout,
            )
        except subprocess.TimeoutExpired:
            return None
    if done.returncode != 0:
        last = (done.stderr.strip().splitlines() or ["(no message)"])[-1]
        return {"error": last}
    result: dict[str, Any] = json.loads(done.stdout.strip().splitlines()[-1])
    return result


def describe(name: str, r: dict[str, Any] | None, timeout: float) -> str:
    if r is None:
        return f"{name}: did not finish within {timeout:.0f} s"
    if "error" in r:
        if "IndexError" in r["error"] and "list index" in r["error"]:
            return (
                f"{name}: did not start (its first solve at the start frequency was not "
                "accepted, and its tangent predictor had no solution to continue from: "
                f"{r['error']})"
            )
        return f"{name}: failed ({r['error']})"
    per = r["seconds"] / max(r["points"] - 1, 1)
    ended = "" if r["points"] >= r.get("asked", 0) else f" (stopped before {r['asked']})"
    span = ""
    if r["omega_first"] is not None:
        span = (
            f", {r['omega_first'] / (2 * math.pi):.3f} to {r['omega_last'] / (2 * math.pi):.3f} Hz"
        )
    return f"{name}: {r['seconds']:.1f} s, {r['points']} points{ended}, {per:.3f} s a point{span}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pyharm", required=True, help="pyHarm's interpreter")
    parser.add_argument("--bays", default="5,10,20", help="sizes, comma-separated")
    parser.add_argument("--points", type=int, default=100)
    parser.add_argument("--timeout", type=float, default=900.0, help="pyHarm's budget a size, s")
    args = parser.parse_args()
    print(
        f"mast, H = {H}, {SAMPLES} samples, 0.1 N at the tip, {args.points} points at most from "
        f"0.8 x open to 1.2 x closed first mode (load {os.getloadavg()[0]:.1f})"
    )
    with tempfile.TemporaryDirectory() as folder:
        for bays in (int(b) for b in args.bays.split(",")):
            path, case = export(bays, Path(folder))
            unknowns = (2 * H + 1) * case["structure"].n_dof
            print(f"{bays} bays ({unknowns} unknowns):", flush=True)
            mine = ours(case, args.points) | {"asked": args.points}
            print("  " + describe("clearjoint", mine, args.timeout), flush=True)
            result = theirs(args.pyharm, path, args.points, args.timeout)
            if result is not None:
                result["asked"] = args.points
            print("  " + describe("pyHarm", result, args.timeout), flush=True)
            if result is None:
                break  # a larger size would not finish either


if __name__ == "__main__":
    main()
