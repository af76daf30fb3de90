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

import numpy as np

from clearjoint import Joint
from clearjoint.harmonic import frequency_response

JOINT = Joint(mass=1.0, clearance=2 * 0.1745, compression_stiffness=3.0, gap_stiffness=1.0)
ZETA = 0.05 / (2.0 * math.sqrt(3.0))  # c_v = 2 zeta sqrt(m k_c) = 0.05
H = 12
#: pyHarm's continuation settings, as in benchmarks/bench_periodic.py: its documented tangent
#: predictor, arc-length corrector and "acceptance" step sizer with ds_max = 0.01. With ds_max
#: 0.05 (and 0.04) its predictor turns back and forth between 1.09 and 1.14 rad/s after the
#: upper fold without end (the sign of det J flips on the sampled law's kinks); with 0.01 it
#: follows the whole curve, 326 points. Give up after this many s all the same.
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
            damping_ratio=ZETA,
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pyharm", help="python interpreter that has pyHarm (pyharm-os)")
    args = parser.parse_args()
    print(f"pyHarm SDOF clearance case, H = {H}, omega 0.05 to 1.8 rad/s")
    first, second, curve = ours(H, 512, 0.025)
    print(
        f"clearjoint.harmonic (N_t = 512, as pyHarm): {curve.omega.size} points, "  # type: ignore[attr-defined]
        f"first call {first:.3f} s, best of {REPEATS - 1} more {second:.3f} s"
    )
    print(describe("  clearjoint", curve.omega, curve.amplitude))  # type: ignore[attr-defined]
    for e in curve.events:  # type: ignore[attr-defined]
        print(f"  {e.kind}: omega = {e.omega:.4f} rad/s, X = {e.amplitude:.4f}")
    if args.pyharm:
        ph = pyharm(args.pyharm, H)
        if not ph:
            print(
                f"pyHarm did not finish within {PYHARM_TIMEOUT} s "
                "(it sometimes stalls after the fold)"
            )
            return
        om, amp = np.array(ph["omega"]), np.array(ph["amplitude"])
        print(
            f"pyHarm (nti = 512): {ph['points']} points, first call {ph['first_s']:.3f} s, "
            f"best of {REPEATS - 1} more {ph['best_s']:.3f} s"
        )
        print(describe("  pyHarm", om, amp))
        ratio = float(ph["best_s"]) / second  # type: ignore[arg-type]
        per_point = (float(ph["best_s"]) / float(ph["points"])) / (  # type: ignore[arg-type]
            second / curve.omega.size  # type: ignore[attr-defined]
        )
        print(f"ratio pyHarm / clearjoint (whole curve, best warm call): {ratio:.2f}x")
        print(f"ratio per point: {per_point:.2f}x")
    else:
        print("pyHarm not run (give --pyharm PYTHON to compare)")
    print("growth with H (default N_t = 32 (2H + 1) rounded up to a power of two):")
    for h in (3, 7, 12, 15, 31):
        _, warm, c = ours(h, None, 0.025)
        print(f"  H = {h:2d}: {c.omega.size} points, {warm:.3f} s")  # type: ignore[attr-defined]
    sys.stdout.flush()


if __name__ == "__main__":
    main()
