"""The BRFD table of docs/identify.md: every file of the shared data set, identified.

Run from the repository's root: ``python docs/identify_brfd.py [BRFD_FOLDER]`` (default
../shared/data/brfd beside the repository). Data: D. Coble, P. Huggins, L. Cao, J. Ricles,
A. Downey, "Dataset-Friction-Damper-with-Backlash", GitHub, ARTS-Laboratory, 2022
(CC BY-SA 4.0).

Checks, per the issue: every file a damper loop or refused with its reason; the backlash
within 15 % of the median of the accepted tests at the same band tension; the loop energy
within 15 % of the elastic-plastic-with-gap estimate 2 F_f (2X - b - 2 F_f / k).

``python docs/identify_brfd.py --diagnose [BRFD_FOLDER]`` prints instead, for the files whose
backlash misses, the travel steps between the level crossings on each branch (what the
damper estimator reads, :mod:`clearjoint.identify.damper`), and the backlash of every file
under an alternative rule tried in docs/identify.md (a long step in which the force falls
back by more than two crossing levels, or one, is ringing, not backlash).
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

import numpy as np

from clearjoint.identify import damper, identify_files

ROOT = Path(__file__).resolve().parents[1]


def _levels(x: np.ndarray, f: np.ndarray) -> tuple[tuple[slice, slice], float, float]:
    top = int(np.argmax(x))
    parts = (slice(0, top + 1), slice(top, x.size))
    levels = []
    for part in parts:
        travel = np.abs(x[part] - x[part][0])
        levels.append(float(np.median(f[part][travel >= (1 - damper.PLATEAU) * travel[-1]])))
    return parts, levels[0], levels[1]


def _steps(x: np.ndarray, f: np.ndarray, dip: float | None) -> tuple[list[np.ndarray], float]:
    """Crossing steps of both branches and the backlash from them (dip: the alternative)."""
    parts, rise, fall = _levels(x, f)
    steps_all, backlash = [], []
    for part, start, stop in ((parts[0], fall, rise), (parts[1], rise, fall)):
        travel, fb = np.abs(x[part] - x[part][0]), f[part]
        s = damper._crossings(travel, fb, start, stop)
        assert s is not None
        steps = np.diff(s)
        typical = float(np.median(steps))
        excess = steps - typical
        long = excess > damper.JUMP * typical
        if dip is not None:
            progress = np.sign(stop - start) * (fb - start) / abs(stop - start)
            for i in range(steps.size):
                inside = (travel >= s[i]) & (travel <= s[i + 1])
                if inside.any() and progress[inside].min() < damper.ALPHAS[i] - dip:
                    long[i] = False
        steps_all.append(steps)
        backlash.append(float(np.sum(excess[long])))
    return steps_all, 0.5 * sum(backlash)


def diagnose(results: list[tuple[object, object]]) -> None:
    loops = {Path(i.source).stem: i.loop for _, i in results}  # type: ignore[attr-defined]
    tension = {k: int(re.search(r"(\d+)lbtension", k)[1]) for k in loops}  # type: ignore[index]
    for dip in (None, 0.1, 0.05):
        b = {k: _steps(*loop, dip)[1] for k, loop in loops.items()}
        median = {t: float(np.median([b[k] for k in b if tension[k] == t])) for t in (0, 30, 36)}
        miss = {
            k: b[k] / median[tension[k]] for k in b if abs(b[k] / median[tension[k]] - 1) > 0.15
        }
        rule = "as shipped" if dip is None else f"ringing dips of more than {dip:.0%} excluded"
        print(
            f"\nbacklash rule {rule}: medians (mm) "
            + ", ".join(f"{t} lb {1e3 * m:.2f}" for t, m in median.items())
            + f"; {len(miss)} miss: "
            + ", ".join(f"{k} {v - 1:+.0%}" for k, v in sorted(miss.items()))
        )
        if dip is None:
            for k in sorted(miss):
                steps, _ = _steps(*loops[k], None)
                for name, st in zip(("rising", "falling"), steps, strict=True):
                    print(
                        f"  {k} {name} branch, steps (mm): "
                        + " ".join(f"{1e3 * v:.2f}" for v in st)
                    )


def main() -> None:
    args = [a for a in sys.argv[1:] if a != "--diagnose"]
    folder = Path(args[0]) if args else ROOT.parent.parent / "shared/data/brfd"
    results, failures = identify_files([str(p) for p in sorted(folder.glob("*.json"))])
    if "--diagnose" in sys.argv:
        diagnose(results)  # type: ignore[arg-type]
        return
    rows = []
    for _, ident in results:
        s, e = ident.summary, ident.stderr
        tension = int(re.search(r"(\d+)lbtension", ident.source)[1])  # type: ignore[index]
        k = 0.5 * (s["compression_stiffness_n_per_m"] + s["tension_stiffness_n_per_m"])
        f_f, x, b = s["friction_force_n"], s["amplitude_m"], s["clearance_m"]
        estimate = 2 * f_f * (2 * x - b - 2 * f_f / k)
        rows.append((Path(ident.source).name, tension, ident, s, e, k, estimate))
    median = {
        t: float(np.median([r[3]["clearance_m"] for r in rows if r[1] == t])) for t in (0, 30, 36)
    }
    print(
        "| file | model | cycles | backlash b (mm) | b / median | F+ / F- (kN) | k (MN/m) "
        "| X (mm) | E (J) | E / 2F_f(2X-b-2F_f/k) | flag |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    misses_b = misses_e = 0
    for name, t, ident, s, e, k, estimate in rows:
        rb = s["clearance_m"] / median[t]
        re_ = s["energy_per_cycle_j"] / estimate
        misses_b += abs(rb - 1) > 0.15
        misses_e += abs(re_ - 1) > 0.15
        print(
            f"| {name} | {ident.model} | {ident.cycles_used}/{ident.cycles_total} "
            f"| {1e3 * s['clearance_m']:.2f} ± {1e3 * e['clearance_m']:.2f} | {rb:.2f} "
            f"| {s['friction_force_positive_n'] / 1e3:.2f} / "
            f"{s['friction_force_negative_n'] / 1e3:.2f} | {k / 1e6:.2f} "
            f"| {1e3 * s['amplitude_m']:.1f} | {s['energy_per_cycle_j']:.0f} | {re_:.3f} "
            f"| {ident.flag} |"
        )
    for name, _, ident, *_ in rows:
        if ident.flag != "ok":
            print(f"\nflagged: {name}: {ident.flag_reason}")
    for line in failures:
        print(f"\nrefused: {line}")
    print(
        f"\nmedian backlash (mm): 0 lb {1e3 * median[0]:.2f}, 30 lb {1e3 * median[30]:.2f}, "
        f"36 lb {1e3 * median[36]:.2f}; damper loops {sum(r[2].model == 'damper' for r in rows)}"
        f" of {len(rows)} accepted, {len(failures)} refused; backlash outside 15 % of its "
        f"median: {misses_b}; energy outside 15 %: {misses_e}"
    )


if __name__ == "__main__":
    main()
