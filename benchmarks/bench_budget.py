"""A structure's stepped-sine period: its measured cost against clearjoint.budget's estimate.

Run on demand::

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_budget.py [--bays 5,10]

(issue 28: a runaway request is refused with an honest estimate, within about 2-3x.) For
examples/chain.toml (5 DOF) and the mast of examples/mast.toml rebuilt with each of
``--bays`` (4 DOF a bay), at closed mode 1 and at twice it: the CPU seconds (this process,
``time.process_time``, which other jobs on a shared machine disturb less than the wall
clock) of a settling period and the extra seconds of a recorded one (its tangent flow for
the Lyapunov exponent), each from the difference of two short stepped sines (2 + 30 periods
against 2, and 5 recorded against 1), beside :func:`clearjoint.budget.structure_period_s`
and :func:`clearjoint.budget.structure_tangent_s`, and the ratio estimate / measured.
"""

from __future__ import annotations

import argparse
import math
import tempfile
import time
from pathlib import Path

import numpy as np

from clearjoint.budget import structure_period_s, structure_tangent_s
from clearjoint.structure import stepped_sine
from clearjoint.structure.study import load_structure_study

ROOT = Path(__file__).resolve().parents[1]


def _cpu(study: object, omega: float, settle: int, record: int) -> float:
    s = study.structure  # type: ignore[attr-defined]
    start = time.process_time()
    stepped_sine(s, study.force, np.array([omega]), settle_periods=settle, record_periods=record)  # type: ignore[attr-defined]
    return time.process_time() - start


def measure(name: str, path: Path) -> None:
    study = load_structure_study(str(path))
    s = study.structure
    w1 = float(s.modes("closed", 1).omega[0])
    _cpu(study, w1, 1, 1)  # compiled code loaded (or compiled) before timing
    n = s.n_dof
    for factor in (1.0, 2.0):
        w = factor * w1
        base = _cpu(study, w, 2, 1)
        settle = (_cpu(study, w, 32, 1) - base) / 30.0
        tangent = (_cpu(study, w, 2, 5) - base) / 4.0 - settle
        print(
            f"{name:10s} {n:3d} DOF {w / (2 * math.pi):7.2f} Hz: settling period "
            f"{settle:.4f} s (estimate {structure_period_s(n):.4f}, ratio "
            f"{structure_period_s(n) / settle:.1f}), tangent flow of a recorded period "
            f"{tangent:.4f} s (estimate {structure_tangent_s(n):.4f}, ratio "
            f"{structure_tangent_s(n) / tangent:.1f})",
            flush=True,
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bays", default="10", help="mast sizes, comma-separated (default 10)")
    args = parser.parse_args()
    measure("chain", ROOT / "examples" / "chain.toml")
    text = (ROOT / "examples" / "mast.toml").read_text(encoding="utf-8")
    with tempfile.TemporaryDirectory() as folder:
        for bays in (int(b) for b in args.bays.split(",")):
            path = Path(folder) / f"mast{bays}.toml"
            tip = f'"n{2 * bays + 1}x"'  # the study's forced and decaying DOF: the tip
            size = text.replace("bays = 10", f"bays = {bays}").replace('"n21x"', tip)
            path.write_text(size, encoding="utf-8")
            measure(f"mast {bays}", path)


if __name__ == "__main__":
    main()
