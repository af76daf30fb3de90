"""The structure solver against solve_ivp, side by side, and its cost with the mast's size.

Run on demand::

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_structure.py [--mast-periods 200]
        [--ivp-periods 2] [--bays 5,10,20,40] [--scaling-periods 5]

(one BLAS thread: the matrices are small, and threads fight over a shared machine.)
Times are CPU seconds of this process (``time.process_time``; both solvers run on one
thread), which other jobs on a shared machine disturb far less than the wall clock; the
wall clock of section 2 is printed beside them.

0. Issue 24: examples/mast.toml (10 bays, 20 joints, 20 N at n21x, 15 Hz) over
   ``--issue-periods`` (10, about 9,000 events): the exact solver (best of
   ``--issue-rounds``) against solve_ivp (DOP853, rtol 1e-9, atol 1e-15, restarted at every
   gap-edge event) over the same span; then the issue's 5-mass chain (rattling) at 2, 20,
   39.66 and 60 Hz: CPU ms per forcing period and events per period, and from them an
   estimate of its 300-frequency stepped-sine diagram. Only with ``--issue24``, alone (the
   default run keeps sections 1-5, which ``side_by_side.py`` times across checkouts)::

       OPENBLAS_NUM_THREADS=1 python benchmarks/bench_structure.py --issue24

1. Accuracy: a 3-link chain with 2 joints (asymmetric, k0 > 0, off-centre gaps, restitution
   on the rigid link) against scipy's solve_ivp (DOP853, rtol 1e-12, an event on every gap
   edge), 20 forcing periods: largest difference relative to the largest motion.
2. Speed: the 10-bay mast with 20 hinge joints forced at its tip near its first closed
   mode: the exact solver over ``--mast-periods`` periods (events per second) and
   solve_ivp (rtol 1e-12, edge events) over the first ``--ivp-periods`` of them, timed in
   the same run; the ratio is per forcing period. Over that common span both are also
   compared with solve_ivp at rtol 1e-13 (largest difference and at its end), which says
   whose error is whose.
3. Cost against the number of bays (``--bays``): seconds and events per forcing period
   over ``--scaling-periods`` periods.
4. The docs' free decay of the mast run with three step sequences (base step T_min / 8,
   / 5, / 16): how many events they share, how far apart they end, the backbone's first
   cycle.
5. Linear checks: a uniform fixed-free bar's first modes against
   (2k - 1) (pi / 2L) sqrt(E / rho) as n grows; a two-mass chain against its closed form.

``--old-src DIR`` (issue 23: "within 5 % of before, side by side") runs none of that: it
times the speed workloads, section 2's mast over ``--mast-periods``, section 3's masts of
``--bays`` over ``--scaling-periods``, section 4's free decay (default base step) over
``--decay-periods``, and section 0's mast.toml over 10 periods and chain over 100 periods at
20 and 39.66 Hz, with the clearjoint of another ``src`` tree and with this one, each in
a fresh child process (PYTHONPATH, OPENBLAS_NUM_THREADS=1) that warms up (imports, numba's
compilation or cache) before it times, alternating old, new, ... ``--rounds`` times. Each
child builds every case anew and reports CPU seconds (``time.process_time``) per workload;
printed are the best and the median over the rounds and new / old. The child runs this
file, so the other tree needs the public names it imports (b1c5d4f has them)::

    python benchmarks/bench_structure.py --old-src /work/wt-old/src [--rounds 5]
        [--mast-periods 200] [--bays 5,10,20,40] [--scaling-periods 5] [--decay-periods 80]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from clearjoint import ClearanceJoint
from clearjoint.structure import (
    Member,
    Structure,
    chain,
    decay_backbone,
    free_decay,
    mast,
    time_response,
)
from clearjoint.structure import motion as motion_module
from clearjoint.structure.reference import reference_response
from clearjoint.structure.study import load_structure_study


def _three_links() -> Structure:
    hit = ClearanceJoint(
        1e-4, 8e7, tension_stiffness=3e7, gap_stiffness=1e6, gap_offset=2e-5, restitution=0.7
    )
    series = ClearanceJoint(1.5e-4, 5e7, tension_stiffness=9e7, gap_stiffness=2e6, gap_offset=-4e-5)
    return chain(
        [2.0, 1.5, 1.0], [math.inf, 6e7, 4e7], [hit, series, None], dampers=[50.0, 30.0, 20.0]
    )


def _side_by_side(s: Structure, force: np.ndarray, omega: float, periods: int) -> None:
    duration = periods * 2.0 * math.pi / omega
    start = time.process_time()
    mine = time_response(s, force, omega, duration, samples_per_period=32)
    t_mine = time.process_time() - start
    start = time.process_time()
    u, v, events = reference_response(s, force, omega, mine.t)
    t_ivp = time.process_time() - start
    du = np.max(np.abs(mine.u - u)) / np.max(np.abs(u))
    dv = np.max(np.abs(mine.v - v)) / np.max(np.abs(v))
    print(
        f"  exact {t_mine:8.2f} s, solve_ivp {t_ivp:8.2f} s, ratio {t_ivp / t_mine:6.2f}x; "
        f"events {mine.events} / {events}; max |du|/max|u| = {du:.2e}, |dv| = {dv:.2e}; "
        f"ledger balance {mine.balance_error:.1e}"
    )


def _mast_case(bays: int) -> tuple[Structure, np.ndarray, float]:
    hinge = ClearanceJoint(50e-6, 5e7, gap_stiffness=1e5)
    s = mast(bays, joints=hinge, rayleigh=(0.0, 2e-6))
    force = np.zeros(s.n_dof)
    force[-2] = 20.0  # the top left node, sideways
    omega = 0.9 * float(s.modes("closed").omega[0])
    return s, force, omega


def _decay_case() -> tuple[Structure, np.ndarray, float, int]:
    """The docs' damped 10-bay mast, its first closed mode at 3 mm of tip: (mast, u0, T, tip)."""
    hinge = ClearanceJoint(50e-6, 5e7, gap_stiffness=1e5)
    tower = mast(10, joints=hinge, rayleigh=(0.5, 2e-6))
    closed = tower.modes("closed")
    tip = tower.dof_names.index("n21x")
    u0 = 3e-3 * closed.shapes[:, 0] / closed.shapes[tip, 0]
    return tower, u0, 2 * math.pi / float(closed.omega[0]), tip


def _study_mast() -> tuple[Structure, np.ndarray, float]:
    """examples/mast.toml as it stands: the 10-bay mast, 20 N at n21x, 15 Hz."""
    study = load_structure_study(Path(__file__).resolve().parents[1] / "examples" / "mast.toml")
    assert study.force is not None
    assert study.omega is not None
    return study.structure, study.force, study.omega


def _rattling_chain() -> tuple[Structure, np.ndarray]:
    """Issue 24's 5-mass chain: 0.5 kg, joints +-0.1 mm, 4e5 N/m, k0 2e4 N/m, 2 N s/m, 30 N."""
    joint = ClearanceJoint(1e-4, 4e5, gap_stiffness=2e4)
    s = chain([0.5] * 5, [math.inf] * 5, [joint] * 5, dampers=[2.0] * 5)
    force = np.zeros(5)
    force[-1] = 30.0
    return s, force


def _chain_cost(hz: float, periods: int, rounds: int) -> tuple[float, float]:
    """CPU seconds per forcing period (best of ``rounds``) and events per period at ``hz``."""
    s, force = _rattling_chain()
    omega = 2.0 * math.pi * hz
    time_response(s, force, omega, 0.1 / hz, samples_per_period=16)  # warm up
    spent = math.inf
    for _ in range(rounds):
        start = time.process_time()
        motion = time_response(s, force, omega, periods / hz, samples_per_period=16)
        spent = min(spent, time.process_time() - start)
    return spent / periods, motion.events / periods


def issue24(args: argparse.Namespace) -> None:
    """Issue 24, item 5: examples/mast.toml over 10 periods against solve_ivp (rtol 1e-9)."""
    s, force, omega = _study_mast()
    periods = args.issue_periods
    duration = periods * 2.0 * math.pi / omega
    time_response(s, force, omega, 0.05 * 2.0 * math.pi / omega)  # compile (cached), warm up
    spent = []
    for _ in range(args.issue_rounds):  # the best of a few: other jobs only ever add time
        start = time.process_time()
        motion = time_response(s, force, omega, duration, samples_per_period=16)
        spent.append(time.process_time() - start)
    t_mine = min(spent)
    start = time.process_time()
    u_ivp, _, events_ivp = reference_response(s, force, omega, motion.t, rtol=1e-9)
    t_ivp = time.process_time() - start
    print(
        f"  exact: {t_mine:.3f} s (best of {args.issue_rounds}; median "
        f"{statistics.median(spent):.3f} s), {motion.events} events, {motion.steps} steps "
        f"({t_mine / motion.events * 1e6:.1f} us per event), ledger {motion.balance_error:.0e}"
    )
    print(
        f"  solve_ivp DOP853 rtol 1e-9 (atol 1e-15), restarted at each of its {events_ivp} "
        f"edge events: {t_ivp:.2f} s; ratio {t_ivp / t_mine:.0f}x "
        f"(load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores)"
    )
    scale = np.max(np.abs(motion.u))
    apart = [np.max(np.abs(motion.u[16 * k] - u_ivp[16 * k])) / scale for k in (1, 2, periods - 1)]
    print(
        f"  exact vs solve_ivp, largest difference of u / largest motion after 1, 2 and "
        f"{periods - 1} periods: {apart[0]:.0e}, {apart[1]:.0e}, {apart[2]:.0e} (a rattling "
        "motion amplifies any difference; section 2 says whose error is whose)"
    )
    print("  the 5-mass chain of issue 24 (rattling): CPU per forcing period, best of the rounds")
    cost = {}
    for hz in (2.0, 20.0, 39.66, 60.0):
        per, events = _chain_cost(hz, max(2, round(args.chain_seconds * hz)), args.issue_rounds)
        cost[hz] = per * hz  # CPU s per second of motion
        print(
            f"    {hz:6.2f} Hz: {per * 1e3:7.3f} ms per period, {events:6.1f} events per "
            f"period ({per / max(events, 1e-300) * 1e6:6.1f} us per event if events dominate)"
        )
    # the diagram (300 frequencies 2-60 Hz, 200 + 100 periods, up and down): CPU seconds per
    # second of motion interpolated in frequency between the four measured, times its motion
    freqs = np.linspace(2.0, 60.0, 300)
    rate = np.interp(freqs, list(cost), list(cost.values()))
    total = 2 * float(np.sum(300.0 / freqs * rate))
    print(
        f"  estimate for the diagram (300 frequencies, 200 + 100 periods, up and down): "
        f"{total:.0f} CPU s, {total / 2 / 60:.1f} min on 2 workers (interpolated, not run)"
    )


def _decay_sensitivity() -> None:
    """The docs' free decay with three step sequences: where they part, and the backbone."""
    tower, u0, period, tip = _decay_case()
    default = motion_module.BASE_STEP_PERIODS
    runs = []
    for fraction in (default, 1.0 / 5.0, 1.0 / 16.0):
        motion_module.BASE_STEP_PERIODS = fraction
        try:
            start = time.process_time()
            decay = free_decay(
                tower, (u0, np.zeros(tower.n_dof)), 80 * period, samples_per_period=64
            )
            spent = time.process_time() - start
        finally:
            motion_module.BASE_STEP_PERIODS = default
        runs.append((fraction, decay, spent))
    ref = runs[0][1]
    f_ref = decay_backbone(ref, tip, mode=1).omega[0] / (2 * math.pi)
    for fraction, decay, spent in runs:
        k = min(decay.events, ref.events)
        apart = (np.abs(decay.event_times[:k] - ref.event_times[:k]) > 1e-12 * period) | (
            decay.event_joints[:k] != ref.event_joints[:k]
        )
        first = int(np.argmax(apart)) if apart.any() else k
        sep = [np.max(np.abs(decay.u[64 * p] - ref.u[64 * p])) / 3e-3 for p in (1, 3, 10)]
        f1 = decay_backbone(decay, tip, mode=1).omega[0] / (2 * math.pi)
        print(
            f"  base step T_min/{1 / fraction:.0f}: {spent:5.2f} s, {decay.events} events, "
            f"{decay.patterns_visited} patterns, ledger {decay.balance_error:.0e}; same first "
            f"{first} events; tip apart by {sep[0]:.0e} / {sep[1]:.0e} / {sep[2]:.0e} of 3 mm "
            f"after 1 / 3 / 10 periods; backbone cycle 1 {f1:.4f} Hz "
            f"({f1 / f_ref - 1:+.1e})"
        )


def _workload_cpu(args: argparse.Namespace) -> dict[str, float]:
    """CPU seconds of each speed workload in this process, after an untimed warm-up."""
    s, force, omega = _mast_case(2)  # imports, numba's compilation (or cache), first calls
    time_response(s, force, omega, 0.5 * 2 * math.pi / omega, samples_per_period=16)
    tower, u0, period, _ = _decay_case()
    free_decay(tower, (u0, np.zeros(tower.n_dof)), 0.5 * period, samples_per_period=64)
    cpu: dict[str, float] = {}
    for name, bays, periods in [("mast", 10, args.mast_periods)] + [
        (f"{b} bays", int(b), args.scaling_periods) for b in args.bays.split(",")
    ]:
        s, force, omega = _mast_case(bays)
        start = time.process_time()
        time_response(s, force, omega, periods * 2 * math.pi / omega, samples_per_period=16)
        cpu[name] = time.process_time() - start
    tower, u0, period, _ = _decay_case()
    start = time.process_time()
    free_decay(
        tower, (u0, np.zeros(tower.n_dof)), args.decay_periods * period, samples_per_period=64
    )
    cpu["free decay"] = time.process_time() - start
    s, force, omega = _study_mast()
    start = time.process_time()
    time_response(s, force, omega, 10 * 2 * math.pi / omega, samples_per_period=16)
    cpu["mast.toml 10T"] = time.process_time() - start
    chain5, force5 = _rattling_chain()
    for hz in (20.0, 39.66):
        start = time.process_time()
        time_response(chain5, force5, 2 * math.pi * hz, 100 / hz, samples_per_period=16)
        cpu[f"chain {hz:g}Hz 100T"] = time.process_time() - start
    return cpu


def against_old(args: argparse.Namespace) -> None:
    """The speed workloads under ``args.old_src`` and this tree, alternately: new / old."""
    trees = {"old": args.old_src, "new": str(Path(__file__).resolve().parents[1] / "src")}
    forwarded = [f"--{k.replace('_', '-')}={getattr(args, k)}" for k in ("mast_periods", "bays")]
    forwarded += [f"--scaling-periods={args.scaling_periods}"]
    forwarded += [f"--decay-periods={args.decay_periods}", "--child"]
    cpu: dict[str, list[dict[str, float]]] = {"old": [], "new": []}
    print(f"load average before: {os.getloadavg()[0]:.2f}")
    for round_ in range(args.rounds):
        for side, src in trees.items():
            env = dict(os.environ, PYTHONPATH=src, OPENBLAS_NUM_THREADS="1")
            done = subprocess.run(
                [sys.executable, __file__, *forwarded],
                env=env,
                capture_output=True,
                text=True,
                check=True,
            )
            cpu[side].append(json.loads(done.stdout.splitlines()[-1]))
            line = ", ".join(f"{k} {v:.3f}" for k, v in cpu[side][-1].items())
            print(f"  round {round_ + 1} {side}: {line} (CPU s)")
    print(f"load average after: {os.getloadavg()[0]:.2f}")
    print(f"old {trees['old']}, new {trees['new']}; CPU s over {args.rounds} rounds")
    print(
        f"  {'workload':12s} {'old best':>9s} {'new best':>9s} {'new/old':>8s}   "
        f"{'old median':>10s} {'new median':>10s} {'new/old':>8s}"
    )
    for name in cpu["old"][0]:
        old = [run[name] for run in cpu["old"]]
        new = [run[name] for run in cpu["new"]]
        o, n = min(old), min(new)
        om, nm = statistics.median(old), statistics.median(new)
        print(f"  {name:12s} {o:9.3f} {n:9.3f} {n / o:8.3f}   {om:10.3f} {nm:10.3f} {nm / om:8.3f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--chain-periods",
        type=int,
        default=8,
        help="periods of the 3-link chain (over 20, solve_ivp itself moves by more than 1e-8)",
    )
    parser.add_argument("--mast-periods", type=int, default=200)
    parser.add_argument("--ivp-periods", type=int, default=2)
    parser.add_argument("--bays", default="5,10,20,40")
    parser.add_argument("--scaling-periods", type=int, default=5)
    parser.add_argument("--old-src", help="only time the speed workloads against this src tree")
    parser.add_argument("--rounds", type=int, default=5, help="old/new child pairs (--old-src)")
    parser.add_argument("--decay-periods", type=int, default=80, help="free decay (--old-src)")
    parser.add_argument(
        "--issue24", action="store_true", help="run section 0 alone (issue 24's ratio, chain)"
    )
    parser.add_argument("--issue-periods", type=int, default=10, help="mast.toml periods")
    parser.add_argument("--issue-rounds", type=int, default=3, help="exact runs, best taken")
    parser.add_argument(
        "--chain-seconds", type=float, default=2.0, help="seconds of the chain's motion timed"
    )
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        print(json.dumps(_workload_cpu(args)))
        return
    if args.old_src:
        against_old(args)
        return
    if args.issue24:  # on request only: side_by_side.py times the default sections
        print(f"0. examples/mast.toml (20 N, 15 Hz), {args.issue_periods} periods: exact vs ivp")
        issue24(args)
        return

    n = args.chain_periods
    print(f"1. 3-link chain, 2 joints, {n} periods: exact vs solve_ivp (rtol 1e-12, edge events)")
    s = _three_links()
    force3 = np.array([500.0, -300.0, 800.0])
    omega3 = 0.9 * float(s.modes().omega[0])
    time_response(s, force3, omega3, 0.1 / omega3)  # compile (or load the cache) untimed
    _side_by_side(s, force3, omega3, n)
    # whose error is it? solve_ivp at a tighter tolerance moves toward the exact solver
    mine = time_response(s, force3, omega3, n * 2 * math.pi / omega3, samples_per_period=32)
    tight, _, _ = reference_response(s, force3, omega3, mine.t, rtol=1e-13, atol=1e-15)
    loose, _, _ = reference_response(s, force3, omega3, mine.t)
    scale = np.max(np.abs(tight))
    print(
        f"  exact vs solve_ivp rtol 1e-13: {np.max(np.abs(mine.u - tight)) / scale:.2e}; "
        f"solve_ivp 1e-12 vs 1e-13: {np.max(np.abs(loose - tight)) / scale:.2e}"
    )

    print(
        f"2. 10-bay mast, 20 joints: exact over {args.mast_periods} periods, solve_ivp over "
        f"the first {args.ivp_periods}"
    )
    s, force, omega = _mast_case(10)
    period = 2.0 * math.pi / omega
    time_response(s, force, omega, 0.05 * period)  # compile (cached) and warm up
    spp = 16
    start, wall = time.process_time(), time.perf_counter()
    motion = time_response(s, force, omega, args.mast_periods * period, samples_per_period=spp)
    t_mine, wall_mine = time.process_time() - start, time.perf_counter() - wall
    print(
        f"  exact: {t_mine:.2f} s for {args.mast_periods} periods = "
        f"{t_mine / args.mast_periods * 1e3:.1f} ms per period; {motion.events} events "
        f"({motion.events / t_mine:.0f} events/s), {motion.steps} steps, "
        f"{motion.patterns_visited} patterns, ledger balance {motion.balance_error:.1e}"
    )
    common = args.ivp_periods * spp + 1  # samples over [0, ivp_periods T], both ends
    t_common = motion.t[:common]
    start, wall = time.process_time(), time.perf_counter()
    u_ivp, _, events_ivp = reference_response(s, force, omega, t_common)
    t_ivp, wall_ivp = time.process_time() - start, time.perf_counter() - wall
    per_mine = t_mine / args.mast_periods
    per_ivp = t_ivp / args.ivp_periods
    events_mine = int(np.sum(motion.event_times <= t_common[-1]))
    print(
        f"  solve_ivp rtol 1e-12: {t_ivp:.2f} s for {args.ivp_periods} periods = "
        f"{per_ivp * 1e3:.0f} ms per period; ratio per period {per_ivp / per_mine:.0f}x "
        f"(events in the common span: exact {events_mine}, solve_ivp {events_ivp})"
    )
    ratio_wall = (wall_ivp / args.ivp_periods) / (wall_mine / args.mast_periods)
    print(
        f"  wall clock: exact {wall_mine:.2f} s, solve_ivp {wall_ivp:.2f} s, ratio per period "
        f"{ratio_wall:.0f}x (other jobs on the machine move this one)"
    )
    start = time.process_time()
    u_tight, _, events_tight = reference_response(s, force, omega, t_common, rtol=1e-13, atol=1e-16)
    per_tight = (time.process_time() - start) / args.ivp_periods
    print(
        f"  solve_ivp rtol 1e-13: {per_tight * 1e3:.0f} ms per period; ratio per period "
        f"{per_tight / per_mine:.0f}x ({events_tight} events)"
    )
    # the same exact solver with another step sequence (base step T_min / 5, not / 8):
    # how fast this motion itself amplifies round-off
    default = motion_module.BASE_STEP_PERIODS
    motion_module.BASE_STEP_PERIODS = 1.0 / 5.0
    try:
        other = time_response(
            s, force, omega, (args.ivp_periods + 1) * period, samples_per_period=spp
        )
    finally:
        motion_module.BASE_STEP_PERIODS = default
    scale = np.max(np.abs(u_tight))
    mine = motion.u[:common]
    pairs = (
        ("exact vs solve_ivp 1e-13", mine, u_tight),
        ("solve_ivp 1e-12 vs 1e-13", u_ivp, u_tight),
        ("exact vs solve_ivp 1e-12", mine, u_ivp),
        ("exact vs exact, base step / 5", mine, other.u[:common]),
    )
    ends = [k * spp for k in range(1, args.ivp_periods + 1)]
    print(
        "  largest difference of u over the DOFs / largest motion, at the end of period "
        + ", ".join(str(k) for k in range(1, args.ivp_periods + 1))
    )
    for name, a, b in pairs:
        at = [np.max(np.abs(a[k] - b[k])) / scale for k in ends]
        print(f"    {name:32s} " + "  ".join(f"{d:.1e}" for d in at))

    print(f"3. cost against bays, over {args.scaling_periods} forcing periods each")
    for bays in (int(b) for b in args.bays.split(",")):
        s, force, omega = _mast_case(bays)
        period = 2.0 * math.pi / omega
        start = time.process_time()
        motion = time_response(
            s, force, omega, args.scaling_periods * period, samples_per_period=16
        )
        spent = time.process_time() - start
        print(
            f"  {bays:3d} bays ({s.n_dof:4d} DOF, {2 * bays:3d} joints): "
            f"{spent / args.scaling_periods * 1e3:8.1f} ms and "
            f"{motion.events / args.scaling_periods:7.0f} events per period "
            f"({motion.events / spent:6.0f} events/s, {motion.steps / motion.events:.2f} steps "
            f"per event)"
        )

    print("4. the mast's free decay (docs/structure.md): 80 closed-mode periods from 3 mm")
    _decay_sensitivity()

    print("5. linear modes")
    length, e, rho, area = 2.0, 7e10, 2700.0, 1e-4
    exact = (2 * np.arange(1, 4) - 1) * math.pi / (2 * length) * math.sqrt(e / rho)
    for n in (10, 20, 40, 80, 160):
        masses = np.full(n + 1, rho * area * length / n)
        masses[-1] *= 0.5
        members = tuple(Member(i, i + 1, youngs_modulus=e, area=area) for i in range(n))
        bar = Structure(np.linspace(0, length, n + 1), masses, members, supports=(0,))
        error = bar.modes(count=3).omega / exact - 1.0
        shown = np.array2string(error, formatter={"float_kind": lambda x: f"{x:.2e}"})
        print(f"  bar, n = {n:4d}: relative error of modes 1-3 = {shown}")
    m1, m2, k1, k2 = 2.0, 0.5, 3e6, 1e6
    a = (k1 + k2) / m1 + k2 / m2
    root = math.sqrt(a * a - 4 * k1 * k2 / (m1 * m2))
    closed = np.sqrt([(a - root) / 2, (a + root) / 2])
    got = chain([m1, m2], [k1, k2]).modes().omega
    worst = np.max(np.abs(got / closed - 1))
    print(f"  two-mass chain: {got} rad/s vs closed form {closed}: {worst:.1e}")


if __name__ == "__main__":
    main()
