"""The BRFD table of docs/identify.md: every file of the shared data set, identified.

Run from the repository's root: ``python docs/identify_brfd.py [BRFD_FOLDER]`` (default
../shared/data/brfd beside the repository). Data: D. Coble, P. Huggins, L. Cao, J. Ricles,
A. Downey, "Dataset-Friction-Damper-with-Backlash", GitHub, ARTS-Laboratory, 2022
(CC BY-SA 4.0).

Checks, per the issue: every file a damper loop or refused with its reason; the backlash
within 15 % of the median of the accepted tests at the same band tension; the loop energy
within 15 % of the elastic-plastic-with-gap estimate 2 F_f (2X - b - 2 F_f / k).

The table's "b before" column is the estimator this one replaced (the sum of the level-crossing
steps longer than two elastic steps, :func:`previous_backlash`), on the same cycle average.

``python docs/identify_brfd.py --diagnose [BRFD_FOLDER]`` prints instead, for every file, the
backlash read on each branch and the level of the step (what the damper estimator fits,
:mod:`clearjoint.identify.damper`), then the medians and the misses under other choices:
the number of crossings N (a resolution), and the variant tried and not adopted (the slope
fitted with the step by least absolute deviations, not read from the median step); then, per
file, the evidence on why two branches of one loop can read different gaps (:func:`evidence`:
the four explanations examined in docs/identify.md, each with its number); last, the CPU time
of the damper estimator per cycle average.
"""

from __future__ import annotations

import json
import re
import sys
import time
from pathlib import Path
from typing import NamedTuple

import numpy as np

from clearjoint.identify import damper, identify_files
from clearjoint.identify.cycles import cycle_bounds, excitation_frequency, stack, steady
from clearjoint.records import read_record

ROOT = Path(__file__).resolve().parents[1]


def _parts(x: np.ndarray) -> tuple[slice, slice]:
    top = int(np.argmax(x))
    return slice(0, top + 1), slice(top, x.size)


def _levels(x: np.ndarray, f: np.ndarray) -> tuple[tuple[slice, slice], float, float]:
    parts = _parts(x)
    levels = []
    for part in parts:
        travel = np.abs(x[part] - x[part][0])
        levels.append(float(np.median(f[part][travel >= (1 - damper.PLATEAU) * travel[-1]])))
    return parts, levels[0], levels[1]


def previous_backlash(x: np.ndarray, f: np.ndarray) -> float:
    """The estimator before this one: on each branch, the first crossings of 17 levels
    (10 % ... 90 % of the level change); b is what the steps longer than two median steps
    hold beyond one median step; the mean of the two branches."""
    parts, rise, fall = _levels(x, f)
    alphas = np.linspace(0.1, 0.9, 17)
    out = []
    for part, start, stop in ((parts[0], fall, rise), (parts[1], rise, fall)):
        travel, fb = np.abs(x[part] - x[part][0]), f[part]
        reached = np.maximum.accumulate(np.sign(stop - start) * (fb - start) / abs(stop - start))
        s = np.interp(alphas, reached, travel)  # the running maximum is non-decreasing
        steps = np.diff(s)
        excess = steps - np.median(steps)
        out.append(float(np.sum(excess[excess > np.median(steps)])))
    return 0.5 * sum(out)


def _set_resolution(n: int) -> None:
    """Read n crossings per branch in :mod:`clearjoint.identify.damper` (for --diagnose)."""
    damper.N_CROSSINGS = n
    damper.ALPHAS = (np.arange(n) + 0.5) / n
    damper._PLACES = np.arange(2, n - 1)
    damper._BEFORE = np.arange(n)[None, :] < damper._PLACES[:, None]


def _fitted_slope_backlash(x: np.ndarray, f: np.ndarray) -> float:
    """The variant not adopted: slope, place and step all by least absolute deviations
    (the slope on a fine grid about the median step's, 0.25 to 4 times it)."""
    out = []
    for branch in _branches(x, f):  # the crossings the adopted estimator reads
        s = branch.s
        d0 = float(np.median(np.diff(s))) * damper.N_CROSSINGS
        best = (np.inf, 0.0)
        for d in d0 * np.geomspace(0.25, 4.0, 241):
            r = s - d * damper.ALPHAS
            j = int(damper._PLACES[damper._best_place(r)])
            lo, hi = np.median(r[:j]), np.median(r[j:])
            loss = float(np.abs(r[:j] - lo).sum() + np.abs(r[j:] - hi).sum())
            if loss < best[0]:
                best = (loss, float(hi - lo))
        out.append(max(best[1], 0.0))
    return 0.5 * sum(out)


def _misses(b: dict[str, float], tension: dict[str, int]) -> str:
    median = {t: float(np.median([b[k] for k in b if tension[k] == t])) for t in (0, 30, 36)}
    miss = {k: b[k] / median[tension[k]] - 1 for k in b}
    out = {k: v for k, v in miss.items() if abs(v) > 0.15}
    return (
        "medians (mm) "
        + ", ".join(f"{t} lb {1e3 * m:.2f}" for t, m in median.items())
        + f"; {len(out)} miss"
        + (": " + ", ".join(f"{k} {v:+.0%}" for k, v in sorted(out.items())) if out else "")
    )


#: Newtons per pound-force (the BRFD's actuator forces are in lb).
LBF = 4.4482216152605


def _cycles(path: Path) -> dict[str, np.ndarray] | None:
    """Each steady cycle's displacement, friction force and the two actuator forces
    ("x", "f", "act1", "act2"; N, (n, M)), stacked as :func:`clearjoint.identify.identify`
    stacks them (from the minimum of the average), and "step" (the time step, s); None when
    the record has too few steady cycles. The actuator forces are read from the JSON here:
    the identification does not use them."""
    record = read_record(path)
    frequency = excitation_frequency(record)
    bounds = cycle_bounds(record, frequency)
    kept = steady(record.displacement, bounds, 0.03)
    if len(kept) < 3:
        return None
    st = stack(record, frequency, bounds, kept, {"x": record.displacement})
    shift = int(np.argmin(st.channels["x"].mean(axis=0)))
    if shift > st.samples // 2 and bounds[kept[0]][0] - (st.samples - shift) >= 0:
        shift -= st.samples
    content = json.loads(path.read_bytes())
    assert content.get("actuator force units", "lb") == "lb"
    data = np.asarray(content["data"], dtype=np.float64)
    channels = {
        "x": record.displacement,
        "f": record.force,
        "act1": data[:, 4] * LBF,
        "act2": data[:, 5] * LBF,
    }
    st = stack(record, frequency, bounds, kept, channels, shift)
    return {**st.channels, "step": np.array(st.step)}


class _Branch(NamedTuple):
    """One branch of a loop as the damper estimator reads it."""

    travel: np.ndarray  # travel from the reversal, m
    f: np.ndarray  # force, N
    s: np.ndarray  # the crossings, m
    c: float  # the lower line's intercept, m
    d: float  # the lines' slope, m per unit alpha
    b: float  # the backlash, m
    j: int  # the step lies between crossings j - 1 and j
    start: float  # the level before (N)
    stop: float  # the level after (N)

    @property
    def alpha_b(self) -> float:
        return float(0.5 * (damper.ALPHAS[self.j - 1] + damper.ALPHAS[self.j]))

    @property
    def level(self) -> float:
        """The backlash level, N."""
        return self.start + self.alpha_b * (self.stop - self.start)


def _branches(x: np.ndarray, f: np.ndarray) -> tuple[_Branch, _Branch]:
    """The rising and the falling branch of a cycle (average) x, f (M,)."""
    parts, rise, fall = _levels(x, f)
    out = []
    for part, start, stop in ((parts[0], fall, rise), (parts[1], rise, fall)):
        travel, fb = np.abs(x[part] - x[part][0]), f[part]
        s = damper._crossings(travel, fb, start, stop)
        assert s is not None
        out.append(_Branch(travel, fb, s, *damper._step_fit(s), start, stop))
    return out[0], out[1]


def _own_slopes(branch: _Branch) -> tuple[float, float]:
    """The backlash with each line's own slope (the median step on its side of the step
    place), read as the distance between the lines at the step's level, and the loading
    line's stiffness over the unloading line's."""
    a, n = damper.ALPHAS, damper.N_CROSSINGS
    lines, steps = [], []
    for part in (slice(0, branch.j), slice(branch.j, n)):
        d = float(np.median(np.diff(branch.s[part]))) * n
        c = float(np.median(branch.s[part] - d * a[part]))
        lines.append(c + d * branch.alpha_b)
        steps.append(d)
    return lines[1] - lines[0], steps[0] / steps[1]


def _left_early(branch: _Branch, other: float) -> float:
    """The part of the way from the backlash level (alpha_b) to the new slip level that the
    force covers within the first half of the gap, taking the gap as long as ``other`` (the
    other branch's reading) from the end of the unloading: 0 for a flat backlash level, 1
    when the force reaches the new level there."""
    gap_start = max(branch.c + branch.d * branch.alpha_b, 0.0)
    window = (branch.travel >= gap_start) & (branch.travel <= gap_start + 0.5 * other)
    delta = branch.stop - branch.start
    progress = np.sign(delta) * (branch.f[window] - branch.start) / abs(delta)
    return float((progress.max() - branch.alpha_b) / (1.0 - branch.alpha_b))


def _delays(x: np.ndarray, f: np.ndarray, step: float) -> tuple[str, str]:
    """The two branches' readings with the force delayed by -16 and +16 ms (whole samples,
    circular on the cycle average), and the delays within +-40 ms at which the two readings
    cross (ms; "none")."""
    ks = np.arange(-round(0.04 / step), round(0.04 / step) + 1)
    diff, at = [], {}
    for k in ks:
        rising, falling = _branches(x, np.roll(f, k))
        diff.append(rising.b - falling.b)
        at[int(k)] = f"{1e3 * rising.b:.1f}/{1e3 * falling.b:.1f}"
    change = np.nonzero(np.diff(np.sign(diff)) != 0)[0]
    k16 = round(0.016 / step)
    return (
        f"{at[-k16]} {at[k16]}",
        ",".join(f"{1e3 * ks[i] * step:.0f}" for i in change) or "none",
    )


def _actuator_gap(branch: _Branch, load: np.ndarray) -> float:
    """Travel from the end of the friction force's unloading (this branch's gap start) to
    where the actuator force that loads on this branch (``load``, (M,) over the branch) is
    first halfway from its level over the first millimetre of the gap to its level over the
    branch's last 40 % (its slip level): the contact as that channel sees it, m."""
    gap_start = max(branch.c + branch.d * branch.alpha_b, 0.0)
    travel = branch.travel
    base = float(np.median(load[(travel >= gap_start) & (travel <= gap_start + 1e-3)]))
    plateau = float(np.median(load[travel >= (1.0 - damper.PLATEAU) * travel[-1]]))
    past = np.nonzero(
        (travel > gap_start)
        & (np.sign(plateau - base) * (load - base) >= 0.5 * abs(plateau - base))
    )[0]
    return float(travel[past[0]] - gap_start) if past.size else float("nan")


def evidence(folder: Path) -> None:
    """Print, per accepted file, the numbers behind docs/identify.md's account of why two
    branches of one loop read different gaps, one explanation a field: the per-cycle
    readings and cycle means (cycles not steady?), each line's own slope (a softer
    loading?), a delay of the force (a lag between the channels?), the backlash level and
    how far the force leaves it early (the force in the gap?), and where the actuator force
    sees the contact. Then the crossings of every branch that reads less than half the
    other (the rule of the "not one gap" flag)."""
    print(
        "\nwhy branches differ, rising / falling branch: per-cycle b (mm) | cycle mean x (mm)"
        " | own slopes: b (mm), k after / k before the gap | force delayed -16 ms, +16 ms: b"
        " (mm); delays (ms) at which the branches read the same | backlash level (kN) | left"
        " early | actuator load's mid-rise after the unloading (mm)"
    )
    early: dict[str, float] = {}
    short: list[tuple[str, _Branch]] = []
    for path in sorted(folder.glob("*.json")):
        cycles = _cycles(path)
        if cycles is None:
            continue
        xs, fs, step = cycles["x"], cycles["f"], float(cycles["step"])
        per = [_branches(xx, ff) for xx, ff in zip(xs, fs, strict=True)]
        x, f = xs.mean(axis=0), fs.mean(axis=0)
        rising, falling = _branches(x, f)
        parts = _parts(x)
        # actuator 2 loads on the rising branch, actuator 1 on the falling one
        act = (
            _actuator_gap(rising, cycles["act2"].mean(axis=0)[parts[0]]),
            _actuator_gap(falling, cycles["act1"].mean(axis=0)[parts[1]]),
        )
        left = (_left_early(rising, falling.b), _left_early(falling, rising.b))
        early[path.stem] = max(left)
        own = (_own_slopes(rising), _own_slopes(falling))
        shifted, equal = _delays(x, f, step)
        for name, mine, other in (("rising", rising, falling), ("falling", falling, rising)):
            if other.b > damper.BRANCH_RATIO * mine.b:
                short.append((f"{path.stem} {name}", mine))
        cycle_b = " ".join(f"{1e3 * p[0].b:.1f}" for p in per) + " / "
        cycle_b += " ".join(f"{1e3 * p[1].b:.1f}" for p in per)
        print(
            f"  {path.stem}: {cycle_b} | "
            + " ".join(f"{1e3 * float(np.mean(xx)):.2f}" for xx in xs)
            + f" | {1e3 * own[0][0]:.2f} / {1e3 * own[1][0]:.2f}, "
            f"{own[0][1]:.2f} / {own[1][1]:.2f} | {shifted}; {equal}"
            f" | {rising.level / 1e3:+.2f} / {falling.level / 1e3:+.2f}"
            f" | {left[0]:.2f} / {left[1]:.2f} | {1e3 * act[0]:.2f} / {1e3 * act[1]:.2f}"
        )
    ranked = sorted(early.items(), key=lambda kv: -kv[1])
    top = ", ".join(f"{k} {v:.2f}" for k, v in ranked[:4])
    print(f"largest 'left early' (either branch): {top}")
    for name, branch in short:
        gap_start = max(branch.c + branch.d * branch.alpha_b, 0.0)
        print(
            f"{name} branch, the gap from {1e3 * gap_start:.2f} mm, crossings from alpha_b "
            "(alpha: travel mm): "
            + " ".join(
                f"{a:.2f}: {1e3 * t:.2f}"
                for a, t in zip(damper.ALPHAS[branch.j :], branch.s[branch.j :], strict=True)
            )
        )


def diagnose(results: list[tuple[object, object]]) -> None:
    loops = {Path(i.source).stem: i.loop for _, i in results}  # type: ignore[attr-defined]
    tension = {k: int(re.search(r"(\d+)lbtension", k)[1]) for k in loops}  # type: ignore[index]
    print("file: backlash rising / falling branch (mm), step level alpha_b rising / falling")
    for k, (x, f) in loops.items():
        fit = damper._damper_fit(x, f, _parts(x))
        assert fit is not None
        _, rise, fall = _levels(x, f)
        places = []
        for part, start, stop in ((_parts(x)[0], fall, rise), (_parts(x)[1], rise, fall)):
            s = damper._crossings(np.abs(x[part] - x[part][0]), f[part], start, stop)
            assert s is not None
            places.append(damper.ALPHAS[damper._step_fit(s)[3]] - 0.5 / damper.N_CROSSINGS)
        b_rise, b_fall = fit.backlash_branches
        print(
            f"  {k}: {1e3 * b_rise:.2f} / {1e3 * b_fall:.2f}, "
            f"alpha_b {places[0]:.2f} / {places[1]:.2f}"
        )
    before = {k: previous_backlash(*loop) for k, loop in loops.items()}
    print(f"\nthe estimator before: {_misses(before, tension)}")
    for n in (24, 32, 48, 64, 96):
        _set_resolution(n)
        b = {}
        for k, (x, f) in loops.items():
            fit = damper._damper_fit(x, f, _parts(x))
            assert fit is not None
            b[k] = 0.5 * sum(fit.backlash_branches)
        print(f"N = {n} crossings: {_misses(b, tension)}")
    _set_resolution(48)
    fitted = {k: _fitted_slope_backlash(*loop) for k, loop in loops.items()}
    print(f"variant, slope fitted too (N = 48): {_misses(fitted, tension)}")
    evidence(Path(next(iter(results))[1].source).parent)  # type: ignore[attr-defined]
    # the estimator's cost: one call per cycle average (each file: the model choice and
    # one per jackknife replicate)
    start = time.process_time()
    for _ in range(5):
        for x, f in loops.values():
            damper._damper_fit(x, f, _parts(x))
    cost = (time.process_time() - start) / (5 * len(loops))
    print(f"CPU time of damper._damper_fit per cycle average: {1e3 * cost:.2f} ms")


def main() -> None:
    args = [a for a in sys.argv[1:] if a != "--diagnose"]
    folder = Path(args[0]) if args else ROOT.parent / "shared" / "data" / "brfd"
    files = sorted(folder.glob("*.json"))
    if not files:  # a table of nothing would read as "0 outside 15 %"
        sys.exit(f"no BRFD records (*.json) in {folder}: pass the folder as the first argument")
    results, failures = identify_files([str(p) for p in files])
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
    before = {r[0]: previous_backlash(*r[2].loop) for r in rows}
    median_before = {
        t: float(np.median([before[r[0]] for r in rows if r[1] == t])) for t in (0, 30, 36)
    }
    print(
        "| file | model | cycles | backlash b (mm) | b / median | b before (mm) | before / median "
        "| F+ / F- (kN) | k (MN/m) | X (mm) | E (J) | E / 2F_f(2X-b-2F_f/k) | flag |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    misses_b = misses_e = 0
    for name, t, ident, s, e, k, estimate in rows:
        rb = s["clearance_m"] / median[t]
        re_ = s["energy_per_cycle_j"] / estimate
        misses_b += abs(rb - 1) > 0.15
        misses_e += abs(re_ - 1) > 0.15
        print(
            f"| {name} | {ident.model} | {ident.cycles_used}/{ident.cycles_total} "
            f"| {1e3 * s['clearance_m']:.2f} ± {1e3 * e['clearance_m']:.2f} | {rb:.2f} "
            f"| {1e3 * before[name]:.2f} | {before[name] / median_before[t]:.2f} "
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
