"""clearjoint.identify: against the rig's truth, an exact friction loop, an independent
solve_ivp simulator with 1 % noise on every channel (tests/independent_joint.py), real BRFD
records shipped in tests/data/brfd (and all 31 when ../shared is beside the clone), flags,
the result object and the command line."""

from __future__ import annotations

import csv
import importlib.util
import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from clearjoint.cli import main
from clearjoint.identify import IdentificationError, damper, identify, identify_files
from clearjoint.records import Record, read_record
from clearjoint.records import write_record as write_clearjoint_record
from clearjoint.rig import load_campaign, run_campaign
from independent_joint import TrueJoint, steady_truth, write_record

BRFD = Path(__file__).resolve().parents[2] / "shared" / "data" / "brfd"
#: Three real BRFD records shipped with the tests (2 Hz, 0.5 in; 0, 30 and 36 lb; CC BY-SA 4.0).
SHIPPED = Path(__file__).resolve().parent / "data" / "brfd"

REDUCED = """
seed = 11
periods = 16
[grid]
frequencies = ["20Hz", "60Hz", "100Hz"]
force_amplitudes = ["800N", "2000N", "3000N"]
"""

REQUIRED = (
    "file",
    "frequency_hz",
    "amplitude_m",
    "clearance_m",
    "compression_stiffness_n_per_m",
    "tension_stiffness_n_per_m",
    "friction_force_n",
    "energy_per_cycle_j",
    "cycles_used",
)


@pytest.fixture(scope="module")
def campaign(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("rig")
    path = folder / "campaign.toml"
    path.write_text(REDUCED)
    return run_campaign(load_campaign(path), folder / "records", jobs=2)


def rows(manifest: Path) -> list[dict[str, str]]:
    with manifest.open() as handle:
        return list(csv.DictReader(handle))


def test_accuracy_on_a_reduced_campaign_of_the_rig(campaign: Path) -> None:
    for row in rows(campaign):
        result = identify(read_record(campaign.parent / row["file"]))
        s = result.summary
        contact = float(row["gap_stiffness_n_per_m"])  # the record's contact slope is k0 + k_s
        # the bare beam's loop is a thousand times thinner: the sensor noise weighs 5 %
        tolerance = 0.05 if row["structure"] == "beam" else 0.02
        assert s["energy_per_cycle_j"] == pytest.approx(
            float(row["energy_per_cycle_j"]), rel=tolerance
        ), row["file"]
        if row["structure"] == "beam":
            assert result.model == "line"
            assert s["clearance_m"] == 0.0
            k = float(row["compression_stiffness_n_per_m"]) + contact
            assert s["compression_stiffness_n_per_m"] == pytest.approx(k, rel=0.03)
            continue
        assert result.model == "joint"
        assert s["clearance_m"] == pytest.approx(float(row["clearance_m"]), rel=0.02), row["file"]
        for side in ("compression", "tension"):
            k = float(row[f"{side}_stiffness_n_per_m"]) + contact
            assert s[f"{side}_stiffness_n_per_m"] == pytest.approx(k, rel=0.03), row["file"]
        assert s["friction_force_n"] == pytest.approx(float(row["friction_force_n"]), abs=3.0)
        assert result.cycles_used >= 10
        assert result.cycles_used <= result.cycles_total
        assert result.frequency_hz == pytest.approx(float(row["frequency_hz"]), rel=1e-4)


def friction_loop(
    backlash: float,
    friction: float,
    stiffness: float,
    amplitude: float,
    cycles: int = 8,
    rate: float = 2000.0,
    frequency: float = 1.0,
    backlash_falling: float | None = None,
    ringing: float = 0.0,
    gap_dip: float = 0.0,
) -> Record:
    """A rigid-plastic friction loop with backlash under imposed x = X sin(w t), exactly.

    The force follows, along the travel from each reversal, elastic unloading at
    ``stiffness``, the backlash at zero force, elastic loading, then the slip plateau.
    ``backlash_falling`` (default: ``backlash``) is the free travel after the upper
    reversal: a loop that is not one gap when the two differ. ``ringing`` (a fraction of
    the friction force) holds the loading force back, from where it first reaches 70 % of
    the slip level, by the dips of a decaying 25 Hz oscillation of that amplitude: the force
    nears the slip level, rings back and reaches it only later, as when the BRFD's slip
    starts again (docs/identify.md). The gap, the slopes and the level are unchanged.
    """
    t = np.arange(int(cycles * rate / frequency)) / rate
    envelope = np.clip(t * frequency, 0.0, 1.0)  # a one-cycle ramp in, as the BRFD has
    x = amplitude * envelope * np.sin(2 * np.pi * frequency * t)
    force = np.zeros_like(x)
    state, anchor, level, contact = 1.0, x[0], 0.0, math.inf
    for n in range(1, x.size):
        direction = np.sign(x[n] - x[n - 1]) or state
        if direction != state:  # reversal: the force starts back from its level there
            state, anchor, level, contact = direction, x[n - 1], force[n - 1], math.inf
        travel = abs(x[n] - anchor)
        unload = abs(level) / stiffness
        gap = backlash if state > 0 or backlash_falling is None else backlash_falling
        if travel <= unload:
            value = level + state * stiffness * travel
        elif travel <= unload + gap:
            inside = (travel - unload) / (0.8 * gap)
            value = -gap_dip * friction * np.sin(np.pi * inside) ** 2 if state < 0 else 0.0
            value = value if inside < 1.0 else 0.0
        else:
            elastic = stiffness * (travel - unload - gap)
            if elastic >= 0.7 * friction:
                contact = min(contact, t[n])
            tau = t[n] - contact if t[n] >= contact else 0.0
            dip = max(np.sin(2 * np.pi * 25.0 * tau), 0.0) * np.exp(-20.0 * tau)
            value = state * (elastic - ringing * friction * dip)
        force[n] = state * min(abs(value), friction) if np.sign(value) == state else value
    return Record(
        time=t,
        force=force,
        displacement=x,
        control="displacement",
        frequency_hz=frequency,
        source="friction loop",
    )


def test_a_loop_whose_branches_show_different_backlash_is_doubtful() -> None:
    """One gap is crossed both ways: 4 mm rising against 1.5 mm falling is not one gap."""
    b, f_f, k, x_amp = 4e-3, 1e4, 5e6, 20e-3
    one_gap = identify(friction_loop(b, f_f, k, x_amp))
    assert one_gap.flags["clearance_m"] == ("ok", "")
    two = identify(friction_loop(b, f_f, k, x_amp, backlash_falling=1.5e-3))
    assert two.model == "damper"
    flag, reason = two.flags["clearance_m"]
    assert flag == "doubtful"
    # each branch's reading is the generator's own free travel
    rising, falling = (float(v) for v in re.findall(r"([\d.]+) mm on the", reason))
    assert rising == pytest.approx(4.0, rel=0.02)
    assert falling == pytest.approx(1.5, rel=0.02)
    # the same rule on the two other branch ratios: 1.8 passes, 2.2 does not
    assert identify(friction_loop(b, f_f, k, x_amp, backlash_falling=b / 1.8)).flag == "ok"
    assert identify(friction_loop(b, f_f, k, x_amp, backlash_falling=b / 2.2)).flag != "ok"


def test_a_force_that_reaches_the_new_level_inside_the_gap_is_flagged() -> None:
    """The two BRFD misses (docs/identify.md): on the falling branch the force leaves the
    backlash level early in the gap and reaches the new slip level before the contact. The
    crossings of the upper fractions then lie inside the gap: that branch reads short, the
    rising one reads the gap, and the loop is flagged, not passed. A dip 80 % of the way
    is one residual: the gap is read exactly (the loop flagged by its fit residual only)."""
    b, f_f, k, x_amp = 4e-3, 1e4, 5e6, 20e-3
    plain = friction_loop(b, f_f, k, x_amp)
    for depth in (0.8, 1.0):
        dip = friction_loop(b, f_f, k, x_amp, gap_dip=depth)
        assert np.min(dip.force - plain.force) == pytest.approx(-depth * f_f, rel=1e-3)
    partway = identify(friction_loop(b, f_f, k, x_amp, gap_dip=0.8))
    # the gap is read; the dip is no part of the elastic-plastic model, so the loop's fit
    # residual (identify/loopcheck.py) flags it, but not as a second gap
    flag, reason = partway.flags["clearance_m"]
    assert flag == "doubtful"
    assert "fit residual" in reason
    assert "not one gap" not in reason
    assert partway.summary["clearance_m"] == pytest.approx(b, rel=0.01)
    result = identify(friction_loop(b, f_f, k, x_amp, gap_dip=1.0))
    assert result.model == "damper"
    flag, reason = result.flags["clearance_m"]
    assert flag == "doubtful"
    assert "not one gap" in reason
    rising, falling = (float(v) for v in re.findall(r"([\d.]+) mm on the", reason))
    assert rising == pytest.approx(1e3 * b, rel=0.02)  # the branch without the dip
    assert falling < 0.5e3 * b  # the dip's first crossings read as the gap's far end


def test_backlash_is_the_distance_between_the_elastic_lines() -> None:
    """Crossings of an elastic-plastic loop whose 4 mm gap is crossed over a tenth of the
    level change, the last two crossings delayed 1.5 mm by ringing: the step fit reads the
    two parallel lines (travel 2 mm per unit of the level change) 4 mm apart exactly."""
    alphas = damper.ALPHAS
    gap = 4e-3 * np.clip((alphas - 0.45) / 0.1, 0.0, 1.0)
    s = 0.3e-3 + 2e-3 * alphas + gap
    s[-2:] += 1.5e-3
    intercept, slope, backlash, place = damper._step_fit(s)
    assert slope == pytest.approx(2e-3, rel=1e-9)
    assert intercept == pytest.approx(0.3e-3, rel=1e-9)
    assert backlash == pytest.approx(4e-3, rel=1e-9)
    assert 0.45 <= damper.ALPHAS[place] <= 0.55 + 1.0 / damper.N_CROSSINGS


def test_ringing_as_slip_starts_is_not_backlash() -> None:
    """The force nears the slip level, rings back by 40 % of the friction force and reaches
    the level millimetres later: that travel is not gap (the estimator before this one read
    4.64 mm here, +16 %: it summed every long step between level crossings)."""
    b, f_f, k, x_amp = 4e-3, 1e4, 5e6, 20e-3
    plain = friction_loop(b, f_f, k, x_amp)
    ringing = friction_loop(b, f_f, k, x_amp, ringing=0.4)
    assert np.max(np.abs(ringing.force - plain.force)) > 0.3 * f_f  # the dips are there
    s = identify(ringing).summary
    assert s["clearance_m"] == pytest.approx(b, rel=0.01)
    assert s["compression_stiffness_n_per_m"] == pytest.approx(k, rel=0.03)
    assert s["friction_force_n"] == pytest.approx(f_f, rel=0.01)


def test_exact_friction_loop_with_backlash() -> None:
    b, f_f, k, x_amp = 4e-3, 1e4, 5e6, 20e-3
    result = identify(friction_loop(b, f_f, k, x_amp))
    s = result.summary
    assert result.model == "damper"
    assert s["clearance_m"] == pytest.approx(b, rel=0.02)
    assert s["friction_force_n"] == pytest.approx(f_f, rel=0.01)
    assert s["compression_stiffness_n_per_m"] == pytest.approx(k, rel=0.03)
    # the loop's area in closed form: 2 F_f (2 X - b - 2 F_f / k)
    assert s["energy_per_cycle_j"] == pytest.approx(
        2 * f_f * (2 * x_amp - b - 2 * f_f / k), rel=0.01
    )


def test_a_dampers_samples_are_staged_by_force_not_by_position() -> None:
    """The loop figure colours samples by Identification.stage: on a damper, a sample on a
    slip plateau is never "free-play", and one at zero force (in the gap) always is, at any
    displacement (they used to be staged by the gap edges' positions)."""
    friction = 1e4
    record = friction_loop(4e-3, friction, 5e6, 20e-3)
    result = identify(record)
    assert result.model == "damper"
    force = result.restoring_force
    slipping = np.abs(force) > 0.9 * friction
    assert np.all(result.stage[slipping] == np.sign(force[slipping]))
    in_gap = (force == 0.0) & (record.time > 1.0)  # after the ramp in
    assert np.all(result.stage[in_gap] == 0)
    assert np.ptp(record.displacement[in_gap]) > 4e-3  # free play on both sides of zero
    assert {name for name, _, _ in result.stage_runs(record.time)} == {
        "free-play",
        "compression",
        "tension",
    }


def test_real_brfd_records() -> None:
    """All 31 with ../shared beside the clone; on a fresh clone, the 3 it ships."""
    full = BRFD.exists()
    results, failures = identify_files(
        [str(p) for p in sorted((BRFD if full else SHIPPED).glob("*.json"))]
    )
    if full:
        # the one record refused: its ramps leave two steady cycles (docs)
        assert len(failures) == 1
        assert "2Hz0lbtension1amplitude.json: 2 steady cycles" in failures[0]
        assert "a record needs at least 3 steady cycles" in failures[0]  # the rule, stated
        assert len(results) == 30
    else:
        assert failures == []
        assert len(results) == 3
    backlash: dict[str, list[float]] = {}
    for _, result in results:
        s = result.summary
        assert result.model == "damper", result.source
        assert result.cycles_used >= 3
        # independent route: an elastic-plastic friction loop with a gap b
        assert s["energy_per_cycle_j"] == pytest.approx(elastic_plastic_energy(s), rel=0.15)
        tension = result.source.split("Hz")[1].split("lb")[0]
        backlash.setdefault(tension, []).append(s["clearance_m"])
    # one device: the backlash within 15 % of the median at its band tension; two of the
    # thirty miss it today, both flagged doubtful as not one gap (docs/identify.md says which)
    misses = [
        result
        for _, result in results
        for values in [backlash[result.source.split("Hz")[1].split("lb")[0]]]
        if abs(result.summary["clearance_m"] / np.median(values) - 1.0) > 0.15
    ]
    assert len(misses) <= 2
    for result in misses:
        flag, reason = result.flags["clearance_m"]
        assert flag == "doubtful", result.source
        assert "not one gap" in reason, result.source


def test_short_and_shapeless_records_are_refused() -> None:
    t = np.arange(300) / 100.0
    short = Record(
        time=t,
        force=np.sin(2 * np.pi * t),
        displacement=np.sin(2 * np.pi * t),
        control="displacement",
        source="short",
    )
    with pytest.raises(IdentificationError, match="steady cycles"):
        identify(short)
    t6 = np.arange(700) / 100.0
    wrong = Record(
        time=t6, force=t6, displacement=np.sin(2 * np.pi * t6), frequency_hz=0.5, source="claims"
    )
    with pytest.raises(IdentificationError, match="not the nominal"):
        identify(wrong)


def test_the_docs_rig_comparison_takes_the_contact_slope_k_s_plus_k0(
    campaign: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # identify's stiffness columns are the slopes a record shows in contact, k0 + k_s
    # (MODEL.md section 3's k_c,meas); the manifest lists k_s and k0 apart. Leaving k0 out
    # reads k0 / k_s (0.38-0.49 % here) too high on every test: the medians tell them apart.
    out = tmp_path / "r.csv"
    files = sorted(str(p) for p in campaign.parent.glob("*.nc"))
    assert main(["identify", *files, "--out", str(out), "--quiet"]) == 0
    truth = {row["file"]: row for row in rows(campaign)}
    found = {Path(row["file"]).name: row for row in rows(out)}
    worst = {}
    for side in ("compression", "tension"):
        column = f"{side}_stiffness_n_per_m"
        errors = [
            float(found[name][column]) / (float(row[column]) + float(row["gap_stiffness_n_per_m"]))
            - 1.0
            for name, row in truth.items()
            if row["structure"] != "beam"
        ]
        assert abs(float(np.median(errors))) < 1e-3, side
        worst[column] = max(abs(e) for e in errors)
    # docs/identify.md quotes docs/identify_rig.py: it compares the same way
    spec = importlib.util.spec_from_file_location(
        "identify_rig", Path(__file__).resolve().parents[1] / "docs" / "identify_rig.py"
    )
    assert spec is not None
    assert spec.loader is not None
    script = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(script)
    capsys.readouterr()
    script.main([str(campaign), str(out)])
    printed = capsys.readouterr().out.splitlines()
    for column, value in worst.items():
        line = next(line for line in printed if line.strip().startswith(column))
        quoted = float(re.search(r"worst \|error\| ([0-9.]+) %", line)[1])  # type: ignore[index]
        assert quoted == pytest.approx(100 * value, abs=0.006), line


def test_cli_loop_figure_of_a_damper_names_its_stages_in_mm_with_the_flag_reason(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import clearjoint.figures

    made = []
    drawn = clearjoint.figures.identified_loop_figure

    def keep(*args: object, **kwargs: object) -> object:
        made.append(drawn(*args, **kwargs))  # type: ignore[arg-type]
        return made[-1]

    monkeypatch.setattr(clearjoint.figures, "identified_loop_figure", keep)
    record = SHIPPED / "2Hz0lbtension0.5amplitude.json"  # doubtful: backlash not one gap
    out = tmp_path / "r.csv"
    assert main(["identify", str(record), "--out", str(out), "--quiet", "--figures",
                 str(tmp_path / "figs")]) == 0  # fmt: skip
    (fig,) = made
    (ax,) = fig.axes
    assert ax.get_xlabel() == "displacement x (mm)"
    labels = {text.get_text() for text in ax.get_legend().get_texts()}
    assert "backlash (after a reversal)" in labels
    assert "free-play" not in labels
    assert "[doubtful]" in ax.get_title()
    assert "not one gap" in rows(out)[0]["flag_reason"]
    assert fig.texts[0].get_text().startswith("backlash ")
    assert (tmp_path / "figs" / "2Hz0lbtension0.5amplitude_loop.png").stat().st_size > 0


def test_cli_writes_csv_and_netcdf_and_says_why_a_file_was_not_used(
    campaign: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    files = sorted(str(p) for p in campaign.parent.glob("joint-1_*Hz_2000N.nc"))
    broken = tmp_path / "broken.csv"
    broken.write_text("time [s],force [N]\n0,1\n")
    out = tmp_path / "results.csv"
    code = main(
        [
            "identify",
            *files,
            str(broken),
            "--out",
            str(out),
            "--quiet",
            "--figures",
            str(tmp_path / "figures"),
        ]
    )
    assert code == 0
    captured = capsys.readouterr()
    assert f"not used: {broken}" in captured.err
    with out.open() as handle:
        table = list(csv.DictReader(handle))
    assert len(table) == len(files)
    for key in REQUIRED:
        assert key in table[0]
    for key in REQUIRED[2:-1]:
        assert f"{key}_std" in table[0]
    assert len(list((tmp_path / "figures").glob("*.png"))) == 2 * len(files)
    assert main(["identify", *files, "--out", str(out), "--quiet"]) == 2  # no overwrite
    capsys.readouterr()
    # figures already there: nothing is written (not even the new table), the message names
    # the option that chose them
    other = tmp_path / "f2.csv"
    figures = ["--figures", str(tmp_path / "figures")]
    assert main(["identify", *files, "--out", str(other), "--quiet", *figures]) == 2
    err = capsys.readouterr().err
    assert "choose another --figures or pass --force" in err
    assert len(err.strip().splitlines()) == 1
    assert not other.exists()
    nc = tmp_path / "results.nc"
    assert main(["identify", *files, "--out", str(nc), "--quiet"]) == 0
    with xr.open_dataset(nc, engine="h5netcdf") as data:
        assert data.sizes["file"] == len(files)
        assert "clearance_m_std" in data


def test_identify_help_names_every_column_kind(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as info:
        main(["identify", "--help"])
    assert info.value.code == 0
    text = " ".join(capsys.readouterr().out.split())
    for word in ("_std", "_se", "flag (ok, doubtful, rejected)", "flag_reason"):
        assert word in text, word


def test_cli_refuses_when_nothing_is_usable(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    junk = tmp_path / "junk.json"
    junk.write_text(json.dumps({"a": 1}))
    assert main(["identify", str(junk), "--out", str(tmp_path / "r.csv"), "--quiet"]) == 2
    assert "no record could be used" in capsys.readouterr().err


# ---- records from an independent simulator (tests/independent_joint.py, not the rig) -------


@pytest.fixture(scope="module")
def independent() -> dict[float, tuple[TrueJoint, dict[str, float]]]:
    joints = {f: TrueJoint(frequency_hz=f) for f in (40.0, 100.0)}
    return {f: (j, steady_truth(j)) for f, j in joints.items()}


def test_the_independent_simulator_balances_its_energy(
    independent: dict[float, tuple[TrueJoint, dict[str, float]]],
) -> None:
    for _, truth in independent.values():
        # the exciter's work over a steady cycle is what friction and drag dissipate
        assert truth["external_work_j"] == pytest.approx(truth["energy_per_cycle_j"], rel=1e-6)
        assert truth["amplitude_m"] > 0.5 * TrueJoint().clearance  # the contacts are reached


def test_noise_free_independent_records_with_acceleration(
    independent: dict[float, tuple[TrueJoint, dict[str, float]]], tmp_path: Path
) -> None:
    for f, (joint, truth) in independent.items():
        path = write_record(joint, tmp_path / f"{f}.csv", noise=0.0, cycles=12)
        s = identify(read_record(path)).summary
        for key in ("clearance_m", "compression_stiffness_n_per_m", "tension_stiffness_n_per_m"):
            assert s[key] == pytest.approx(truth[key], rel=0.01), (f, key)
        assert s["friction_force_n"] == pytest.approx(truth["friction_force_n"], rel=0.05)
        assert s["energy_per_cycle_j"] == pytest.approx(truth["energy_per_cycle_j"], rel=0.01)


KEYS = ("clearance_m", "compression_stiffness_n_per_m", "tension_stiffness_n_per_m")


@pytest.mark.parametrize("frequency", [40.0, 100.0])
def test_one_percent_noise_on_every_channel_with_acceleration(
    independent: dict[float, tuple[TrueJoint, dict[str, float]]], tmp_path: Path, frequency: float
) -> None:
    joint, truth = independent[frequency]
    path = write_record(joint, tmp_path / "noisy.csv", noise=0.01, acceleration=True)
    s = identify(read_record(path)).summary
    assert s["clearance_m"] == pytest.approx(truth["clearance_m"], rel=0.01)
    for key in KEYS[1:]:
        assert s[key] == pytest.approx(truth[key], rel=0.02), key
    assert s["friction_force_n"] == pytest.approx(truth["friction_force_n"], rel=0.10)
    assert s["energy_per_cycle_j"] == pytest.approx(truth["energy_per_cycle_j"], rel=0.01)


def test_the_friction_standard_error_matches_its_spread_over_noise_draws(
    independent: dict[float, tuple[TrueJoint, dict[str, float]]], tmp_path: Path
) -> None:
    """One independent record (40 Hz, 10 cycles, 1 % noise on every channel: the weak form)
    over 40 noise draws: the spread of the friction estimates against the rms of the
    standard errors reported. When every jackknife replicate took the average's velocity
    sign the ratio was 2.58 (the sign's flips were in no replicate); with each replicate's
    own sign it is 0.88. Tolerance 0.6-1.25: the spread of 40 draws is good to about 11 %,
    and a jackknife over a sign (not smooth in the data) overstates the error somewhat
    (0.61-0.88 at 6-24 cycles, docs/identify_bias.py --spread); never too small."""
    joint, truth = independent[40.0]
    est, se = [], []
    for seed in range(1000, 1040):
        path = write_record(joint, tmp_path / "s.csv", noise=0.01, seed=seed, cycles=10)
        result = identify(read_record(path))
        est.append(result.summary["friction_force_n"])
        se.append(result.stderr["friction_force_n"])
    ratio = float(np.std(est, ddof=1) / np.sqrt(np.mean(np.square(se))))
    assert 0.6 <= ratio <= 1.25, ratio
    # and the bias over the draws is inside one standard error (not worth a correction)
    assert abs(np.mean(est) - truth["friction_force_n"]) < np.sqrt(np.mean(np.square(se)))


@pytest.mark.parametrize(("cycles", "seed"), [(6, 2), (6, 4), (10, 2), (10, 3), (16, 2)])
def test_a_friction_more_than_ten_percent_off_is_doubtful_or_within_two_errors(
    independent: dict[float, tuple[TrueJoint, dict[str, float]]],
    tmp_path: Path,
    cycles: int,
    seed: int,
) -> None:
    """The misses of docs/identify_bias.py --cycles (11.9-15.3 % low, 2.3-8.5 standard errors
    out and ok when the replicates shared the average's velocity sign)."""
    joint, truth = independent[40.0]
    path = write_record(joint, tmp_path / "r.csv", noise=0.01, seed=seed, cycles=cycles)
    result = identify(read_record(path))
    miss = abs(result.summary["friction_force_n"] - truth["friction_force_n"])
    assert miss > 0.10 * truth["friction_force_n"]  # still a miss: the estimate is unchanged
    doubtful = result.flags["friction_force_n"][0] == "doubtful"
    assert doubtful or miss <= 2.0 * result.stderr["friction_force_n"]


@pytest.mark.parametrize(("frequency", "rate"), [(40.0, 12_010.0), (37.0, 12_000.0)])
def test_a_period_that_is_not_a_whole_number_of_samples(
    tmp_path: Path, frequency: float, rate: float
) -> None:
    """300.25 and 324.3 samples a period: the cycles are stacked by interpolation; the
    targets hold as on a whole number (sample-by-sample fits on that stack gave the
    friction 8-21 % low, flagged ok)."""
    joint = TrueJoint(frequency_hz=frequency)
    truth = steady_truth(joint)
    for seed in (1, 3):
        path = write_record(joint, tmp_path / f"{seed}.csv", noise=0.01, rate=rate, seed=seed)
        s = identify(read_record(path)).summary
        assert s["clearance_m"] == pytest.approx(truth["clearance_m"], rel=0.01), seed
        for key in KEYS[1:]:
            assert s[key] == pytest.approx(truth[key], rel=0.02), (seed, key)
        assert s["friction_force_n"] == pytest.approx(truth["friction_force_n"], rel=0.10), seed
        assert s["energy_per_cycle_j"] == pytest.approx(truth["energy_per_cycle_j"], rel=0.01)


def test_an_interpolated_stack_fitted_sample_by_sample_is_doubtful(
    independent: dict[float, tuple[TrueJoint, dict[str, float]]], tmp_path: Path
) -> None:
    """100 Hz at 12 010 Hz: a contact too short for the weak form on an interpolated stack
    (the friction reads 16 % low without an acceleration channel): flagged, with the rate."""
    joint, _ = independent[100.0]
    path = write_record(joint, tmp_path / "r.csv", noise=0.01, rate=12_010.0, acceleration=False)
    flags = identify(read_record(path)).flags
    assert flags["friction_force_n"][0] == "doubtful"
    flag, reason = flags["clearance_m"]  # its standard error is small: this is the reason
    assert flag == "doubtful"
    assert "120.10 samples a period" in reason
    assert "interpolation" in reason
    exact = write_record(joint, tmp_path / "e.csv", noise=0.0, rate=12_000.0)
    assert "interpolation" not in identify(read_record(exact)).flags["clearance_m"][1]


@pytest.mark.parametrize("frequency", [40.0, 100.0])
def test_one_percent_noise_without_acceleration(
    independent: dict[float, tuple[TrueJoint, dict[str, float]]], tmp_path: Path, frequency: float
) -> None:
    joint, truth = independent[frequency]
    path = write_record(joint, tmp_path / "noisy.csv", noise=0.01, acceleration=False)
    result = identify(read_record(path))
    s = result.summary
    for key in KEYS[1:]:
        assert s[key] == pytest.approx(truth[key], rel=0.02), key
    assert s["energy_per_cycle_j"] == pytest.approx(truth["energy_per_cycle_j"], rel=0.01)
    if frequency == 40.0:  # at 100 Hz the free-play crossing is too short (docs)
        assert s["clearance_m"] == pytest.approx(truth["clearance_m"], rel=0.01)
        assert s["friction_force_n"] == pytest.approx(truth["friction_force_n"], rel=0.10)
    # every value carries a standard error
    assert all(result.stderr[k] > 0 for k in KEYS)


def test_force_control_without_a_mass_warns_and_estimates_it(
    independent: dict[float, tuple[TrueJoint, dict[str, float]]], tmp_path: Path
) -> None:
    joint, truth = independent[40.0]
    path = write_record(joint, tmp_path / "nomass.csv", noise=0.01, mass_in_metadata=False)
    result = identify(read_record(path))
    assert len(result.warnings) == 1
    assert "without a mass" in result.warnings[0]
    assert "# mass = " in result.warnings[0]  # says how to add it
    assert result.summary["mass_kg"] == pytest.approx(joint.mass, rel=0.02)
    assert result.summary["clearance_m"] == pytest.approx(truth["clearance_m"], rel=0.01)
    flag, reason = result.flags["clearance_m"]
    assert flag == "doubtful"
    assert "mass" in reason
    assert result.row()["flag"] == "doubtful"


def test_an_estimated_mass_has_the_standard_error_of_its_scatter(tmp_path: Path) -> None:
    # 100 Hz with a measured acceleration: the sample-by-sample fit, whose mass was one
    # estimate for every jackknife replicate (a standard error of 0.0 on a fitted value).
    # Checked against ten noise draws: the reported standard error is the estimates' scatter.
    joint = TrueJoint(frequency_hz=100.0)
    masses, errors = [], []
    for seed in range(10):
        path = tmp_path / f"nomass{seed}.csv"
        write_record(joint, path, noise=0.01, mass_in_metadata=False, seed=seed)
        result = identify(read_record(path))
        assert result.model == "joint"
        masses.append(result.summary["mass_kg"])
        errors.append(result.row()["mass_kg_se"])
    assert min(errors) > 0.0
    assert np.mean(masses) == pytest.approx(joint.mass, rel=0.01)
    scatter = float(np.std(masses, ddof=1))
    assert 0.5 < float(np.median(errors)) / scatter < 2.0, (errors, scatter)


LAB = Path(__file__).resolve().parents[1] / "examples" / "lab-csv"
ADVICE = re.compile(
    r"to use the known one, (?:"
    r"add the line '(?P<under>[^']+)' \(your moving mass\) under the first line "
    r"'(?P<magic>[^']+)' of (?P<file>\S+)"
    r"|add the line '(?P<line>[^']+)' \(your moving mass\) to (?P<sidecar>\S+)"
    r"|create (?P<new>\S+) holding the line '(?P<content>[^']+)' \(your moving mass\))$"
)


def follow(advice: str) -> None:
    """Do literally what the missing-mass warning says, and nothing else."""
    match = ADVICE.search(advice)
    assert match, advice
    if match["file"]:
        path = Path(match["file"])
        lines = path.read_text().splitlines(keepends=True)
        assert lines[0].strip() == match["magic"]
        path.write_text(lines[0] + match["under"] + "\n" + "".join(lines[1:]))
    elif match["sidecar"]:
        path = Path(match["sidecar"])
        path.write_text(path.read_text().rstrip("\n") + "\n" + match["line"] + "\n")
    else:
        Path(match["new"]).write_text(match["content"] + "\n")


@pytest.mark.parametrize("layout", ["lab csv and sidecar", "lab csv alone", "clearjoint csv"])
def test_the_missing_mass_advice_followed_literally_adds_the_mass(
    independent: dict[float, tuple[TrueJoint, dict[str, float]]],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    layout: str,
) -> None:
    # a lab CSV reads its metadata from NAME.toml only (a '# mass' line in it is a comment),
    # a clearjoint CSV from its header only: the advice must name the one that works
    if layout == "clearjoint csv":
        path = write_record(independent[40.0][0], tmp_path / "nomass.csv", mass_in_metadata=False)
    else:
        path = tmp_path / "joint-1_40Hz_1600N.csv"
        path.write_bytes((LAB / path.name).read_bytes())
        if layout == "lab csv and sidecar":  # the tutorial's file with its mass line dropped
            text = (LAB / "joint-1_40Hz_1600N.toml").read_text()
            kept = [line for line in text.splitlines() if not line.startswith("mass")]
            assert len(kept) < len(text.splitlines())
            path.with_suffix(".toml").write_text("\n".join(kept) + "\n")
    assert read_record(path).mass is None
    out = tmp_path / "r.csv"
    assert main(["identify", str(path), "--out", str(out), "--quiet"]) == 0
    warned = [line for line in capsys.readouterr().err.splitlines() if "without a mass" in line]
    assert len(warned) == 1
    follow(warned[0])
    assert read_record(path).mass == pytest.approx(1.5)
    assert main(["identify", str(path), "--out", str(out), "--quiet", "--force"]) == 0
    assert "without a mass" not in capsys.readouterr().err
    with out.open() as handle:
        (row,) = list(csv.DictReader(handle))
    assert float(row["mass_kg"]) == pytest.approx(1.5)


def backlash_loop(gap: float, noise: float, seed: int = 3) -> Record:
    """A displacement-controlled friction damper with backlash, written here: a slider
    dragged through an elastic link (2 MN/m, slip at 2 kN) that acts only once the play
    ``gap`` is taken up; 10 mm at 1 Hz, 6 cycles at 1 kHz, Gaussian noise of ``noise``
    times each channel's standard deviation on force and displacement."""
    t = np.arange(6000) / 1000.0
    x = 10e-3 * np.sin(2 * np.pi * t)
    k, slip, half = 2e6, 2000.0, 0.5 * gap
    force = np.empty_like(x)
    z = 0.0  # the slider
    for i, xi in enumerate(x):
        d = xi - z
        e = k * (d - half) if d > half else k * (d + half) if d < -half else 0.0
        if abs(e) > slip:
            z = xi - math.copysign(half + slip / k, e)
            e = math.copysign(slip, e)
        force[i] = e
    rng = np.random.default_rng(seed)
    return Record(
        time=t,
        force=force + rng.normal(0.0, noise * float(np.std(force)), t.size),
        displacement=x + rng.normal(0.0, noise * float(np.std(x)), t.size),
        control="displacement",
        frequency_hz=1.0,
        joint_id="damper",
    )


def test_a_backlash_whose_interval_spans_zero_is_rejected_in_the_cli_csv(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # a play of 0.2 mm under 3 % noise cannot be told from none; 4 mm at 1 % can
    tiny = write_clearjoint_record(backlash_loop(0.2e-3, 0.03), tmp_path / "tiny.csv")
    clear = write_clearjoint_record(backlash_loop(4e-3, 0.01), tmp_path / "clear.csv")
    out = tmp_path / "r.csv"
    assert main(["identify", str(tiny), str(clear), "--out", str(out), "--quiet"]) == 0
    with out.open() as handle:
        table = {Path(row["file"]).name: row for row in csv.DictReader(handle)}
    row = table["tiny.csv"]
    assert row["model"] == "damper"
    assert row["flag"] == "rejected"
    assert "its interval spans zero" in row["flag_reason"]
    # the reason is the columns' own: the two-standard-error interval reaches below zero
    assert float(row["clearance_m"]) - 2 * float(row["clearance_m_se"]) <= 0.0
    row = table["clear.csv"]
    assert row["model"] == "damper"
    assert float(row["clearance_m"]) == pytest.approx(4e-3, rel=0.05)
    assert row["flag"] != "rejected"
    assert "spans zero" not in row["flag_reason"]


# ---- real records shipped with the tests ------------------------------------------------


def elastic_plastic_energy(s: dict[str, float]) -> float:
    """Loop area of an elastic-plastic friction loop with a gap: 2 F_f (2X - b - 2 F_f / k)."""
    k = 0.5 * (s["compression_stiffness_n_per_m"] + s["tension_stiffness_n_per_m"])
    f_f, x, b = s["friction_force_n"], s["amplitude_m"], s["clearance_m"]
    return 2 * f_f * (2 * x - b - 2 * f_f / k)


@pytest.mark.parametrize("tension", [0, 30, 36])
def test_shipped_brfd_records_are_damper_loops(tension: int) -> None:
    record = read_record(SHIPPED / f"2Hz{tension}lbtension0.5amplitude.json")
    assert "band tension" in record.notes
    result = identify(record)
    s = result.summary
    assert result.model == "damper"
    assert result.cycles_used >= 3
    # the device's backlash is a few millimetres (3.8 to 4.2 mm median per band tension over
    # the 31 files, docs/identify.md)
    assert 2e-3 < s["clearance_m"] < 6e-3
    # the slip levels of both directions, with the friction force half their difference
    up, down = s["friction_force_positive_n"], s["friction_force_negative_n"]
    assert up > 0 > down
    assert s["friction_force_n"] == pytest.approx(0.5 * (up - down))
    # 2 Hz, 0 lb: a backlash of about 4.7 mm on the rising branch, 1.4 mm on the falling one
    # (docs/identify.md): not one gap, so its backlash is doubtful; the others read alike
    flag, reason = result.flags["clearance_m"]
    assert flag == ("doubtful" if tension == 0 else "ok")
    assert ("not one gap" in reason) == (tension == 0)
    assert s["energy_per_cycle_j"] == pytest.approx(elastic_plastic_energy(s), rel=0.15)


# ---- the result object and the command line ---------------------------------------------


def test_identification_repr_tables_and_plot() -> None:
    result = identify(read_record(SHIPPED / "2Hz36lbtension0.5amplitude.json"))
    text = repr(result)
    assert text.startswith("Identification(")
    assert "model='damper'" in text
    assert len(text) < 400
    assert "array" not in text
    data = result.to_xarray()
    assert data.sizes["cycle"] == result.cycles_used
    assert data["clearance_m"].attrs["units"] == "m"
    assert data["clearance_m"].attrs["estimate"] == result.summary["clearance_m"]
    assert data["clearance_m"].attrs["flag"] in ("ok", "doubtful", "rejected")
    # three cycles, three jackknife groups: the cycles' pseudo-values' spread over sqrt(3)
    # is the standard error
    values = data["clearance_m"].to_numpy()
    assert values.size == 3
    assert np.std(values, ddof=1) / np.sqrt(3) == pytest.approx(result.stderr["clearance_m"])
    table = result.to_pandas()
    assert table.loc["friction_force_n", "unit"] == "N"
    assert set(table["flag"]) <= {"ok", "doubtful", "rejected"}
    import matplotlib

    matplotlib.use("Agg")
    ax = result.plot()
    assert ax.get_xlabel() == "displacement (mm)"
    assert len(ax.lines) >= 1


def test_cli_plot_flags_warnings_and_jobs(
    independent: dict[float, tuple[TrueJoint, dict[str, float]]],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    joint, _ = independent[40.0]
    nomass = write_record(joint, tmp_path / "nomass.csv", noise=0.01, mass_in_metadata=False)
    files = [str(p) for p in sorted(SHIPPED.glob("*.json"))] + [str(nomass)]
    out, plot = tmp_path / "r.csv", tmp_path / "loops.png"
    assert main(["identify", *files, "--out", str(out), "--plot", str(plot), "--quiet"]) == 0
    err = capsys.readouterr().err
    assert "clearjoint identify: warning: " in err
    assert "without a mass" in err
    assert plot.stat().st_size > 0
    with out.open() as handle:
        table = list(csv.DictReader(handle))
    assert {"flag", "flag_reason", "clearance_m_se"} <= set(table[0])
    assert table[-1]["flag"] == "doubtful"
    assert "mass" in table[-1]["flag_reason"]
    # an existing plot is not overwritten without --force
    assert main(["identify", *files, "--out", str(tmp_path / "s.csv"), "--plot", str(plot)]) == 2
    assert "will not overwrite" in capsys.readouterr().err
    # two processes give the serial results, in file order
    serial, _ = identify_files(files)
    parallel, _ = identify_files(files, jobs=2)
    for (_, a), (_, b) in zip(serial, parallel, strict=True):
        np.testing.assert_equal(a.row(), b.row())  # NaN equals NaN here


def test_a_clearance_twice_the_median_of_the_device_is_flagged() -> None:
    from dataclasses import replace

    from clearjoint.identify import flag_outliers

    base = identify(read_record(SHIPPED / "2Hz36lbtension0.5amplitude.json"))
    assert base.joint_id == "BRFD"
    c = base.summary["clearance_m"]
    tests = [
        replace(base, source=f"t{k}", summary={**base.summary, "clearance_m": c * factor})
        for k, factor in enumerate((1.0, 1.1, 0.9, 2.5))
    ]
    flagged = flag_outliers(tests)
    assert [t.flags["clearance_m"][0] for t in flagged[:3]] == [base.flags["clearance_m"][0]] * 3
    flag, reason = flagged[3].flags["clearance_m"]
    assert flag == "doubtful"
    assert "more than twice the median" in reason
    assert "BRFD" in reason
    # another device's tests are not compared with these
    other = replace(tests[3], joint_id="other")
    assert flag_outliers([*tests[:3], other])[3].flags == other.flags


def test_the_steady_cycle_rule_is_stated_where_a_record_is_refused() -> None:
    from clearjoint.identify import steady_rule

    t = np.arange(300) / 100.0
    short = Record(
        time=t,
        force=np.sin(2 * np.pi * t),
        displacement=np.sin(2 * np.pi * t),
        control="displacement",
        source="short",
    )
    with pytest.raises(IdentificationError) as refused:
        identify(short, tolerance=0.05)
    assert steady_rule(0.05) in str(refused.value)
    # one rule, its percentages written alike: 5 % twice (the tolerance), 15 % and 90 %
    rule = steady_rule(0.05)
    assert rule.count("within 5 %") == 2
    assert "at most 15 % of A" in rule
    assert "at least 90 % of the largest" in rule
    assert "%" not in rule.replace(" %", "")  # no "3%" beside "10 %"
    # and docs/identify.md states it in the same words as the message (at --tolerance 3 %)
    docs = (Path(__file__).resolve().parents[1] / "docs" / "identify.md").read_text()
    flat = " ".join(docs.split()).lower()
    assert steady_rule(0.03).lower() in flat


def test_batched_replicate_fits_equal_the_fits_one_by_one(
    independent: dict[float, tuple[TrueJoint, dict[str, float]]],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The jackknife's replicates are fitted in one batched solve; fitted one by one (the
    row-by-row robust least squares, the fallback) they give the same values and errors."""
    import clearjoint.identify.core as core

    joint, _ = independent[40.0]
    # 0.2 % noise: a quiet average, fitted sample by sample (at 1 % the weak form is used)
    path = write_record(joint, tmp_path / "noisy.csv", noise=0.002, acceleration=True)
    t = np.arange(4000) / 2000.0
    x = 1e-4 * np.sin(2 * np.pi * 10.0 * t)
    v = 2e-3 * np.pi * np.cos(2 * np.pi * 10.0 * t)
    rng = np.random.default_rng(3)
    spring = Record(
        time=t,
        force=3e6 * x + 500.0 * v + rng.normal(0.0, 1.0, t.size),
        displacement=x,
        control="displacement",
        frequency_hz=10.0,
    )
    records = {"joint": read_record(path), "line": spring}
    batched = {name: identify(record) for name, record in records.items()}
    monkeypatch.setattr(core, "_joint_fits", lambda *args: None)
    monkeypatch.setattr(core, "_line_fits", lambda *args: None)
    for name, record in records.items():
        one_by_one = identify(record)
        assert batched[name].model == one_by_one.model == name
        for q, value in one_by_one.summary.items():
            assert batched[name].summary[q] == pytest.approx(value, rel=1e-9, nan_ok=True), q
            assert batched[name].stderr[q] == pytest.approx(
                one_by_one.stderr[q], rel=1e-6, abs=1e-12, nan_ok=True
            ), q


def test_fft_length_is_the_smallest_even_five_smooth_one() -> None:
    """numpy's FFT at the length scipy's next_fast_len would give (where that one is even)."""
    from scipy.fft import next_fast_len

    from clearjoint.identify.cycles import _smooth_length

    rng = np.random.default_rng(5)
    for n in [1, 2, 3, 7, 100, 1000, 14_400, 118_788, *rng.integers(1, 10**6, 300)]:
        length = _smooth_length(int(n))
        assert length >= n
        assert length % 2 == 0
        reduced = length
        for p in (2, 3, 5):
            while reduced % p == 0:
                reduced //= p
        assert reduced == 1
        reference = next_fast_len(int(n), real=True)
        if reference % 2 == 0:
            assert length == reference


def test_parallel_shares_give_the_serial_outcomes_in_file_order(tmp_path: Path) -> None:
    files = [str(p) for p in sorted(SHIPPED.glob("*.json"))]
    files.insert(1, str(tmp_path / "missing.json"))  # refused, with its reason, in its place
    serial, serial_failures = identify_files(files)
    seen: list[int] = []
    parallel, failures = identify_files(files, jobs=3, progress=lambda done, _: seen.append(done))
    assert failures == serial_failures
    assert "missing.json: no such file" in failures[0]
    assert seen == [1, 2, 3, 4]
    assert [i.source for _, i in parallel] == [i.source for _, i in serial]
    for (ra, a), (rb, b) in zip(serial, parallel, strict=True):
        np.testing.assert_equal(a.row(), b.row())  # bit for bit; NaN equals NaN here
        np.testing.assert_array_equal(ra.displacement, rb.displacement)


def test_cycle_result_tables_and_plot() -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from clearjoint.identify import CycleResult

    values = {"amplitude_m": 2e-4, "clearance_m": 1e-4, "energy_per_cycle_j": 3e-3}
    lines = ((-50.0, 8e7), (0.0, 1e5), (40.0, 5e7))
    cycle = CycleResult(0, 512, values, 5e-5, -5e-5, "joint", lines)
    data = cycle.to_xarray()
    for key, value in values.items():
        assert float(data[key]) == value
    assert data["clearance_m"].attrs["units"] == "m"
    assert data["energy_per_cycle_j"].attrs["units"] == "J"
    np.testing.assert_array_equal(data["line_slope"].values, [8e7, 1e5, 5e7])
    assert data["line_slope"].attrs["units"] == "N/m"
    assert list(data["stage"].values) == ["tension", "free play", "compression"]
    row = cycle.to_pandas()
    assert row.loc[0, "clearance_m"] == 1e-4
    assert row.loc[0, "upper_edge_m"] == 5e-5
    assert repr(cycle).startswith("CycleResult(samples 0-512, joint, X = 200 um")
    _, ax = plt.subplots()
    assert cycle.plot(ax) is ax
    compression = ax.get_lines()[-1]
    x = np.asarray(compression.get_xdata()) * 1e-6
    np.testing.assert_allclose(compression.get_ydata(), 40.0 + 5e7 * x)
    plt.close("all")
