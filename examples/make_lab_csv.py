"""Write the tutorial's lab-style CSV files from the virtual rig: ``python examples/make_lab_csv.py``.

Four tests of joint 1 (c = 0.106 mm) and two of joint 2 (c = 0.196 mm) from the default
campaign, at 40 Hz, written as a lab's data logger would: a plain CSV with the unit of
each column in brackets (displacement in mm), 4 kHz, the last 12 cycles, and the test's
metadata in a sidecar TOML file beside it. docs/tutorial/csv-to-report.md uses them.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from clearjoint.rig import load_campaign, simulate_test

HERE = Path(__file__).parent / "lab-csv"
TESTS = [f"joint-1_40Hz_{f}N" for f in (800, 1600, 2500, 3000)] + [
    f"joint-2_40Hz_{f}N" for f in (1600, 3000)
]
KEEP_RATE = 4000.0  # Hz
KEEP_CYCLES = 12


def main() -> None:
    campaign = load_campaign()
    seeds = np.random.SeedSequence(campaign.seed).spawn(len(campaign.tests))
    for spec in campaign.tests:
        if spec.file_stem not in TESTS:
            continue
        record, _ = simulate_test(campaign.rig, spec, campaign.periods, seeds[spec.index])
        step = round(record.sampling_rate / KEEP_RATE)
        keep = record.time >= record.time[-1] - KEEP_CYCLES / spec.frequency_hz
        idx = np.nonzero(keep)[0][::step]
        t = record.time[idx] - record.time[idx[0]]
        rows = np.column_stack(
            (t, record.force[idx], record.displacement[idx] * 1e3, record.acceleration[idx])  # type: ignore[index]
        )
        path = HERE / f"{spec.file_stem}.csv"
        with path.open("w", encoding="utf-8") as handle:
            handle.write("time [s],force [N],displacement [mm],acceleration [m/s^2]\n")
            for row in rows:
                handle.write(f"{row[0]:.6f},{row[1]:.2f},{row[2]:.6f},{row[3]:.3f}\n")
        path.with_suffix(".toml").write_text(
            f'joint_id = "{spec.structure.name}"\n'
            'control = "force"\n'
            f'frequency = "{spec.frequency_hz:g} Hz"\n'
            f'force_amplitude = "{spec.force_amplitude:g} N"\n'
            f'mass = "{campaign.rig.mass:g} kg"  # the moving mass, for force - m x\'\'\n',
            encoding="utf-8",
        )
        print(f"wrote {path} ({len(rows)} rows) and its .toml")


if __name__ == "__main__":
    main()
