"""Samples per second of the identification, end to end (read + identify) for one record.

Run on demand: ``python benchmarks/bench_identify.py [BRFD_FOLDER]``. Target (issue 6):
at least 10^6 samples per second for one record. It times, best of five, a long rig
record (20 Hz, 30 cycles at 12 kHz, netCDF), a short one (100 Hz), and a real BRFD
JSON file when the data set is found.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

from clearjoint.identify import identify
from clearjoint.records import read_record
from clearjoint.rig import load_campaign, run_campaign

TARGET = 1e6


def rate(path: Path, repeats: int = 5) -> tuple[int, float]:
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        record = read_record(path)
        identify(record)
        best = min(best, time.perf_counter() - start)
    return record.time.size, best


def main() -> None:
    with tempfile.TemporaryDirectory() as folder:
        campaign_file = Path(folder) / "campaign.toml"
        campaign_file.write_text(
            '[grid]\nfrequencies = ["20Hz", "100Hz"]\nforce_amplitudes = ["1600N"]\n'
            '[[structures]]\nname = "joint-1"\nclearance = "0.106mm"\n'
        )
        manifest = run_campaign(load_campaign(campaign_file), Path(folder) / "out", jobs=1)
        files = sorted(manifest.parent.glob("*.nc"))
        brfd = (
            Path(sys.argv[1])
            if len(sys.argv) > 1
            else (Path(__file__).resolve().parents[2] / "shared" / "data" / "brfd")
        )
        if brfd.exists():
            files.append(brfd / "0.5Hz36lbtension1.5amplitude.json")
        for path in files:
            samples, seconds = rate(path)
            verdict = "meets" if samples / seconds >= TARGET else "below"
            print(
                f"{path.name:40s} {samples:6d} samples in {seconds * 1e3:6.1f} ms: "
                f"{samples / seconds:.3g} samples/s ({verdict} the target of {TARGET:.0e})"
            )


if __name__ == "__main__":
    main()
