"""Print the identification's errors on records of the independent simulator
(tests/independent_joint.py) at off-grid sampling rates and against the number of cycles.

    python docs/identify_bias.py --off-grid     # 40 Hz at 12 000/12 010/11 990/12 030 Hz, 37 Hz
    python docs/identify_bias.py --cycles       # 6, 10, 24 cycles at 40 Hz, 12 kHz
    python docs/identify_bias.py --brfd-residuals  # the damper fit residual / noise floor
    python docs/identify_bias.py --bouc-wen     # the same on a smooth loop with no gap
    python docs/identify_bias.py --rig-residuals DIR  # every model's residual / noise floor
        # on the records of DIR (e.g. the default campaign: clearjoint rig --out DIR)
    python docs/identify_bias.py --floor [FILE ...]  # residual, floor, ratio, unsure signs
    python docs/identify_bias.py --csv-residuals DIR  # the same on DIR/*.csv
        # (e.g. examples/lab-csv, the tutorial's records)
    python docs/identify_bias.py --spread 6 10 16 24  # the friction over 40 noise draws:
        # its spread against the mean standard error reported (add --calibrated for the
        # regression-calibrated sign, erf(v / (sqrt 2 sigma_v)), tried and not kept)

1 % noise on every channel, with an acceleration channel, seeds 1-5. Errors in % of the
simulator's own truth; the friction's standard error (in % of the truth) and its flag.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path
from typing import Any

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


def _brfd_residuals(folder: Path | None = None, pattern: str = "*.json") -> None:
    """Each file's fit residual over its noise floor (flagged above 3): the BRFD files'
    damper fit by default, or the records of ``folder`` (any model), with the model."""
    import re

    import clearjoint.identify.core as core
    from clearjoint.identify.cycles import IdentificationError

    factor = core.RESIDUAL_FACTOR
    core.RESIDUAL_FACTOR = 0.0  # every residual then shows in the reasons, with its ratio
    if folder is None:
        folder = Path(__file__).resolve().parents[2] / "shared" / "data" / "brfd"
    ratios = []
    for path in sorted(folder.glob(pattern)):
        try:
            result = identify(read_record(path))
        except IdentificationError:
            continue
        found = re.search(r"fit residual \S+ N is ([0-9.]+) times", result.flag_reason)
        if found:
            ratios.append((float(found.group(1)), f"{path.name} ({result.model})"))
    core.RESIDUAL_FACTOR = factor
    for ratio, name in sorted(ratios):
        print(f"{ratio:4.1f}  {name}{'  (flagged)' if ratio > factor else ''}")


def _bouc_wen_forced(bouc_wen: Any) -> None:
    """The Bouc-Wen loops forced into the line's fit (no damper), into the joint's
    sample-by-sample fit (stage windows at 70-100 % of the stroke each way and the middle
    half, the weak form held off) and into the weak form (the same windows), as
    tests/test_identify_loopcheck.py forces them."""
    import numpy as np

    import clearjoint.identify.core as core

    saved = {
        k: getattr(core, k) for k in ("_damper_fit", "_windows", "_joint_fit", "MIN_EQUATIONS")
    }
    fit = core._joint_fit

    def windows(x: Any, y: Any, n: int) -> list[tuple[bool, float, float]]:
        a, m = 0.5 * float(np.ptp(x)), 0.5 * float(x.max() + x.min())
        return [
            (True, m - a, m - 0.7 * a),
            (False, m - 0.5 * a, m + 0.5 * a),
            (True, m + 0.7 * a, m + a),
        ]

    try:
        core._damper_fit = lambda *args: None  # type: ignore[assignment]
        for path in ("line", "joint", "weak form"):
            if path != "line":
                core._windows = windows  # type: ignore[assignment]
                core._joint_fit = lambda x, r, v, p, w, compete=True: fit(x, r, v, p, w, False)  # type: ignore[assignment]
                core.MIN_EQUATIONS = 10**9 if path == "joint" else saved["MIN_EQUATIONS"]
            for noise, seed in ((0.0, 0), (0.01, 1), (0.01, 2), (0.01, 3), (0.01, 4)):
                result = identify(bouc_wen(noise, seed))
                reason = result.flags["friction_force_n"][1]
                head = f"forced into the {path} fit, noise {noise:.0%} seed {seed}"
                print(f"{head}: {result.model}, {reason}")
    finally:
        for k, v in saved.items():
            setattr(core, k, v)


def _floor(paths: list[Path], folder: Path) -> None:
    """Each record's fit residual against its errors-in-variables noise floor, with the
    noise of each channel and the share of toss-up velocity signs: the given records, or
    the independent simulator's (1 % noise, 24 cycles, seeds 0-2; 0 and 0.2 % at 12
    cycles; 6-24 cycles at 40 Hz, seeds 1-5) with the friction's error."""
    import clearjoint.identify.core as core

    seen: list[Any] = []
    flags = core._flags

    def spy(model: str, summary: Any, stderr: Any, residual: Any, *rest: Any) -> Any:
        seen.append(residual)
        return flags(model, summary, stderr, residual, *rest)

    def show(label: str, path: Path, truth: dict[str, float] | None) -> None:
        seen.clear()
        result = identify(read_record(path))
        r = seen[0]
        miss = ""
        if truth is not None:
            error = 100 * (result.summary["friction_force_n"] / truth["friction_force_n"] - 1)
            se = 100 * result.stderr["friction_force_n"] / truth["friction_force_n"]
            miss = f"  friction {error:+.1f} ± {se:.1f} %"
        print(
            f"{label}: {result.model}, residual {r.residual:.3g} N, floor {r.floor:.3g} N, "
            f"ratio {r.ratio:.2f}, unsure signs {r.unsure:.0%}{miss}",
            flush=True,
        )

    core._flags = spy  # type: ignore[assignment]
    try:
        for path in paths:
            show(path.name, path, None)
        if paths:
            return
        runs = [
            (f, acc, noise, 24, seed)
            for f in (40.0, 100.0)
            for acc in (True, False)
            for seed in (0, 1, 2)
            for noise in (0.01,)
        ]
        runs += [
            (f, True, noise, 12, seed)
            for f in (40.0, 100.0)
            for noise in (0.0, 0.002)
            for seed in (1, 2)
        ]
        runs += [(40.0, True, 0.01, n, seed) for n in (6, 10, 16, 24) for seed in SEEDS]
        for f, acc, noise, cycles, seed in runs:
            joint = TrueJoint(frequency_hz=f)
            path = write_record(
                joint, folder / "r.csv", noise=noise, acceleration=acc, seed=seed, cycles=cycles
            )
            label = f"{f:g} Hz, acceleration {acc}, noise {noise:.1%}, {cycles} cycles, seed {seed}"
            show(label, path, steady_truth(joint))
    finally:
        core._flags = flags  # type: ignore[assignment]


def _spread(counts: list[int], draws: int, calibrated: bool, folder: Path) -> None:
    """The friction of one independent record (40 Hz, 12 kHz, 1 % noise on every channel,
    with acceleration) over ``draws`` noise seeds (1000, 1001, ...) at each number of
    cycles: mean error, spread (standard deviation over the draws), rms of the standard
    errors reported, their ratio, the share of draws more than 2 standard errors off and
    the share flagged; all in % of the truth."""
    import math

    import numpy as np

    from clearjoint.identify import weak

    own = getattr(weak.WeakSystem, "friction_of", None)  # None: an older src, run as it is
    if calibrated:
        from scipy.special import erf

        from clearjoint.identify.loopcheck import jackknife_noise

        def friction_of(self: Any, velocity: Any) -> Any:
            sigma = jackknife_noise(velocity)  # the replicates' spread: the average's noise
            return self.integrals(erf(velocity / (math.sqrt(2.0) * sigma)), self.phi)

        weak.WeakSystem.friction_of = friction_of  # type: ignore[method-assign]
    joint = TrueJoint(frequency_hz=40.0)
    truth = steady_truth(joint)["friction_force_n"]
    print(
        "| cycles | draws | mean error | spread | rms SE | spread / rms SE | > 2 SE off | flagged |"
    )
    print("|---|---|---|---|---|---|---|---|")
    try:
        for cycles in counts:
            est, se, flagged = [], [], 0
            for seed in range(1000, 1000 + draws):
                path = write_record(joint, folder / "s.csv", noise=0.01, seed=seed, cycles=cycles)
                result = identify(read_record(path))
                est.append(result.summary["friction_force_n"])
                se.append(result.stderr["friction_force_n"])
                flagged += result.flags["friction_force_n"][0] != "ok"
            e, s = np.array(est), np.array(se)
            spread = float(np.std(e, ddof=1))
            rms = float(np.sqrt(np.mean(s**2)))
            off = float(np.mean(np.abs(e - truth) > 2.0 * s))
            print(
                f"| {cycles} | {draws} | {100 * (e.mean() / truth - 1):+.1f} | "
                f"{100 * spread / truth:.1f} | {100 * rms / truth:.1f} | {spread / rms:.2f} | "
                f"{off:.0%} | {flagged / draws:.0%} |",
                flush=True,
            )
    finally:
        if own is not None:
            weak.WeakSystem.friction_of = own  # type: ignore[method-assign]


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
    parser.add_argument(
        "--rig-residuals", type=Path, default=None, help="each rig record's (*.nc) residual"
    )
    parser.add_argument(
        "--csv-residuals", type=Path, default=None, help="each CSV record's (*.csv) residual"
    )
    parser.add_argument(
        "--floor",
        nargs="*",
        type=Path,
        default=None,
        help="each record's residual, floor and ratio (the simulator's without files)",
    )
    parser.add_argument(
        "--spread",
        nargs="*",
        type=int,
        default=None,
        help="numbers of cycles (6 10 16 24): the friction's spread over noise draws",
    )
    parser.add_argument("--draws", type=int, default=40, help="noise draws for --spread")
    parser.add_argument("--calibrated", action="store_true", help="--spread, erf sign")
    args = parser.parse_args()
    if args.spread is not None:
        _spread(
            args.spread or [6, 10, 16, 24], args.draws, args.calibrated, Path(tempfile.mkdtemp())
        )
    if args.floor is not None:
        _floor(args.floor, Path(tempfile.mkdtemp()))
    if args.bouc_wen:
        from test_identify_loopcheck import bouc_wen

        for noise, seed in ((0.0, 0), (0.01, 1), (0.01, 2), (0.01, 3), (0.01, 4)):
            result = identify(bouc_wen(noise, seed))
            print(f"noise {noise:.0%} seed {seed}: {result.model}, {result.flag_reason}")
        _bouc_wen_forced(bouc_wen)
    if args.brfd_residuals:
        _brfd_residuals()
    if args.rig_residuals is not None:
        _brfd_residuals(args.rig_residuals, "*.nc")
    if args.csv_residuals is not None:
        _brfd_residuals(args.csv_residuals, "*.csv")
    head = " | ".join(name for _, name in KEYS)
    folder = Path(tempfile.mkdtemp())
    if args.off_grid:
        print(f"| f (Hz) @ rate (samples a period) | seed | {head} | friction SE | flag |")
        print("|---|---|---|---|---|---|---|---|")
        for frequency, rate in (
            (40.0, 12_000.0),
            (40.0, 12_010.0),
            (40.0, 11_990.0),
            (40.0, 12_030.0),
            (37.0, 12_000.0),
        ):
            label = f"{frequency:g} @ {rate:g} ({rate / frequency:.2f})"
            _row(label, frequency, rate, 24, folder)
    if args.cycles is not None:
        print(f"| cycles | seed | {head} | friction SE | flag |")
        print("|---|---|---|---|---|---|---|---|")
        for cycles in args.cycles or (6, 10, 24):
            _row(str(cycles), 40.0, 12_000.0, cycles, folder)


if __name__ == "__main__":
    main()
