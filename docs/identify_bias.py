"""Print the identification's errors on records of the independent simulator
(tests/independent_joint.py) at off-grid sampling rates and against the number of cycles.

    python docs/identify_bias.py --off-grid     # 40 Hz at 12 000/12 010/11 990/12 030 Hz, 37 Hz
    python docs/identify_bias.py --cycles       # 6, 10, 24 cycles at 40 Hz, 12 kHz
    python docs/identify_bias.py --brfd-residuals  # the damper fit residual / noise floor
    python docs/identify_bias.py --bouc-wen     # the same on a smooth loop with no gap

1 % noise on every channel, with an acceleration channel, seeds 1-5. Errors in % of the
simulator's own truth; the friction's standard error (in % of the truth) and its flag.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from independent_joint import TrueJoint, steady_truth, write_record  # noqa: E402

from clearjoint.identify import identify  # noqa: E402
from clearjoint.records import read_record  # noqa: E402

KEYS = (
    ("clearance_m", "clearance"),
    ("compression_stiffness_n_per_m", "k_c"),
    ("friction_force_n", "friction"),
    ("energy_per_cycle_j", "energy"),
)
SEEDS = (1, 2, 3, 4, 5)


def _row(label: str, frequency: float, rate: float, cycles: int, folder: Path) -> None:
    joint = TrueJoint(frequency_hz=frequency)
    truth = steady_truth(joint)
    for seed in SEEDS:
        path = write_record(
            joint, folder / f"{label}_{seed}.csv", noise=0.01, seed=seed, rate=rate, cycles=cycles
        )
        result = identify(read_record(path))
        s = result.summary
        errors = " | ".join(f"{100 * (s[k] / truth[k] - 1):+.2f}" for k, _ in KEYS)
        se = 100 * result.stderr["friction_force_n"] / truth["friction_force_n"]
        flag, reason = result.flags["friction_force_n"]
        print(f"| {label} | {seed} | {errors} | {se:.1f} | {flag}{_short(reason)} |", flush=True)


def _short(reason: str) -> str:
    """The flag's reason in a few words (the table's last column)."""
    if not reason:
        return ""
    if reason.startswith("fit residual"):
        return f" (residual {reason.split(' is ')[1].split(' times')[0]}x floor)"
    if "standard error" in reason:
        return f" (SE {reason.split('error of ')[1].split(' of')[0]})"
    return f" ({reason.split(':')[0]})"


def _brfd_residuals() -> None:
    """Each BRFD file's damper fit residual over its noise floor (flagged above 3)."""
    import re

    import clearjoint.identify.core as core
    from clearjoint.identify.cycles import IdentificationError

    factor = core.RESIDUAL_FACTOR
    core.RESIDUAL_FACTOR = 0.0  # every residual then shows in the reasons, with its ratio
    folder = Path(__file__).resolve().parents[2] / "shared" / "data" / "brfd"
    ratios = []
    for path in sorted(folder.glob("*.json")):
        try:
            result = identify(read_record(path))
        except IdentificationError:
            continue
        found = re.search(r"fit residual \S+ N is ([0-9.]+) times", result.flag_reason)
        if found:
            ratios.append((float(found.group(1)), path.name))
    core.RESIDUAL_FACTOR = factor
    for ratio, name in sorted(ratios):
        print(f"{ratio:4.1f}  {name}{'  (flagged)' if ratio > factor else ''}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--off-grid", action="store_true")
    parser.add_argument(
        "--cycles", nargs="*", type=int, default=None, help="numbers of cycles (6 10 24)"
    )
    parser.add_argument(
        "--brfd-residuals",
        action="store_true",
        help="each BRFD file's damper-model residual over its noise floor (../shared/data/brfd)",
    )
    parser.add_argument("--bouc-wen", action="store_true", help="Bouc-Wen loops, no gap")
    args = parser.parse_args()
    if args.bouc_wen:
        from test_identify_loopcheck import bouc_wen

        for noise, seed in ((0.0, 0), (0.01, 1), (0.01, 2), (0.01, 3), (0.01, 4)):
            result = identify(bouc_wen(noise, seed))
            print(f"noise {noise:.0%} seed {seed}: {result.model}, {result.flag_reason}")
    if args.brfd_residuals:
        _brfd_residuals()
    head = " | ".join(name for _, name in KEYS)
    folder = Path(tempfile.mkdtemp())
    if args.off_grid:
        print(f"| f (Hz) @ rate (samples a period) | seed | {head} | friction SE | flag |")
        print("|---|---|---|---|---|---|---|---|")
        for frequency, rate in ((40.0, 12_000.0), (40.0, 12_010.0), (40.0, 11_990.0),
                                (40.0, 12_030.0), (37.0, 12_000.0)):
            label = f"{frequency:g} @ {rate:g} ({rate / frequency:.2f})"
            _row(label, frequency, rate, 24, folder)
    if args.cycles is not None:
        print(f"| cycles | seed | {head} | friction SE | flag |")
        print("|---|---|---|---|---|---|---|---|")
        for cycles in args.cycles or (6, 10, 24):
            _row(str(cycles), 40.0, 12_000.0, cycles, folder)


if __name__ == "__main__":
    main()
