"""Tests of clearjoint.sweep: sweep files, results against closed forms, seeds, stores, the CLI.

Physics is checked by independent routes: the forced linear oscillator's closed-form
amplitude and input energy (a joint with no clearance), the impact loss of a free
cycle by energy conservation, and the truncated normal's closed-form mean.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from distributed import LocalCluster
from scipy import stats

from clearjoint.cli import main
from clearjoint.errors import OutputExistsError
from clearjoint.parallel import StoreError, point_seed
from clearjoint.sweep import SERIAL, TASKS, Sweep, SweepError, open_sweep, run_sweep
from clearjoint.sweep.plot import default_picture, plot_sweep, save_sweep_plot
from helpers import LINEAR_STUDY

GAP_STUDY = """
[joint]
mass = "2kg"
clearance = "0.1mm"
compression_stiffness = "8e7N/m"
[excitation]
force_amplitude = "500N"
frequency = "400Hz"
[losses]
damping_ratio = 0.02
restitution = 0.8
"""


def _files(tmp_path: Path, sweep: str, study: str = GAP_STUDY) -> Path:
    (tmp_path / "study.toml").write_text(study, encoding="utf-8")
    path = tmp_path / "sweep.toml"
    path.write_text(sweep, encoding="utf-8")
    return path


def test_steady_state_matches_the_forced_linear_oscillator(tmp_path: Path) -> None:
    path = _files(
        tmp_path,
        """
base = "study.toml"
chunk_size = 3
[task]
name = "steady_state"
outputs = ["amplitude_m", "energy_input_j", "viscous_j"]
[axes.excitation]
frequency = ["200Hz", "1kHz"]
force_amplitude = { start = "10N", stop = "1kN", num = 3, spacing = "log" }
""",
        LINEAR_STUDY,
    )
    results = run_sweep(Sweep.from_toml(path), client=SERIAL)
    assert results.amplitude_m.dims == ("excitation.frequency", "excitation.force_amplitude")
    assert results["excitation.frequency"].attrs["units"] == "Hz"
    assert results.amplitude_m.attrs["units"] == "m"
    np.testing.assert_allclose(results["excitation.force_amplitude"], [10.0, 100.0, 1000.0])
    m, k, zeta = 2.0, 8e7, 0.05
    c = 2 * zeta * math.sqrt(m * k)
    w = 2 * math.pi * results["excitation.frequency"].values[:, None]
    f0 = results["excitation.force_amplitude"].values[None, :]
    x = f0 / np.hypot(k - m * w**2, c * w)
    np.testing.assert_allclose(results.amplitude_m, x, rtol=1e-6)
    np.testing.assert_allclose(results.energy_input_j, math.pi * c * w * x**2, rtol=1e-6)
    np.testing.assert_allclose(results.viscous_j, results.energy_input_j, rtol=1e-6)
    assert (results.status == "ok").all()
    assert results.attrs["points_failed"] == 0


def test_energies_give_the_impact_loss_of_the_free_cycle(tmp_path: Path) -> None:
    # k0 = 0, symmetric: the mass reaches each gap edge with (1/2) m v^2 = (1/2) k A^2,
    # so two impacts per cycle lose 2 (1 - e^2)/2 m v^2 = (1 - e^2) k A^2
    path = _files(
        tmp_path,
        """
base = "study.toml"
[task]
name = "energies"
outputs = ["impact_j", "total_j"]
[axes.task]
amplitude = ["1um", "5um", "20um"]
[axes.losses]
restitution = [0.5, 0.8, 1.0]
""",
    )
    results = run_sweep(Sweep.from_toml(path), client=SERIAL)
    a = results["task.amplitude"].values[:, None]
    e = results["losses.restitution"].values[None, :]
    np.testing.assert_allclose(results.impact_j, (1 - e**2) * 8e7 * a**2, rtol=1e-9)
    assert results.attrs["fixed"] == "{}"


def test_a_point_that_fails_is_nan_with_its_reason_and_the_sweep_goes_on(tmp_path: Path) -> None:
    path = _files(
        tmp_path,
        """
base = "study.toml"
chunk_size = 2
[task]
name = "steady_state"
outputs = ["amplitude_m"]
max_periods = 12
[axes.losses]
damping_ratio = [0.5, 0.0005]
""",
    )
    results = run_sweep(Sweep.from_toml(path), client=SERIAL)
    status = list(results.status.values)
    assert status[0] == "ok"
    assert status[1].startswith("SimulationError: ")
    assert np.isfinite(results.amplitude_m.values[0])
    assert np.isnan(results.amplitude_m.values[1])
    assert results.attrs["points_failed"] == 1


MONTE_CARLO = """
base = "study.toml"
seed = 11
samples = {samples}
chunk_size = {chunk}
[task]
name = "energies"
outputs = ["impact_j"]
amplitude = "5um"
[draws.joint.clearance]
distribution = "normal"
mean = "0.1mm"
std = "0.1mm"
{lower}
"""


def test_a_normal_clearance_is_refused_below_zero_unless_truncated(tmp_path: Path) -> None:
    text = MONTE_CARLO.format(samples=2000, chunk=500, lower="")
    with pytest.raises(SweepError, match=r"draws.joint.clearance.*outside.*lower ="):
        Sweep.from_toml(_files(tmp_path, text))
    text = MONTE_CARLO.format(samples=2000, chunk=500, lower='lower = "0mm"')
    sweep = Sweep.from_toml(_files(tmp_path, text))
    drawn = sweep.drawn()["joint.clearance"]
    assert drawn.min() >= 0.0
    # the truncated normal's own mean and spread, not a clipped normal's
    expected = stats.truncnorm(-1.0, np.inf, loc=1e-4, scale=1e-4)
    assert abs(drawn.mean() - expected.mean()) < 4 * expected.std() / math.sqrt(drawn.size)
    assert stats.kstest(drawn, expected.cdf).pvalue > 1e-3
    np.testing.assert_array_equal(drawn, sweep.drawn()["joint.clearance"])  # one seed


def test_monte_carlo_has_a_sample_dimension_with_the_draws_as_coordinates(tmp_path: Path) -> None:
    text = MONTE_CARLO.format(samples=6, chunk=4, lower='lower = "0mm"')
    sweep = Sweep.from_toml(_files(tmp_path, text))
    results = run_sweep(sweep, client=SERIAL)
    assert results.impact_j.dims == ("sample",)
    np.testing.assert_array_equal(results["joint.clearance"], sweep.drawn()["joint.clearance"])
    assert results["joint.clearance"].attrs["units"] == "m"
    # the impact loss of the free cycle does not depend on the clearance (k0 = 0)
    np.testing.assert_allclose(results.impact_j, (1 - 0.8**2) * 8e7 * 5e-6**2, rtol=1e-9)
    assert "6 points (sample: 6)" in repr(sweep)


CAMPAIGN = """
seed = 1
periods = 12
[grid]
frequencies = ["40Hz"]
force_amplitudes = ["1500N"]
[[structures]]
name = "joint-1"
clearance = "0.106mm"
"""

RIG_SWEEP = """
base = "campaign.toml"
seed = 5
samples = 3
chunk_size = {chunk}
[task]
name = "rig_test"
outputs = ["identified_clearance_m", "clearance_m", "energy_per_cycle_j"]
[axes.test]
force_amplitude = ["1.5kN"]
"""


def test_rig_tests_are_bit_for_bit_the_same_serial_and_on_a_local_cluster(
    tmp_path: Path,
) -> None:
    (tmp_path / "campaign.toml").write_text(CAMPAIGN, encoding="utf-8")
    serial = run_sweep(Sweep.from_toml(_files(tmp_path, RIG_SWEEP.format(chunk=3))), client=SERIAL)
    # two worker processes of a LocalCluster, chunks of one point finishing in any order
    on_dask = run_sweep(Sweep.from_toml(_files(tmp_path, RIG_SWEEP.format(chunk=1))), workers=2)
    np.testing.assert_array_equal(serial.identified_clearance_m, on_dask.identified_clearance_m)
    assert (serial.status == "ok").all()
    found = serial.identified_clearance_m.values
    truth = serial.clearance_m.values
    np.testing.assert_allclose(found, truth, rtol=0.1)  # the identification works
    assert len(set(found.ravel())) == 3  # every sample has its own noise
    assert TASKS["rig_test"].base == "campaign"
    # the noise seed of a point is numpy's spawn by point index
    assert point_seed(5, 2).spawn_key == np.random.SeedSequence(5).spawn(3)[2].spawn_key


STORE_SWEEP = """
base = "study.toml"
chunk_size = 2
[task]
name = "steady_state"
outputs = ["amplitude_m", "energy_input_j"]
samples_per_period = 16
[axes.excitation]
force_amplitude = ["200N", "400N", "600N", "800N", "1kN"]
"""


def test_a_stopped_sweep_resumes_with_only_the_missing_chunks(tmp_path: Path) -> None:
    path = _files(tmp_path, STORE_SWEEP)
    sweep = Sweep.from_toml(path)
    whole = run_sweep(sweep, client=SERIAL, out=tmp_path / "whole.zarr")
    calls: list[tuple[int, int]] = []

    def stop_after_first_chunk(done: int, total: int) -> None:
        calls.append((done, total))
        if done > 0:
            raise KeyboardInterrupt

    out = tmp_path / "cut.zarr"
    with pytest.raises(KeyboardInterrupt):
        run_sweep(sweep, client=SERIAL, out=out, progress=stop_after_first_chunk)
    partial = open_sweep(out)
    assert partial.attrs["points_missing"] == 3
    # its picture counts the points not yet computed apart: none failed
    assert plot_sweep(partial, "amplitude_m").get_title().endswith("(3 not computed)")
    with pytest.raises(OutputExistsError, match=r"pass resume=True .*, force=True"):
        run_sweep(sweep, client=SERIAL, out=out)  # from Python: its arguments, not the flags
    calls.clear()
    resumed = run_sweep(
        sweep, client=SERIAL, out=out, resume=True, progress=lambda d, t: calls.append((d, t))
    )
    assert calls[0] == (2, 5)  # the first chunk was not computed again
    np.testing.assert_array_equal(resumed.amplitude_m, whole.amplitude_m)
    np.testing.assert_array_equal(resumed.energy_input_j, whole.energy_input_j)
    assert list(resumed.status.values) == ["ok"] * 5
    # another sweep file cannot resume this store
    other = Sweep.from_toml(_files(tmp_path, STORE_SWEEP.replace('"1kN"', '"1.2kN"')))
    with pytest.raises(StoreError, match="different sweep file"):
        run_sweep(other, client=SERIAL, out=out, resume=True)
    replaced = run_sweep(other, client=SERIAL, out=out, force=True)
    assert replaced["excitation.force_amplitude"].values[-1] == 1200.0


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ('base = "study.toml"\nfoo = 1\n[task]\nname = "energies"', "unknown key"),
        ('base = "study.toml"\n[task]\nname = "nope"', "name must be one of"),
        (
            'base = "study.toml"\n[task]\nname = "energies"\namplitude = "1um"\n'
            "[axes.joint]\nclearance = []",
            "has no values",
        ),
        (
            'base = "study.toml"\n[task]\nname = "energies"\namplitude = "1um"\n'
            "[axes.joint]\nclearance = [0.1]",
            "give a unit",
        ),
        ('base = "study.toml"\n[task]\nname = "energies"\n[axes.joint]\nmass = ["1kg"]', "needs"),
        (
            'base = "study.toml"\n[task]\nname = "steady_state"\noutputs = ["x"]\n'
            '[axes.joint]\nmass = ["1kg"]',
            "not outputs",
        ),
        (
            'base = "study.toml"\n[task]\nname = "steady_state"\n[axes.joint]\nmass = ["1kg"]\n'
            '[axes.pin]\nradius = ["1mm"]',
            "no parameter 'pin.radius'",
        ),
        (
            'base = "study.toml"\n[task]\nname = "steady_state"\n'
            '[draws.joint.mass]\ndistribution = "lognormal"\nmedian = "2kg"\nsigma = 0.1',
            "samples = N",
        ),
        ('base = "nothere.toml"\n[task]\nname = "steady_state"', "no such study file"),
        (
            'base = "study.toml"\n[task]\nname = "stepped_sine"\nfrequency_start = "300Hz"\n'
            'frequency_stop = "900Hz"\nfrequency_steps = 0\n[axes.joint]\nmass = ["1kg"]',
            r"\[task\] frequency_steps: 1 of 1 values lie outside its range \(>= 2",
        ),
        (
            'base = "study.toml"\n[task]\nname = "stepped_sine"\nfrequency_start = "nan Hz"\n'
            'frequency_stop = "900Hz"\n[axes.joint]\nmass = ["1kg"]',
            r"\[task\] frequency_start: 1 of 1 values lie outside its range",
        ),
        (
            'base = "study.toml"\n[task]\nname = "frequency_response"\n'
            'frequency_start = "1300Hz"\nfrequency_stop = "900Hz"\n[axes.joint]\nmass = ["1kg"]',
            r"frequency_stop \(900 Hz\) must exceed frequency_start \(1300 Hz\)",
        ),
        (  # a linear axis of zero width would run the same point num times
            'base = "study.toml"\n[task]\nname = "steady_state"\n'
            '[axes.joint]\nclearance = { start = "0.1mm", stop = "0.1mm", num = 5 }',
            r"start and stop are equal \(0.0001 m\), so its 5 points would all be the same",
        ),
        (
            'base = "study.toml"\n[task]\nname = "steady_state"\n'
            '[axes.joint]\nclearance = { start = "0.1mm", stop = "0.1mm", num = 3, '
            'spacing = "log" }',
            "start and stop are equal",
        ),
        (
            'base = "study.toml"\n[task]\nname = "steady_state"\n'
            '[axes.joint]\nclearance = ["0.1mm", "0.2mm", "0.1mm"]',
            "repeats a value",
        ),
        ('base = "study.toml"\n[task]\nname = "steady_state"', "the sweep has no points"),
        (  # per_joint needs the joints of a structure
            'base = "study.toml"\nsamples = 2\n[task]\nname = "steady_state"\n'
            '[draws.joint.clearance]\ndistribution = "uniform"\nlow = "0.05mm"\n'
            'high = "0.1mm"\nper_joint = true',
            "per_joint = true needs a structure task",
        ),
    ],
)
def test_bad_sweep_files_are_one_clear_error(tmp_path: Path, text: str, message: str) -> None:
    with pytest.raises(SweepError, match=message) as info:
        Sweep.from_toml(_files(tmp_path, text))
    assert "\n" not in str(info.value)


def test_the_command_line_runs_refuses_and_plots(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _files(tmp_path, STORE_SWEEP)
    out = tmp_path / "r.zarr"
    # a "running cluster" in this process, reached by its address as --scheduler would
    with LocalCluster(n_workers=1, processes=False, protocol="tcp", dashboard_address=":0") as c:
        command = ["sweep", str(path), "--out", str(out), "--scheduler", c.scheduler_address]
        assert main(command) == 0
        assert "wrote 5 points (0 failed" in capsys.readouterr().out
        assert main([*command, "--resume"]) == 0  # nothing left to compute
        assert "5 of them kept from the store" in capsys.readouterr().out
    assert main(["sweep", str(path), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "will not overwrite" in err
    assert "pass --resume" in err
    assert "--force" in err
    assert err.count("\n") == 1
    assert main(["sweep", "--plot", str(out), "amplitude_m"]) == 0
    assert (tmp_path / "r_amplitude_m.png").stat().st_size > 1000
    assert main(["sweep", "--plot", str(out), "nope"]) == 2
    assert "choose one of" in capsys.readouterr().err
    assert main(["sweep", str(path), "--out", str(tmp_path / "x.nc")]) == 2
    # --out with --plot is a figure, checked as every --plot is (suffix, no overwrite)
    picture = ["sweep", "--plot", str(out), "amplitude_m", "--out"]
    capsys.readouterr()
    assert main([*picture, str(tmp_path / "m.csv")]) == 2
    assert "--out must end in .png, .pdf, .svg, got 'm.csv'" in capsys.readouterr().err
    assert main([*picture, str(tmp_path / "r_amplitude_m.png")]) == 2
    assert "will not overwrite" in capsys.readouterr().err
    assert main([*picture, str(tmp_path / "m.svg")]) == 0
    assert "<svg" in (tmp_path / "m.svg").read_text()
    assert (
        main(["sweep", str(path), "--out", str(out), "--scheduler", "tcp://x:1", "--workers", "2"])
        == 2
    )


def test_plot_draws_a_map_and_a_histogram(tmp_path: Path) -> None:
    path = _files(
        tmp_path,
        """
base = "study.toml"
[task]
name = "energies"
amplitude = "5um"
[axes.joint]
clearance = ["0.05mm", "0.1mm"]
compression_stiffness = ["5e7N/m", "8e7N/m", "1e8N/m"]
""",
    )
    results = run_sweep(Sweep.from_toml(path), client=SERIAL)
    ax = plot_sweep(results, "total_j")
    assert ax.get_xlabel() == "joint.clearance (um)"
    assert ax.get_ylabel() == "joint.compression_stiffness (MN/m)"
    text = MONTE_CARLO.format(samples=20, chunk=20, lower='lower = "0mm"')
    ax = plot_sweep(run_sweep(Sweep.from_toml(_files(tmp_path, text)), client=SERIAL), "impact_j")
    assert ax.get_ylabel() == "samples"


def test_a_sweep_picture_is_named_beside_its_store_and_written_where_asked(
    tmp_path: Path,
) -> None:
    assert default_picture("runs/gap.zarr", "total_j") == Path("runs/gap_total_j.png")
    path = _files(tmp_path, 'base = "study.toml"\n[task]\nname = "energies"\namplitude = "5um"\n'
                  '[axes.joint]\nclearance = ["0.05mm", "0.1mm"]\n')  # fmt: skip
    results = run_sweep(Sweep.from_toml(path), client=SERIAL)
    picture = save_sweep_plot(results, "total_j", str(tmp_path / "total.png"))
    assert picture == tmp_path / "total.png"
    assert picture.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_stepped_sine_peak_is_the_linear_resonance_on_its_grid(tmp_path: Path) -> None:
    path = _files(
        tmp_path,
        """
base = "study.toml"
[task]
name = "stepped_sine"
outputs = ["peak_amplitude_m", "peak_frequency_hz", "jump_m", "steps_failed"]
frequency_start = "900Hz"
frequency_stop = "1100Hz"
frequency_steps = 9
[axes.excitation]
force_amplitude = ["100N", "300N"]
""",
        LINEAR_STUDY,
    )
    results = run_sweep(Sweep.from_toml(path), client=SERIAL)
    m, k, zeta = 2.0, 8e7, 0.05
    hz = np.linspace(900.0, 1100.0, 9)
    w = 2 * np.pi * hz
    curve = 1.0 / np.hypot(k - m * w**2, 2 * zeta * math.sqrt(m * k) * w)
    f0 = results["excitation.force_amplitude"].values
    np.testing.assert_allclose(results.peak_amplitude_m, f0 * curve.max(), rtol=1e-6)
    np.testing.assert_array_equal(results.peak_frequency_hz, hz[np.argmax(curve)])
    assert results.jump_m.max() < 1e-9 * results.peak_amplitude_m.max()  # linear: no jump
    assert (results.steps_failed == 0).all()


def test_free_cycle_gives_eq_4_and_the_impact_damping(tmp_path: Path) -> None:
    # k0 = 0, symmetric: T = 2 pi / w1 + 2 c / (A w1), w1 = sqrt(k / m)  (MODEL.md eq 4),
    # and the impacts' (1 - e^2) k A^2 per cycle over 4 pi U_max, U_max = k A^2 / 2
    path = _files(
        tmp_path,
        """
base = "study.toml"
[task]
name = "free_cycle"
amplitude = "10um"
[axes.joint]
clearance = ["0.05mm", "0.2mm"]
[axes.losses]
damping_ratio = [0.0]
""",
    )
    results = run_sweep(Sweep.from_toml(path), client=SERIAL).squeeze("losses.damping_ratio")
    w1 = math.sqrt(8e7 / 2.0)
    c = results["joint.clearance"].values
    period = 2 * math.pi / w1 + 2 * c / (10e-6 * w1)
    np.testing.assert_allclose(results.natural_frequency_hz, 1 / period, rtol=1e-9)
    np.testing.assert_allclose(results.dynamic_stiffness_n_per_m, 2.0 * (2 * np.pi / period) ** 2)
    # impacts only: (1 - e^2) k A^2 / (4 pi k A^2 / 2), whatever the clearance
    np.testing.assert_allclose(results.equivalent_damping_ratio, (1 - 0.8**2) / (2 * math.pi))


def test_a_chunk_that_dies_is_reported_and_the_rest_is_kept_for_resume(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import clearjoint.sweep.run as sweep_run
    from clearjoint.parallel import ChunkFailedError

    sweep = Sweep.from_toml(_files(tmp_path, STORE_SWEEP))
    real = sweep_run._evaluate_chunk

    def dies_on_the_second_chunk(chunk: Any) -> Any:
        if chunk.first == 2:
            raise MemoryError("worker lost")  # as a killed worker would surface
        return real(chunk)

    monkeypatch.setattr(sweep_run, "_evaluate_chunk", dies_on_the_second_chunk)
    out = tmp_path / "r.zarr"
    with pytest.raises(ChunkFailedError, match=r"1 of 3 chunks.*worker lost.*--resume"):
        run_sweep(sweep, client=SERIAL, out=out)
    assert open_sweep(out).attrs["points_missing"] == 2
    monkeypatch.setattr(sweep_run, "_evaluate_chunk", real)
    done = run_sweep(sweep, client=SERIAL, out=out, resume=True)
    assert done.attrs["points_missing"] == 0
    assert list(done.status.values) == ["ok"] * 5


def test_the_shipped_sweep_files_read() -> None:
    examples = Path(__file__).resolve().parents[1] / "examples"
    peak = Sweep.from_toml(examples / "sweep.toml")
    assert peak.dims == ("joint.clearance", "excitation.force_amplitude")
    assert peak.n_points == 20
    tolerance = Sweep.from_toml(examples / "tolerance.toml")
    assert tolerance.shape == (1000, 2)
    assert tolerance.drawn()["joint.clearance"].min() > 0.0
    mast = Sweep.from_toml(examples / "mast_tolerance_sweep.toml")
    assert mast.shape == (1000, 2)
    assert mast.drawn()["joint.clearance"].shape == (1000, 20)


def test_the_sweep_file_in_the_docs_reads(tmp_path: Path) -> None:
    docs = Path(__file__).resolve().parents[1] / "docs" / "sweep.md"
    block = docs.read_text(encoding="utf-8").split("```toml\n", 1)[1].split("```", 1)[0]
    sweep = Sweep.from_toml(_files(tmp_path, block))
    assert sweep.dims == ("sample", "joint.compression_stiffness", "losses.restitution")
    assert sweep.shape == (1000, 2, 5)


def test_a_record_set_is_identified_file_by_file(tmp_path: Path) -> None:
    import csv

    from clearjoint.rig import load_campaign, run_campaign

    (tmp_path / "campaign.toml").write_text(
        CAMPAIGN.replace('["1500N"]', '["1500N", "2500N"]'), encoding="utf-8"
    )
    manifest = run_campaign(load_campaign(tmp_path / "campaign.toml"), tmp_path / "rec", jobs=1)
    (tmp_path / "rec" / "zz_broken.nc").write_text("not a record", encoding="utf-8")
    path = _files(
        tmp_path,
        """
base = "rec/*.nc"
[task]
name = "identify"
outputs = ["clearance_m", "cycles_used"]
""",
    )
    results = run_sweep(Sweep.from_toml(path), client=SERIAL)
    names = [Path(f).name for f in results.file.values]
    assert names == ["joint-1_40Hz_1500N.nc", "joint-1_40Hz_2500N.nc", "zz_broken.nc"]
    with manifest.open() as handle:
        truth = {row["file"]: float(row["clearance_m"]) for row in csv.DictReader(handle)}
    for i, name in enumerate(names[:2]):
        assert results.status.values[i] == "ok"
        assert results.clearance_m.values[i] == pytest.approx(truth[name], rel=0.1)
    assert np.isnan(results.clearance_m.values[2])
    assert "zz_broken.nc" in results.status.values[2]
    with pytest.raises(SweepError, match="matches no file"):
        Sweep.from_toml(_files(tmp_path, 'base = "none/*.nc"\n[task]\nname = "identify"'))


def test_a_bare_number_is_refused_without_pointing_to_a_unit_key(tmp_path: Path) -> None:
    """A sweep has no keys that name their unit: the hint is the unit alone."""
    text = 'base = "study.toml"\n[task]\nname = "steady_state"\n[axes.joint]\nclearance = [0.1]'
    with pytest.raises(SweepError) as info:
        Sweep.from_toml(_files(tmp_path, text))
    assert str(info.value).endswith('clearance = 0.1: give a unit, e.g. "0.1mm"')


@pytest.mark.parametrize(
    ("content", "message"),
    [(None, "is a folder"), (b"", "empty file"), (b"\x00\x01\x02", "binary file")],
)
def test_sweep_path_errors_come_from_the_one_toml_reader(
    tmp_path: Path, content: bytes | None, message: str
) -> None:
    path = tmp_path / "s.toml"
    if content is None:
        path.mkdir()
    else:
        path.write_bytes(content)
    with pytest.raises(SweepError, match=message):
        Sweep.from_toml(path)


MAST = """
[structure]
kind = "mast"
bays = 2
longeron_rigidity = "{rigidity}"
[joint]
clearance = "0.1mm"
compression_stiffness = "5e7N/m"
"""
MAST_SWEEP = """
base = "study.toml"
samples = 4
[task]
name = "structure_mode"
amplitude = "1mm"
[draws.joint.clearance]
distribution = "normal"
mean = "0.1mm"
std = "0.02mm"
lower = "0mm"
per_joint = {per_joint}
"""


def test_a_structure_sweep_draws_per_joint_and_its_hash_sees_every_value(tmp_path: Path) -> None:
    sweep = Sweep.from_toml(
        _files(tmp_path, MAST_SWEEP.format(per_joint="true"), MAST.format(rigidity="2e7N"))
    )
    (draw,) = sweep.draws
    assert draw.per_joint == 4  # a 2-bay mast has a joint in each of its 4 longerons
    drawn = sweep.drawn()["joint.clearance"]
    assert drawn.shape == (4, 4)
    assert np.unique(drawn).size == 16
    assert (drawn >= 0).all()
    one = Sweep.from_toml(
        _files(tmp_path, MAST_SWEEP.format(per_joint="false"), MAST.format(rigidity="2e7N"))
    )
    assert one.drawn()["joint.clearance"].shape == (4,)  # the same draw for every joint
    # the structure's repr is a summary: its hash must still see a member's stiffness
    stiffer = Sweep.from_toml(
        _files(tmp_path, MAST_SWEEP.format(per_joint="true"), MAST.format(rigidity="3e7N"))
    )
    assert repr(stiffer.base.structure) == repr(sweep.base.structure)
    assert stiffer.fingerprint != sweep.fingerprint
    with pytest.raises(SweepError, match="per_joint must be true or false"):
        Sweep.from_toml(
            _files(tmp_path, MAST_SWEEP.format(per_joint='"yes"'), MAST.format(rigidity="2e7N"))
        )
    no_joints = MAST.format(rigidity="2e7N").split("[joint]")[0]
    # the study loader refuses a mast without joints first, naming the section to add
    with pytest.raises(SweepError, match="a mast needs a \\[joint\\] section"):
        Sweep.from_toml(_files(tmp_path, MAST_SWEEP.format(per_joint="true"), no_joints))
