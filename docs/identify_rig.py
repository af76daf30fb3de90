"""Compare ``clearjoint identify`` on the rig's records with the rig's manifest, like with like.

    clearjoint rig --out rig && clearjoint identify rig/*.nc --out r.csv
    python docs/identify_rig.py rig/manifest.csv r.csv

The two files document different stiffnesses (MODEL.md section 0): identify's
``compression_stiffness_n_per_m`` and ``tension_stiffness_n_per_m`` are the contact slopes
a record shows, k0 + k_s (docs/identify.md, step 6); the manifest's are the structure's
k_s alone, its ``gap_stiffness_n_per_m`` holding k0 (docs/rig.md). The truth compared with
is therefore the manifest's k_s + k0. The last lines print the comparison that leaves k0
out, to show what it would read (k0 / k_s high).
"""

from __future__ import annotations

import argparse
import csv
from pathlib import Path

#: identify's columns compared with the manifest's
COLUMNS = (
    "clearance_m",
    "compression_stiffness_n_per_m",
    "tension_stiffness_n_per_m",
    "energy_per_cycle_j",
)


def truth_of(column: str, row: dict[str, str]) -> float:
    """The manifest's truth for identify's ``column``: a contact stiffness is k_s + k0."""
    value = float(row[column])
    if column.endswith("_stiffness_n_per_m"):
        value += float(row["gap_stiffness_n_per_m"])
    return value


def _read(path: Path) -> dict[str, dict[str, str]]:
    with path.open(newline="") as handle:
        return {Path(row["file"]).name: row for row in csv.DictReader(handle)}


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("manifest", type=Path, help="the rig's manifest.csv")
    parser.add_argument("results", type=Path, help="the results CSV of clearjoint identify")
    args = parser.parse_args(argv)
    truth, found = _read(args.manifest), _read(args.results)
    missing = sorted(set(truth) - set(found))
    if missing:
        raise SystemExit(f"{args.results}: no result for {len(missing)} records, e.g. {missing[0]}")
    joints = [name for name in truth if truth[name]["structure"] != "beam"]
    beams = [name for name in truth if truth[name]["structure"] == "beam"]
    models = {found[name]["model"] for name in joints}, {found[name]["model"] for name in beams}
    flagged = sum(found[name]["flag"] != "ok" for name in truth)
    print(
        f"{len(joints)} jointed tests (models {sorted(models[0])}), {len(beams)} beam tests "
        f"(models {sorted(models[1])}), {flagged} flagged"
    )
    for group, names in (("jointed", joints), ("beam", beams)):
        print(f"{group} tests, identified / truth - 1:")
        for column in COLUMNS:
            if group == "beam" and column == "clearance_m":
                continue  # a line: no clearance
            errors = [
                (float(found[n][column]) / truth_of(column, truth[n]) - 1.0, n) for n in names
            ]
            lo, hi = min(errors), max(errors)
            print(
                f"  {column:30s} {100 * lo[0]:+.3f} % ({lo[1]}) to {100 * hi[0]:+.3f} % "
                f"({hi[1]}): worst |error| {100 * max(abs(lo[0]), abs(hi[0])):.2f} %"
            )
    friction = [float(found[name]["friction_force_n"]) for name in joints]
    true_friction = {float(truth[name]["friction_force_n"]) for name in joints}
    print(
        f"  friction_force_n (jointed)     {min(friction):.2f} to {max(friction):.2f} N "
        f"(true {sorted(true_friction)} N)"
    )
    print("jointed tests, leaving k0 out of the truth (not like with like):")
    for side in ("compression", "tension"):
        column = f"{side}_stiffness_n_per_m"
        bare = [float(found[n][column]) / float(truth[n][column]) - 1.0 for n in joints]
        print(f"  {column:30s} {100 * min(bare):+.3f} % to {100 * max(bare):+.3f} %")


if __name__ == "__main__":
    main()
