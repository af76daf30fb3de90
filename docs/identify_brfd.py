"""The BRFD table of docs/identify.md: every file of the shared data set, identified.

Run from the repository's root: ``python docs/identify_brfd.py [BRFD_FOLDER]`` (default
../shared/data/brfd beside the repository). Data: D. Coble, P. Huggins, L. Cao, J. Ricles,
A. Downey, "Dataset-Friction-Damper-with-Backlash", GitHub, ARTS-Laboratory, 2022
(CC BY-SA 4.0).

Checks, per the issue: every file a damper loop or refused with its reason; the backlash
within 15 % of the median of the accepted tests at the same band tension; the loop energy
within 15 % of the elastic-plastic-with-gap estimate 2 F_f (2X - b - 2 F_f / k).
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

import numpy as np

from clearjoint.identify import identify_files

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    folder = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT.parent.parent / "shared/data/brfd"
    results, failures = identify_files([str(p) for p in sorted(folder.glob("*.json"))])
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
